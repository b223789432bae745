// The `graspsim` Python module: thin bindings of a run stepped from Python (session.hpp, over
// app::RunSession) and of recordings/' trace reader. Values cross as numpy arrays, in the
// engine's units (m, m/s, rad/s, N, N m, s); no physics and no file format here.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <cmath>
#include <sstream>
#include <stdexcept>

#include "app/output_file.hpp"
#include "graspsim/engine/math.hpp"
#include "graspsim/recordings/trace_reader.hpp"
#include "graspsim/recordings/trace_writer.hpp"
#include "session.hpp"

namespace py = pybind11;
using graspsim::Vec3;
using graspsim::python::LoadArgs;
using graspsim::python::Session;

namespace {

// An (n, width) float64 array filled by fill(i, row).
template <typename Fill>
py::array_t<double> rows(std::size_t n, std::size_t width, Fill fill) {
  py::array_t<double> a({n, width});
  auto v = a.template mutable_unchecked<2>();
  for (std::size_t i = 0; i < n; ++i) fill(i, &v(i, 0));
  return a;
}
template <typename Get>
py::array_t<double> vec3s(std::size_t n, Get get) {
  return rows(n, 3, [&](std::size_t i, double* out) {
    const Vec3 x = get(i);
    for (int k = 0; k < 3; ++k) out[k] = x[k];
  });
}
template <typename T, typename Get>
py::array_t<T> scalars(std::size_t n, Get get) {
  py::array_t<T> a(n);
  auto v = a.template mutable_unchecked<1>();
  for (std::size_t i = 0; i < n; ++i) v(i) = static_cast<T>(get(i));
  return a;
}

Vec3 to_vec3(const py::handle& x, const char* what) {
  const auto a = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(x);
  if (!a || a.ndim() != 1 || a.shape(0) != 3)
    throw py::value_error(std::string(what) + " needs three numbers (x, y, z)");
  return Vec3(a.at(0), a.at(1), a.at(2));
}

// One `set` value as --set takes it: text as given, a number in full (repr: the shortest text
// that reads back as the same double; an integer exactly), a sequence of numbers joined by commas (gravity=0,0,-9.81).
std::string set_value(const py::handle& v, const std::string& name) {
  if (py::isinstance<py::str>(v)) return v.cast<std::string>();
  if (py::isinstance<py::bool_>(v)) return v.cast<bool>() ? "true" : "false";
  // Any integral or real number (numpy's scalars too, whose repr under numpy 2 is
  // "np.float64(0.5)") as a Python int or float first: repr of those is plain digits.
  const py::module_ numbers = py::module_::import("numbers");
  const py::module_ builtins = py::module_::import("builtins");   // int(), float(): exact types, even of a subclass
  if (py::isinstance(v, numbers.attr("Integral"))) return py::repr(builtins.attr("int")(v)).cast<std::string>();
  if (py::isinstance(v, numbers.attr("Real"))) return py::repr(builtins.attr("float")(v)).cast<std::string>();
  if (py::isinstance<py::sequence>(v)) {
    std::string s;
    for (const auto& x : v.cast<py::sequence>()) s += (s.empty() ? "" : ",") + set_value(x, name);
    return s;
  }
  throw py::type_error("set['" + name + "']: a str, a number or a sequence of numbers, got " +
                       py::repr(v).cast<std::string>());
}

std::vector<std::string> set_list(const py::object& set) {
  std::vector<std::string> out;
  if (set.is_none()) return out;
  if (py::isinstance<py::dict>(set)) {
    for (const auto& [k, v] : set.cast<py::dict>()) {
      const std::string name = py::str(k);
      if (name.empty() || name.find('=') != std::string::npos)
        throw py::value_error("set: '" + name + "' is not a field name (NAME = VALUE)");
      out.push_back(name + "=" + set_value(v, name));
    }
    return out;
  }
  if (py::isinstance<py::str>(set)) throw py::type_error("set: a dict {NAME: VALUE} or a list of \"NAME=VALUE\", got a str");
  for (const auto& item : set.cast<py::sequence>()) {
    const std::string s = py::str(item);
    if (s.find('=') == std::string::npos || s.front() == '=')
      throw py::value_error("set: '" + s + "' is not NAME=VALUE");
    out.push_back(s);
  }
  return out;
}

// A file name from a str or an os.PathLike (pathlib.Path).
std::string fspath(const py::object& file) {
  return py::str(py::module_::import("os").attr("fspath")(file)).cast<std::string>();
}

const char* phase_name(graspsim::ContactPhase p) {
  switch (p) {
    case graspsim::ContactPhase::kStick: return "stick";
    case graspsim::ContactPhase::kSlip: return "slip";
    default: return "free";
  }
}

// What a finger touches, by name: an object, "floor" or "" (free).
std::string touching(const graspsim::Model& m, int body) {
  if (body == graspsim::kFloor) return "floor";
  if (body < 0) return "";
  return m.bodies[static_cast<std::size_t>(body)].name;
}

py::dict result_dict(const graspsim::app::RunResult& r) {
  py::list expectations;
  for (const auto& e : r.expectations)
    expectations.append(py::dict(py::arg("what") = e.what, py::arg("passed") = e.passed, py::arg("detail") = e.detail));
  py::dict d;
  d["passed"] = r.passed();
  d["expectations"] = expectations;
  d["error"] = r.error;
  d["trace"] = r.trace_path.empty() ? py::object(py::none()) : py::object(py::str(r.trace_path));
  d["trace_error"] = r.trace_error;
  d["warnings"] = r.warnings;
  d["servo_ticks"] = r.servo_ticks;
  d["haptic_ticks"] = r.haptic_ticks;
  d["physics_ticks"] = r.physics_ticks;
  d["simulated"] = r.simulated;
  d["wall"] = r.wall;
  return d;
}

// A stepped tick that ended the run (a script error, a device fault, a divergence): the run is
// finished, its trace marked "error: ...", and Python hears of it at once.
void raise_if_failed(Session& s) {
  if (s.run().error().empty()) return;
  const std::string error = s.run().error();
  s.run().finish();
  throw graspsim::python::RunError(error);
}

}  // namespace

