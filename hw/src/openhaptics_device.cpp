// The OpenHaptics (HD API) backend. Built against the real SDK when CMake finds it, and a second
// time against the test double in tests/hw/openhaptics_double (which mirrors the calls used here).
//
// Threads: the HD scheduler runs one servo callback (servo_frame) for every open Phantom on its
// own thread at the device rate (1 kHz by default); graspsim's read()/render() run on the
// caller's thread. They meet in one Mailbox per device, a mutex-guarded pair of buffers (the
// sample HD wrote, the force graspsim asked for). The servo side only try_locks: it never waits
// on graspsim, and on the rare contended frame it keeps its last force and publishes the sample
// one frame later. graspsim's side locks, and waits at most for a copy of ten numbers. A mutex
// (not a seqlock) because it is obviously correct, and the copies inside it are tiny.
#include "graspsim/hw/openhaptics_device.hpp"

#include <HD/hd.h>

#include "graspsim/hw/force_safety.hpp"

#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <mutex>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

namespace graspsim::hw {
namespace {

constexpr std::uint64_t kStallFrames = kOpenHapticsStallFrames;

// OpenHaptics axes (x right, y up, z toward the user) to the device frame (x right, y away from
// the user, z up), and back. A rotation (det +1), so forces map the same way as positions.
Vec3 hd_to_device(const std::array<double, 3>& v) { return Vec3(v[0], -v[2], v[1]); }
std::array<double, 3> device_to_hd(const Vec3& v) { return {v.x(), v.z(), -v.y()}; }

const char* hd_error_name(HDerror code) {
  switch (code) {
    case HD_SUCCESS: return "HD_SUCCESS";
    case HD_INVALID_ENUM: return "HD_INVALID_ENUM";
    case HD_INVALID_VALUE: return "HD_INVALID_VALUE";
    case HD_INVALID_OPERATION: return "HD_INVALID_OPERATION";
    case HD_INVALID_INPUT_TYPE: return "HD_INVALID_INPUT_TYPE";
    case HD_BAD_HANDLE: return "HD_BAD_HANDLE";
    case HD_WARM_MOTORS: return "HD_WARM_MOTORS";
    case HD_EXCEEDED_MAX_FORCE: return "HD_EXCEEDED_MAX_FORCE";
    case HD_EXCEEDED_MAX_FORCE_IMPULSE: return "HD_EXCEEDED_MAX_FORCE_IMPULSE";
    case HD_EXCEEDED_MAX_VELOCITY: return "HD_EXCEEDED_MAX_VELOCITY";
    case HD_FORCE_ERROR: return "HD_FORCE_ERROR";
    case HD_DEVICE_FAULT: return "HD_DEVICE_FAULT";
    case HD_DEVICE_ALREADY_INITIATED: return "HD_DEVICE_ALREADY_INITIATED";
    case HD_COMM_ERROR: return "HD_COMM_ERROR";
    case HD_COMM_CONFIG_ERROR: return "HD_COMM_CONFIG_ERROR";
    case HD_TIMER_ERROR: return "HD_TIMER_ERROR";
    case HD_ILLEGAL_BEGIN: return "HD_ILLEGAL_BEGIN";
    case HD_ILLEGAL_END: return "HD_ILLEGAL_END";
    case HD_FRAME_ERROR: return "HD_FRAME_ERROR";
    case HD_INVALID_PRIORITY: return "HD_INVALID_PRIORITY";
    case HD_SCHEDULER_FULL: return "HD_SCHEDULER_FULL";
    case HD_INVALID_LICENSE: return "HD_INVALID_LICENSE";
    default: return "unknown HD error";
  }
}

// "HD_COMM_ERROR (0x0302, internal 7): <hdGetErrorString>"
std::string describe_error(const HDErrorInfo& e) {
  char code[64];
  std::snprintf(code, sizeof code, " (0x%04X, internal %d): ", e.errorCode, e.internalErrorCode);
  const HDstring text = hdGetErrorString(e.errorCode);
  return std::string(hd_error_name(e.errorCode)) + code + (text ? text : "no description");
}

// Pops every error HD has stacked and returns the most recent (HD_SUCCESS if none).
HDErrorInfo take_error() {
  HDErrorInfo latest{HD_SUCCESS, 0, HD_INVALID_HANDLE};
  bool first = true;
  for (HDErrorInfo e = hdGetError(); HD_DEVICE_ERROR(e); e = hdGetError()) {
    if (first) latest = e;
    first = false;
  }
  return latest;
}

std::string quoted(const std::string& s) { return "\"" + s + "\""; }

// One device's exchange between the HD servo thread and graspsim.
struct Mailbox {
  std::mutex mutex;
  // Written by the servo thread, read by graspsim.
  std::array<double, 3> position_mm{0.0, 0.0, 0.0};   // mm, OpenHaptics axes
  std::array<double, 3> gimbal{0.0, 0.0, 0.0};        // rad, HD_CURRENT_GIMBAL_ANGLES
  std::uint32_t buttons = 0;                          // HD_CURRENT_BUTTONS bits
  std::int64_t frame = -1;                            // servo frame the sample was read in
  HDErrorInfo fault{HD_SUCCESS, 0, HD_INVALID_HANDLE};   // first HD error seen in a frame
  // Written by graspsim, read by the servo thread.
  std::array<double, 3> force_hd{0.0, 0.0, 0.0};   // N, OpenHaptics axes, already clamped
  std::uint64_t requests = 0;                      // force requests so far
  std::uint64_t releases = 0;                      // release() calls so far
  std::uint64_t released_at = 0;                   // `requests` at the last release()
};

struct Slot {
  HHD handle = HD_INVALID_HANDLE;
  std::string requested;   // the name the caller asked for
  std::string opened;      // the configured name that opened ("" for HD_DEFAULT_DEVICE)
  std::string model;       // HD_DEVICE_MODEL_TYPE
  PhantomNominal nominal;
  double rate = kOpenHapticsDefaultRate;   // Hz: frames per second of the device clock
  Mailbox box;
  // Servo thread only (set up before the scheduler first serves the slot).
  std::optional<ForceSafety> safety;   // nominal peak and continuous force, on the frame clock
  std::int64_t frame = 0;              // servo frames served so far: frame k runs at k / rate s
  std::uint64_t seen_requests = 0;
  std::uint64_t seen_releases = 0;
  std::uint64_t frames_since_request = 0;
  HDErrorInfo fault{HD_SUCCESS, 0, HD_INVALID_HANDLE};   // first HD error in a frame; sticky
};

// Every open Phantom, and the one scheduler callback that serves them all. The device list only
// changes while the scheduler is stopped, so the callback reads it without a lock.
class Session {
 public:
  static Session& instance() {
    static Session session;
    return session;
  }

