// The HD API test double: a single-threaded model of the few OpenHaptics calls graspsim uses.
// The scheduler never runs on its own; run_frames() calls the scheduled callbacks on the test's
// thread, so every test is deterministic. Misuses the real API would punish (state read outside
// a frame, a device initialised while the scheduler runs, a synchronous call with the scheduler
// stopped, which would block forever) are logged as violations for the tests to check.
#include "hd_double.hpp"

#include <algorithm>
#include <memory>
#include <stdexcept>

namespace hd_double {
namespace {

struct Internal {
  std::unique_ptr<FakeDevice> device;
  bool in_frame = false;
  std::array<double, 3> pending_force{0.0, 0.0, 0.0};
};

struct Async {
  HDSchedulerHandle id;
  HDSchedulerCallback callback;
  void* data;
  HDushort priority;
};

struct World {
  std::vector<Internal> devices;
  std::string default_name;
  HHD current = HD_INVALID_HANDLE;
  HHD next_handle = 1;
  std::vector<HDErrorInfo> errors;
  std::vector<Async> async;
  HDSchedulerHandle next_id = 1;
  bool running = false;
  std::vector<std::string> init_log;
  std::vector<std::string> violations;
};

World& world() {
  static World w;
  return w;
}

Internal* by_handle(HHD h) {
  for (auto& d : world().devices)
    if (d.device->handle == h && h != HD_INVALID_HANDLE) return &d;
  return nullptr;
}

void raise(HDerror code, int internal = 0) {
  world().errors.push_back(HDErrorInfo{code, internal, world().current});
}

void violation(const std::string& what) { world().violations.push_back(what); }

Internal* current_device(const char* call) {
  Internal* d = by_handle(world().current);
  if (!d) {
    violation(std::string(call) + " with no current device");
    raise(HD_BAD_HANDLE);
  }
  return d;
}

}  // namespace

void reset() { world() = World{}; }

FakeDevice& add_device(const std::string& name) {
  Internal d;
  d.device = std::make_unique<FakeDevice>();
  d.device->name = name;
  world().devices.push_back(std::move(d));
  return *world().devices.back().device;
}

void set_default(const std::string& name) { world().default_name = name; }

FakeDevice& device(const std::string& name) {
  for (auto& d : world().devices)
    if (d.device->name == name) return *d.device;
  throw std::invalid_argument("hd_double: no configured device " + name);
}

int run_frames(int n) {
  int calls = 0;
  if (!world().running) return 0;
  for (int frame = 0; frame < n; ++frame) {
    std::vector<Async> order = world().async;
    std::stable_sort(order.begin(), order.end(),
                     [](const Async& a, const Async& b) { return a.priority > b.priority; });
    for (const Async& a : order) {
      ++calls;
      if (a.callback(a.data) == HD_CALLBACK_DONE) hdUnschedule(a.id);
    }
    for (auto& d : world().devices)
      if (d.in_frame) violation("a frame of " + d.device->name + " left open by the callback");
  }
  return calls;
}

int scheduled_callbacks() { return static_cast<int>(world().async.size()); }
bool scheduler_running() { return world().running; }
const std::vector<std::string>& init_log() { return world().init_log; }
const std::vector<std::string>& violations() { return world().violations; }

}  // namespace hd_double

using namespace hd_double;