namespace {

// The session, refused while step() or run() runs in another Python thread (Session::busy).
template <typename S>
S& idle(S& s) {
  if (s.busy) throw std::runtime_error("session is busy: step() or run() is running in another thread");
  return s;
}

// Marks the session busy for a scope (with the GIL held at both ends).
struct BusyScope {
  Session& s;
  explicit BusyScope(Session& session) : s(idle(session)) { s.busy = true; }
  ~BusyScope() { s.busy = false; }
};

// Steps up to n ticks, with the GIL released, Ctrl-C seen every kSignalTicks ticks (between two
// ticks: the session stays usable). Returns the ticks run.
constexpr std::int64_t kSignalTicks = 3000;
std::int64_t step_ticks(Session& s, std::int64_t n) {
  if (n < 0) throw py::value_error("step(n): n is a number of servo ticks >= 0, got " + std::to_string(n));
  std::int64_t done = 0;
  const BusyScope busy(s);
  while (done < n) {
    const std::int64_t chunk = std::min(kSignalTicks, n - done);
    std::int64_t ran = 0;
    {
      py::gil_scoped_release release;
      while (ran < chunk && s.run().step()) ++ran;
    }
    done += ran;
    raise_if_failed(s);
    if (ran < chunk) break;
    if (PyErr_CheckSignals() != 0) throw py::error_already_set();
  }
  return done;
}

py::dict state_dict(const Session& s) {
  idle(s);
  const graspsim::Simulation& sim = s.run().simulation();
  const graspsim::State& st = sim.state();
  const std::size_t nb = st.bodies.size();
  py::array_t<double> rotation({nb, std::size_t{3}, std::size_t{3}});
  auto r = rotation.mutable_unchecked<3>();
  for (std::size_t b = 0; b < nb; ++b)
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) r(b, i, j) = st.bodies[b].rotation(i, j);
  py::dict bodies;
  bodies["position"] = vec3s(nb, [&](std::size_t b) { return st.bodies[b].position; });
  bodies["rotation"] = rotation;
  // w, x, y, z with w >= 0: the engine's own conversion, as the trace's orientation column.
  bodies["orientation"] = rows(nb, 4, [&](std::size_t b, double* out) {
    const graspsim::Quat q = graspsim::quat_of(st.bodies[b].rotation);
    out[0] = q.w(), out[1] = q.x(), out[2] = q.y(), out[3] = q.z();
  });
  bodies["velocity"] = vec3s(nb, [&](std::size_t b) { return st.bodies[b].velocity; });
  bodies["angular_velocity"] = vec3s(nb, [&](std::size_t b) { return st.bodies[b].angular_velocity; });
  bodies["asleep"] = scalars<bool>(nb, [&](std::size_t b) { return st.bodies[b].asleep; });
  py::list phase, touch;
  for (const auto& f : st.fingers) {
    phase.append(phase_name(f.phase));
    touch.append(touching(s.model(), f.body));
  }
  py::dict fingers;
  fingers["phase"] = phase;
  fingers["touching"] = touch;
  py::dict d;
  d["tick"] = st.tick;
  d["time"] = sim.time();
  d["bodies"] = bodies;
  d["fingers"] = fingers;
  return d;
}