  Slot* open(const std::string& name, const OpenHapticsOptions& options);
  void close(Slot* slot);
  std::mutex& mutex() { return mutex_; }

 private:
  ~Session() {
    std::lock_guard<std::mutex> lock(mutex_);
    stop();
    for (Slot* s : slots_) {
      hdDisableDevice(s->handle);
      delete s;
    }
    slots_.clear();
  }
  void start();   // schedules servo_frame and starts the scheduler if any device is open
  void stop();    // stops the scheduler and unschedules servo_frame if running
  static HDCallbackCode HDCALLBACK servo_frame(void* data);
  static HDCallbackCode HDCALLBACK one_frame(void*) { return HD_CALLBACK_DONE; }

  std::mutex mutex_;            // guards everything below; graspsim's threads only
  std::vector<Slot*> slots_;    // open devices, in the order they were opened
  HDSchedulerHandle callback_ = 0;
  bool running_ = false;
};

void Session::start() {
  if (running_ || slots_.empty()) return;
  callback_ = hdScheduleAsynchronous(&Session::servo_frame, this, HD_MAX_SCHEDULER_PRIORITY);
  HDErrorInfo e = take_error();
  if (!HD_DEVICE_ERROR(e)) {
    hdStartScheduler();
    e = take_error();
  }
  if (HD_DEVICE_ERROR(e)) throw std::runtime_error("OpenHaptics: the HD scheduler did not start: " +
                                                   describe_error(e));
  running_ = true;
  // Wait for one whole servo frame (synchronous calls run after the higher-priority servo
  // callback of the same frame), so every device has published a real sample before anyone
  // reads: never a silent zero position.
  hdScheduleSynchronous(&Session::one_frame, nullptr, HD_MIN_SCHEDULER_PRIORITY);
  e = take_error();
  if (HD_DEVICE_ERROR(e))
    throw std::runtime_error("OpenHaptics: the HD scheduler did not run: " + describe_error(e));
}

void Session::stop() {
  if (!running_) return;
  hdStopScheduler();
  hdUnschedule(callback_);
  take_error();   // unscheduling a callback the stop already removed is harmless
  running_ = false;
}

HDCallbackCode HDCALLBACK Session::servo_frame(void* data) {
  auto* self = static_cast<Session*>(data);
  for (Slot* s : self->slots_) {
    std::array<double, 3> position{0.0, 0.0, 0.0}, gimbal{0.0, 0.0, 0.0};
    HDint buttons = 0;
    const double t = static_cast<double>(s->frame) / s->rate;   // s, the device's frame clock
    hdMakeCurrentDevice(s->handle);
    hdBeginFrame(s->handle);
    hdGetDoublev(HD_CURRENT_POSITION, position.data());
    hdGetDoublev(HD_CURRENT_GIMBAL_ANGLES, gimbal.data());
    hdGetIntegerv(HD_CURRENT_BUTTONS, &buttons);
    // Take graspsim's latest request and release if the mailbox is free; otherwise hold. A
    // release re-arms the ramp; the zero it sent is not a request of its own (a request made
    // after it is, and ramps in from this frame).
    bool fresh = false, released = false;
    std::array<double, 3> request{0.0, 0.0, 0.0};
    if (s->box.mutex.try_lock()) {
      if (s->box.releases != s->seen_releases) {
        s->seen_releases = s->box.releases;
        released = true;
      }
      if (s->box.requests != s->seen_requests) {
        s->seen_requests = s->box.requests;
        request = s->box.force_hd;
        fresh = !released || s->box.requests != s->box.released_at;
      }
      s->box.mutex.unlock();
    }
    s->frames_since_request = fresh ? 0 : s->frames_since_request + 1;
    // Zero (and the ramp re-armed) after a release, a stall, or for good after an HD error.
    const bool faulted = HD_DEVICE_ERROR(s->fault);
    if (released || faulted || s->frames_since_request >= kStallFrames) s->safety->release();
    if (fresh && !faulted) s->safety->request(Vec3(request[0], request[1], request[2]), t);
    // Every frame: the thermal state advances over the frame with the force held in it.
    const Vec3 out = s->safety->output(t);
    const std::array<double, 3> force{out.x(), out.y(), out.z()};
    hdSetDoublev(HD_CURRENT_FORCE, force.data());
    hdEndFrame(s->handle);
    const HDErrorInfo e = take_error();
    if (HD_DEVICE_ERROR(e) && !HD_DEVICE_ERROR(s->fault)) s->fault = e;   // zero from next frame
    if (s->box.mutex.try_lock()) {
      s->box.position_mm = position;
      s->box.gimbal = gimbal;
      s->box.buttons = static_cast<std::uint32_t>(buttons);
      s->box.frame = s->frame;
      s->box.fault = s->fault;   // published on the first frame the mailbox is free
      s->box.mutex.unlock();
    }
    ++s->frame;
  }
  return HD_CALLBACK_CONTINUE;
}

// The configured names to try for `name`: the default device goes by several names across
// OpenHaptics versions ("Default PHANToM" before 3.4, "Default Device" after) and by
// HD_DEFAULT_DEVICE; any other name is tried alone, so a typo never opens some other device.
std::vector<const char*> names_to_try(const std::string& name) {
  static const char* const kAliases[] = {"Default Device", "Default PHANToM"};
  auto lower = [](const std::string& s) {
    std::string out;
    for (char c : s) out += static_cast<char>(c >= 'A' && c <= 'Z' ? c - 'A' + 'a' : c);
    return out;
  };
  const std::string key = lower(name);
  const bool is_default = key.empty() || key == "default" || key == lower(kAliases[0]) ||
                          key == lower(kAliases[1]);
  if (!is_default) return {name.c_str()};
  std::vector<const char*> names;
  if (!key.empty() && key != "default") names.push_back(name.c_str());   // as written, first
  for (const char* alias : kAliases)
    if (lower(alias) != key) names.push_back(alias);
  names.push_back(HD_DEFAULT_DEVICE);
  return names;
}

Slot* Session::open(const std::string& name, const OpenHapticsOptions& options) {
  // hdInitDevice is not for a running scheduler: pause it (a start-up step; forces are zero).
  stop();
  auto* slot = new Slot;
  slot->requested = name;
  std::string tried;
  for (const char* candidate : names_to_try(name)) {
    const HHD h = hdInitDevice(candidate);
    const HDErrorInfo e = take_error();
    if (h != HD_INVALID_HANDLE && !HD_DEVICE_ERROR(e)) {
      slot->handle = h;
      slot->opened = candidate ? candidate : "";
      break;
    }
    if (h != HD_INVALID_HANDLE) hdDisableDevice(h);
    if (!tried.empty()) tried += "; ";
    tried += (candidate ? quoted(candidate) : std::string("HD_DEFAULT_DEVICE")) + " -> " +
             (HD_DEVICE_ERROR(e) ? describe_error(e) : "no handle and no HD error");
  }
  auto fail = [&](const std::string& what) {
    if (slot->handle != HD_INVALID_HANDLE) {
      hdDisableDevice(slot->handle);
      take_error();
    }
    delete slot;
    try {
      start();   // the devices already open go on
    } catch (const std::exception&) {
    }
    throw std::runtime_error("OpenHaptics device " + quoted(name) + ": " + what);
  };
  if (slot->handle == HD_INVALID_HANDLE)
    fail("could not be opened; names tried: " + tried +
         ". Check the name in Phantom Configuration (Touch Setup), that the device is plugged "
         "in and powered, and the permissions on its port (hw/README.md)");
  hdMakeCurrentDevice(slot->handle);
  hdEnable(HD_FORCE_OUTPUT);
  if (const HDErrorInfo e = take_error(); HD_DEVICE_ERROR(e))
    fail("opened as " + quoted(slot->opened) + " but force output could not be enabled: " +
         describe_error(e));
  HDdouble peak = 0.0, continuous = 0.0, stiffness = 0.0;
  hdGetDoublev(HD_NOMINAL_MAX_FORCE, &peak);
  hdGetDoublev(HD_NOMINAL_MAX_CONTINUOUS_FORCE, &continuous);
  hdGetDoublev(HD_NOMINAL_MAX_STIFFNESS, &stiffness);
  if (const HDErrorInfo e = take_error(); HD_DEVICE_ERROR(e))
    fail("its nominal limits could not be read: " + describe_error(e));
  // A limit that is not a positive number is never used as a silent zero or infinity.
  for (auto [what, value] : {std::pair{"HD_NOMINAL_MAX_FORCE", peak},
                             std::pair{"HD_NOMINAL_MAX_CONTINUOUS_FORCE", continuous},
                             std::pair{"HD_NOMINAL_MAX_STIFFNESS", stiffness}})
    if (!(std::isfinite(value) && value > 0.0))
      fail(std::string("reports ") + what + " = " + std::to_string(value) +
           ", not a positive number; refusing to render forces with it");
  slot->nominal = PhantomNominal{peak, continuous, stiffness * 1000.0};   // N/mm -> N/m
  // The device clock's rate: HD_UPDATE_RATE (Hz) when it gives a positive number, else the HD
  // scheduler's default (rate() says which).
  HDint rate = 0;
  hdGetIntegerv(HD_UPDATE_RATE, &rate);
  take_error();
  slot->rate = rate > 0 ? static_cast<double>(rate) : static_cast<double>(kOpenHapticsDefaultRate);
  ForceSafetyConfig safety;
  safety.peak_force = peak;
  safety.continuous_force = continuous;
  safety.thermal_time_constant = options.thermal_time_constant;
  safety.rise_time = options.rise_time;
  safety.stall_timeout = static_cast<double>(kStallFrames) / slot->rate;   // the servo's own stall
  try {
    slot->safety.emplace(safety);
  } catch (const std::invalid_argument& e) {
    fail(std::string("its force safety cannot be set up from its nominal limits: ") + e.what());
  }
  const HDstring model = hdGetString(HD_DEVICE_MODEL_TYPE);
  take_error();   // the model is only for messages
  slot->model = model ? model : "";
  slots_.push_back(slot);
  try {
    start();
  } catch (const std::exception& ex) {
    slots_.pop_back();
    fail(ex.what());
  }
  return slot;
}

void Session::close(Slot* slot) {
  {
    std::lock_guard<std::mutex> lock(slot->box.mutex);
    slot->box.force_hd = {0.0, 0.0, 0.0};
    ++slot->box.requests;
  }
  // One more whole frame so the zero reaches the motors before the device is disabled.
  if (running_) hdScheduleSynchronous(&Session::one_frame, nullptr, HD_MIN_SCHEDULER_PRIORITY);
  stop();
  hdDisableDevice(slot->handle);
  take_error();
  for (auto it = slots_.begin(); it != slots_.end(); ++it)
    if (*it == slot) {
      slots_.erase(it);
      break;
    }
  delete slot;
  start();
}

class PhantomDevice final : public OpenHapticsDevice {
 public:
  explicit PhantomDevice(Slot* slot) : slot_(slot) {}
  ~PhantomDevice() override {
    Session& session = Session::instance();
    std::lock_guard<std::mutex> lock(session.mutex());
    try {
      session.close(slot_);
    } catch (const std::exception&) {
      // A destructor must not throw; the device is disabled and its force was zeroed first.
    }
  }
  PhantomDevice(const PhantomDevice&) = delete;
  PhantomDevice& operator=(const PhantomDevice&) = delete;