extern "C" {

HHD hdInitDevice(HDstring pConfigName) {
  World& w = world();
  const std::string name = pConfigName ? pConfigName : w.default_name;
  w.init_log.push_back(pConfigName ? pConfigName : "<default>");
  if (w.running) violation("hdInitDevice while the scheduler runs");
  for (auto& d : w.devices) {
    if (d.device->name != name) continue;
    if (d.device->init_error != HD_SUCCESS) {
      raise(d.device->init_error, d.device->init_internal);
      return HD_INVALID_HANDLE;
    }
    if (d.device->handle != HD_INVALID_HANDLE) {
      raise(HD_DEVICE_ALREADY_INITIATED);
      return HD_INVALID_HANDLE;
    }
    d.device->handle = w.next_handle++;
    w.current = d.device->handle;
    return d.device->handle;
  }
  raise(HD_COMM_CONFIG_ERROR, -1);
  return HD_INVALID_HANDLE;
}

void hdMakeCurrentDevice(HHD hHD) {
  if (!by_handle(hHD)) {
    violation("hdMakeCurrentDevice on a handle that is not open");
    raise(HD_BAD_HANDLE);
    return;
  }
  world().current = hHD;
}

void hdDisableDevice(HHD hHD) {
  Internal* d = by_handle(hHD);
  if (!d) {
    raise(HD_BAD_HANDLE);
    return;
  }
  if (world().running) violation("hdDisableDevice while the scheduler runs");
  d->device->handle = HD_INVALID_HANDLE;
  d->device->force_output = false;
  if (world().current == hHD) world().current = HD_INVALID_HANDLE;
}

HHD hdGetCurrentDevice(void) { return world().current; }

void hdBeginFrame(HHD hHD) {
  Internal* d = by_handle(hHD);
  if (!d) {
    raise(HD_BAD_HANDLE);
    return;
  }
  if (d->in_frame) {
    raise(HD_ILLEGAL_BEGIN);
    return;
  }
  d->in_frame = true;
  d->pending_force = {0.0, 0.0, 0.0};   // as in HD: a frame's force starts at zero
}

void hdEndFrame(HHD hHD) {
  Internal* d = by_handle(hHD);
  if (!d) {
    raise(HD_BAD_HANDLE);
    return;
  }
  if (!d->in_frame) {
    raise(HD_ILLEGAL_END);
    return;
  }
  d->in_frame = false;
  if (d->device->force_output) d->device->force = d->pending_force;
  ++d->device->frames;
  if (d->device->frame_error != HD_SUCCESS) {
    raise(d->device->frame_error, 1);
    d->device->frame_error = HD_SUCCESS;
  }
}

HDErrorInfo hdGetError(void) {
  World& w = world();
  if (w.errors.empty()) return HDErrorInfo{HD_SUCCESS, 0, HD_INVALID_HANDLE};
  const HDErrorInfo e = w.errors.back();
  w.errors.pop_back();
  return e;
}

HDstring hdGetErrorString(HDerror errorCode) {
  switch (errorCode) {
    case HD_SUCCESS: return "No error";
    case HD_COMM_ERROR: return "Communication error";
    case HD_COMM_CONFIG_ERROR: return "Communication configuration error";
    case HD_DEVICE_FAULT: return "Device fault";
    case HD_WARM_MOTORS: return "Motors are too warm";
    case HD_EXCEEDED_MAX_VELOCITY: return "Exceeded maximum velocity";
    default: return "Other error";
  }
}

void hdEnable(HDenum cap) {
  Internal* d = current_device("hdEnable");
  if (!d) return;
  if (cap == HD_FORCE_OUTPUT)
    d->device->force_output = true;
  else
    raise(HD_INVALID_ENUM);
}

void hdDisable(HDenum cap) {
  Internal* d = current_device("hdDisable");
  if (!d) return;
  if (cap == HD_FORCE_OUTPUT)
    d->device->force_output = false;
  else
    raise(HD_INVALID_ENUM);
}

void hdGetIntegerv(HDenum pname, HDint* params) {
  Internal* d = current_device("hdGetIntegerv");
  if (!d) return;
  switch (pname) {
    case HD_CURRENT_BUTTONS:
      if (!d->in_frame) violation("HD_CURRENT_BUTTONS read outside a frame");
      params[0] = d->device->buttons;
      return;
    case HD_UPDATE_RATE: params[0] = d->device->update_rate; return;
    default: raise(HD_INVALID_ENUM);
  }
}

void hdGetDoublev(HDenum pname, HDdouble* params) {
  Internal* d = current_device("hdGetDoublev");
  if (!d) return;
  const FakeDevice& f = *d->device;
  switch (pname) {
    case HD_CURRENT_POSITION:
    case HD_CURRENT_GIMBAL_ANGLES: {
      if (!d->in_frame) violation("current state read outside a frame");
      const auto& v = pname == HD_CURRENT_POSITION ? f.position_mm : f.gimbal;
      for (int i = 0; i < 3; ++i) params[i] = v[i];
      return;
    }
    case HD_NOMINAL_MAX_FORCE: params[0] = f.max_force; return;
    case HD_NOMINAL_MAX_CONTINUOUS_FORCE: params[0] = f.max_continuous_force; return;
    case HD_NOMINAL_MAX_STIFFNESS: params[0] = f.max_stiffness; return;
    case HD_CURRENT_FORCE:
      for (int i = 0; i < 3; ++i) params[i] = d->pending_force[i];
      return;
    default: raise(HD_INVALID_ENUM);
  }
}

HDstring hdGetString(HDenum pname) {
  Internal* d = current_device("hdGetString");
  if (!d) return nullptr;
  if (pname == HD_DEVICE_MODEL_TYPE) return d->device->model.c_str();
  raise(HD_INVALID_ENUM);
  return nullptr;
}

void hdSetDoublev(HDenum pname, const HDdouble* params) {
  Internal* d = current_device("hdSetDoublev");
  if (!d) return;
  if (pname != HD_CURRENT_FORCE) {
    raise(HD_INVALID_ENUM);
    return;
  }
  if (!d->in_frame) violation("HD_CURRENT_FORCE written outside a frame");
  for (int i = 0; i < 3; ++i) d->pending_force[i] = params[i];
}

void hdStartScheduler(void) { world().running = true; }
void hdStopScheduler(void) { world().running = false; }

HDSchedulerHandle hdScheduleAsynchronous(HDSchedulerCallback pCallback, void* pUserData,
                                         HDushort nPriority) {
  World& w = world();
  w.async.push_back(Async{w.next_id, pCallback, pUserData, nPriority});
  return w.next_id++;
}

void hdScheduleSynchronous(HDSchedulerCallback pCallback, void* pUserData, HDushort) {
  if (!world().running) {
    violation("hdScheduleSynchronous with the scheduler stopped (would block forever)");
    raise(HD_INVALID_OPERATION);
    return;
  }
  // The next servo frame: the asynchronous callbacks (higher priority) first, then this one.
  run_frames(1);
  for (int i = 0; i < 1000; ++i)
    if (pCallback(pUserData) == HD_CALLBACK_DONE) return;
  violation("a synchronous callback did not finish in 1000 frames");
}

void hdUnschedule(HDSchedulerHandle hHandle) {
  auto& a = world().async;
  const auto it = std::find_if(a.begin(), a.end(),
                               [&](const Async& x) { return x.id == hHandle; });
  if (it == a.end()) {
    raise(HD_INVALID_OPERATION);
    return;
  }
  a.erase(it);
}

}  // extern "C"