py::dict records_dict(const Session& s) {
  idle(s);
  const graspsim::TickRecord& r = s.run().record();
  const graspsim::Input& in = s.run().input();
  const std::size_t nf = r.servo.size(), nb = r.physics.size();
  py::dict servo;
  servo["hip"] = vec3s(nf, [&](std::size_t f) { return r.servo[f].hip; });
  servo["force"] = vec3s(nf, [&](std::size_t f) { return r.servo[f].force; });
  servo["gimbal"] = vec3s(in.fingers.size(), [&](std::size_t f) { return in.fingers[f].gimbal; });
  py::dict haptic;
  haptic["god_object"] = vec3s(nf, [&](std::size_t f) { return r.haptic[f].god_object; });
  haptic["surface_point"] = vec3s(nf, [&](std::size_t f) { return r.haptic[f].surface_point; });
  haptic["depth"] = scalars<double>(nf, [&](std::size_t f) { return r.haptic[f].depth; });
  haptic["friction_radius"] = scalars<double>(nf, [&](std::size_t f) { return r.haptic[f].friction_radius; });
  haptic["force"] = vec3s(nf, [&](std::size_t f) { return r.haptic[f].force; });
  haptic["phase"] = scalars<std::int8_t>(nf, [&](std::size_t f) { return static_cast<int>(r.haptic[f].phase); });
  haptic["body"] = scalars<std::int32_t>(nf, [&](std::size_t f) { return r.haptic[f].body; });
  haptic["slip"] = scalars<double>(nf, [&](std::size_t f) { return r.haptic[f].slip; });
  py::list touch;
  for (std::size_t f = 0; f < nf; ++f) touch.append(touching(s.model(), r.haptic[f].body));
  haptic["touching"] = touch;
  py::dict physics;
  physics["position"] = vec3s(nb, [&](std::size_t b) { return r.physics[b].position; });
  physics["orientation"] = rows(nb, 4, [&](std::size_t b, double* out) {
    const auto& q = r.physics[b].orientation;
    out[0] = q.w(), out[1] = q.x(), out[2] = q.y(), out[3] = q.z();
  });
  physics["velocity"] = vec3s(nb, [&](std::size_t b) { return r.physics[b].velocity; });
  physics["angular_velocity"] = vec3s(nb, [&](std::size_t b) { return r.physics[b].angular_velocity; });
  physics["force"] = vec3s(nb, [&](std::size_t b) { return r.physics[b].force; });
  physics["torque"] = vec3s(nb, [&](std::size_t b) { return r.physics[b].torque; });
  physics["floor_contacts"] = scalars<std::int32_t>(nb, [&](std::size_t b) { return r.physics[b].floor_contacts; });
  physics["body_contacts"] = scalars<std::int32_t>(nb, [&](std::size_t b) { return r.physics[b].body_contacts; });
  py::dict d;
  d["tick"] = r.tick;
  d["haptic_ran"] = r.haptic_ran;
  d["physics_ran"] = r.physics_ran;
  d["servo"] = servo;
  d["haptic"] = haptic;
  d["physics"] = physics;
  return d;
}