  // The latest servo-frame sample in the device frame (m, rad). `tick` and `time` are graspsim's
  // clock; the device runs on its own. Throws if HD reported an error in a servo frame.
  DeviceSample read(std::int64_t, double) override {
    DeviceSample s;
    HDErrorInfo fault{HD_SUCCESS, 0, HD_INVALID_HANDLE};
    {
      std::lock_guard<std::mutex> lock(slot_->box.mutex);
      const auto& p = slot_->box.position_mm;
      s.position = hd_to_device({p[0] / 1000.0, p[1] / 1000.0, p[2] / 1000.0});
      s.gimbal = Vec3(slot_->box.gimbal[0], slot_->box.gimbal[1], slot_->box.gimbal[2]);
      s.buttons = slot_->box.buttons;
      fault = slot_->box.fault;
      new_frames_ = slot_->box.frame - frame_;
      frame_ = slot_->box.frame;
    }
    if (HD_DEVICE_ERROR(fault))
      throw std::runtime_error("OpenHaptics device " + quoted(slot_->requested) +
                               " reported an error in its servo loop, its force is now zero: " +
                               describe_error(fault));
    return s;
  }
  DeviceLimits limits() const override { return DeviceLimits{slot_->nominal.max_force}; }
  std::string describe() const override {
    return "phantom " + quoted(slot_->opened.empty() ? "HD_DEFAULT_DEVICE" : slot_->opened) +
           (slot_->model.empty() ? "" : " (" + slot_->model + ")");
  }
  PhantomNominal nominal() const override { return slot_->nominal; }
  std::string config_name() const override { return slot_->opened; }
  double rate() const override { return slot_->rate; }
  // s: the last read sample's servo frame on the device clock, k / rate.
  bool has_sample_clock() const override { return true; }
  double sample_time() const override { return static_cast<double>(frame_) / slot_->rate; }
  std::int64_t sample_sequence() const override { return frame_; }   // its servo frame k
  std::int64_t new_samples() const override { return new_frames_; }  // frames since the read before

 protected:
  // `force` (N, device frame) is already clamped by Device::render.
  void output(const Vec3& force) override {
    const std::array<double, 3> f = device_to_hd(force);
    std::lock_guard<std::mutex> lock(slot_->box.mutex);
    slot_->box.force_hd = f;
    ++slot_->box.requests;
  }
  // After release()'s zero: the servo callback re-arms the ramp (ForceSafety::release).
  void on_release() override {
    std::lock_guard<std::mutex> lock(slot_->box.mutex);
    ++slot_->box.releases;
    slot_->box.released_at = slot_->box.requests;
  }

 private:
  Slot* slot_;   // owned by the Session while the device is open
  std::int64_t frame_ = -1;       // servo frame of the last read sample (-1: none read yet)
  std::int64_t new_frames_ = 0;   // frames between the previous read's sample and the last
};

}  // namespace

std::unique_ptr<Device> make_openhaptics_device(const std::string& device_name,
                                                const OpenHapticsOptions& options) {
  Session& session = Session::instance();
  std::lock_guard<std::mutex> lock(session.mutex());
  return std::make_unique<PhantomDevice>(session.open(device_name, options));
}

}  // namespace graspsim::hw