// A dataset as numpy, in its stored type (integers exact, uint64 hashes from their bits).
py::array dataset_array(const graspsim::recordings::Dataset& d) {
  using graspsim::recordings::DType;
  std::vector<py::ssize_t> shape(d.shape.begin(), d.shape.end());
  const auto fill = [&](auto tag) {
    using T = decltype(tag);
    py::array_t<T> a(shape);
    T* out = a.mutable_data();
    for (std::size_t i = 0; i < d.values.size(); ++i) out[i] = static_cast<T>(d.values[i]);
    return py::array(a);
  };
  switch (d.dtype) {
    case DType::kInt64: return fill(std::int64_t{});
    case DType::kInt32: return fill(std::int32_t{});
    case DType::kInt8: return fill(std::int8_t{});
    case DType::kUInt64: {
      py::array_t<std::uint64_t> a(shape);
      std::copy(d.bits.begin(), d.bits.end(), a.mutable_data());
      return a;
    }
    default: return fill(double{});
  }
}

}  // namespace

PYBIND11_MODULE(graspsim, m) {
  m.doc() = "graspsim: a deterministic multi-rate simulator of multi-finger haptic grasping (python/README.md)";
  // Every error of the module is a graspsim.Error; the class says what went wrong. (The C++
  // type only names the Python class: nothing throws it.)
  struct AnyError {};
  static py::exception<AnyError> error(m, "Error");
  py::register_exception<graspsim::scripting::ScenarioError>(m, "ScenarioError", error.ptr());
  py::register_exception<graspsim::app::DeviceError>(m, "DeviceError", error.ptr());
  py::register_exception<graspsim::app::OutputError>(m, "OutputError", error.ptr());
  py::register_exception<graspsim::recordings::TraceError>(m, "TraceError", error.ptr());
  py::register_exception<graspsim::python::RunError>(m, "RunError", error.ptr());

  py::class_<Session>(m, "Session",
                      "A scenario's run, stepped from Python one servo tick at a time (graspsim.load)")
      .def("step", &step_ticks, py::arg("n") = 1,
           "Runs the next n servo ticks (default 1); returns how many ran (fewer at the run's end). "
           "A tick that ends the run (a script error, a divergence) raises graspsim.RunError.")
      .def(
          "run",
          [](Session& s) {
            step_ticks(s, idle(s).run().ticks() - s.run().tick());
            return result_dict(s.run().finish());
          },
          "Runs to the end, checks the expectations due there, finishes the trace; returns the result")
      .def(
          "finish", [](Session& s) { return result_dict(idle(s).run().finish()); },
          "Ends the run at this tick (expectations due later: not checked), finishes the trace; "
          "returns the result. Later calls return the same result.")
      .def("__enter__", [](Session& s) -> Session& { return s; })
      .def("__exit__", [](Session& s, py::args) { idle(s).run().finish(); })
      .def_property_readonly("tick", [](const Session& s) { return idle(s).run().tick(); },
                             "servo ticks run so far (the next tick's number)")
      .def_property_readonly("ticks", [](const Session& s) { return idle(s).run().ticks(); },
                             "servo ticks of the whole run (duration * servo rate)")
      .def_property_readonly("time", [](const Session& s) { return idle(s).run().simulation().time(); },
                             "s: simulated time, tick / servo rate")
      .def_property_readonly("done", [](const Session& s) { return idle(s).run().done(); })
      .def_property_readonly("duration", [](const Session& s) { return s.scenario().duration(); }, "s")
      .def_property_readonly("name", [](const Session& s) { return s.scenario().name(); })
      .def_property_readonly("rates",
                             [](const Session& s) {
                               const auto& r = s.model().rates;
                               return py::dict(py::arg("servo") = r.servo, py::arg("haptic") = r.haptic,
                                               py::arg("physics") = r.physics);
                             }, "Hz: the three loops' rates")
      .def_property_readonly("fingers",
                             [](const Session& s) {
                               std::vector<std::string> n;
                               for (const auto& f : s.model().fingers) n.push_back(f.name);
                               return n;
                             })
      .def_property_readonly("bodies",
                             [](const Session& s) {
                               std::vector<std::string> n;
                               for (const auto& b : s.model().bodies) n.push_back(b.name);
                               return n;
                             })
      .def(
          "hip",
          [](const Session& s, const std::string& finger) {
            const Vec3 h = idle(s).run().input().fingers.at(s.finger(finger)).hip;
            return vec3s(1, [&](std::size_t) { return h; }).attr("reshape")(3);
          },
          py::arg("finger"), "m, world: the finger's HIP as its device gave it at the last tick")
      .def(
          "set_hip",
          [](Session& s, const std::string& finger, const py::object& hip, const py::object& gimbal) {
            const Vec3 g = gimbal.is_none() ? Vec3::Zero() : to_vec3(gimbal, "gimbal");
            idle(s).driven(s.finger(finger)).set(to_vec3(hip, "hip"), g);
          },
          py::arg("finger"), py::arg("hip"), py::arg("gimbal") = py::none(),
          "Sets a driven finger's HIP (m, world) and gimbal angles (rad: roll, pitch, yaw; default 0) "
          "from the next tick on, as its device would; the finger must be in load(..., drive=[...])")
      .def(
          "follow_trajectory", [](Session& s, const std::string& finger) { idle(s).driven(s.finger(finger)).follow_trajectory(); },
          py::arg("finger"), "Hands a driven finger back to its scenario trajectory from the next tick on")
      .def(
          "rendered_force",
          [](Session& s, const std::string& finger) {
            const Vec3 f = idle(s).driven(s.finger(finger)).last_force();
            return vec3s(1, [&](std::size_t) { return f; }).attr("reshape")(3);
          },
          py::arg("finger"), "N, world: the force a driven finger's device rendered at the last tick (clamped)")
      .def("state", &state_dict, "The engine state now (bodies' pose and velocities; fingers' contact) as numpy")
      .def("records", &records_dict, "The last tick's records (servo, haptic, physics) as numpy");

  m.def(
      "load",
      [](const py::object& path, const py::object& set, const py::object& trace, const py::object& record,
         int compression, const std::vector<std::string>& drive) {
        LoadArgs args;
        args.path = fspath(path);
        args.sets = set_list(set);
        if (!trace.is_none()) args.trace = fspath(trace);
        if (!record.is_none()) args.record = record.cast<std::string>();
        args.compression = compression;
        args.drive = drive;
        return std::make_unique<Session>(args);
      },
      py::arg("path"), py::arg("set") = py::none(), py::arg("trace") = py::none(), py::arg("record") = py::none(),
      py::arg("compression") = 0, py::arg("drive") = std::vector<std::string>{},
      "Loads a scenario and prepares its run (python/README.md). set: {NAME: VALUE} or [\"NAME=VALUE\"] "
      "(as --set); trace: the trace's path, or None for no trace; record: \"LOOP[:EVERY],...\" (as "
      "--record); compression: deflate level 0-9; drive: fingers whose HIP Python sets (set_hip).");

  m.def(
      "read_trace",
      [](const py::object& file) {
        const std::string path = fspath(file);
        py::dict d;
        // Each table read once, whatever its layout (a 1000-object /physics is one pass).
        for (const auto& [name, dataset] : graspsim::recordings::read_trace(path))
          d[py::str(name)] = dataset_array(dataset);
        return d;
      },
      py::arg("path"), "Every dataset of a trace, {\"/physics/objects/box/position\": array, ...}, in its stored type");
  m.def(
      "trace_attribute",
      [](const py::object& file, const std::string& name, const std::string& object) -> py::object {
        const std::string path = fspath(file);
        try {
          return py::str(graspsim::recordings::read_string_attribute(path, object, name));
        } catch (const graspsim::recordings::TraceError&) {
          return py::float_(graspsim::recordings::read_double_attribute(path, object, name));
        }
      },
      py::arg("path"), py::arg("name"), py::arg("object") = "/",
      "An attribute of a trace (a root attribute by default: \"status\", \"record\", \"scenario_source\", ...)");
}
