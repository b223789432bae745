// The stability check on the library's scenarios: the grasps the paper's 50 Hz step cannot hold
// are flagged, their faster versions are not, and every scenario the check passes runs bounded.
#include <catch2/catch.hpp>

#include <algorithm>
#include <filesystem>
#include <map>

#include "graspsim/engine/stability.hpp"
#include "tests/engine/scenario_run.hpp"

using namespace graspsim;
using namespace graspsim::test;

namespace {

// The contact set a scenario reaches at `seconds` with physics at 100 Hz (stable for all four
// grasps below) and finger `finger` moved by `offset`, as a hand placed off by `offset` would be.
struct Reached {
  scripting::Scenario scenario;
  State state;
};

Reached reach(const std::string& name, double seconds, int finger, const Vec3& offset) {
  Reached r{load_scenario(name, {"rates.physics=100"}), {}};
  Simulation sim(r.scenario.model());
  drive(r.scenario, sim, static_cast<std::int64_t>(seconds * 3000), {},
        [&](std::size_t f, double) { return static_cast<int>(f) == finger ? offset : Vec3::Zero(); });
  r.state = sim.state();
  return r;
}

}  // namespace

// Four library grasps, each with the contact set it reaches (run at 100 Hz, one finger 0.1 mm
// off), analysed under the paper's scheme at 50 Hz and at 100 Hz. The figures measured by hand
// on the runs (engine/README.md, "Stability check"), derived here where a single mode gives them:
//  - gravity_drop's rod (0.2 kg, 20 x 4 x 4 cm) pinched 8 cm off centre by two 400 N/m pads:
//    sideways motion with yaw and roll on the two springs, radius 3.89 at 50 Hz (by hand: 3.89);
//  - two_finger_lift's box squeezed on its floor (pads 400 N/m at +-4 cm, 100 N/m corners):
//    pitch about y on finger and floor springs together, each stable alone, 2.0 (by hand: 2.0);
//  - gimbal_twist's 6 cm, 0.2 kg box on two 400 N/m, 4 N s/m pads at +-3 cm: its pitch alone
//    has K = 2 k a^2 = 0.72 N m/rad, C = 2 c a^2, I = 2 m a^2 / 3, so h^2 K / I = 2.4 and
//    h C / I = 1.2: radius 1.717 (by hand: 1.72). The pads hold it 2.9 mm above its centre
//    (the hanging sag), which couples pitch with sideways translation and stiffens the mode: the
//    coupled map's radius is a little larger (1.83);
//  - three_finger_rotate's cube closed on by three fingers on its floor: pitch about y on the
//    fingers and the floor, 1.57. (A figure of 2.64 measured by hand for "a box held by three
//    fingers" is not of a library scene; this cube once lifted has radius 0.99, and is not
//    flagged.)
// Tolerance 0.5% on the figures measured by hand: they are quoted to three digits.
TEST_CASE("four library grasps are flagged at 50 Hz and not at 100 Hz", "[stability][scenario]") {
  struct Case {
    std::string scenario;
    double seconds;   // s: when the grasp has formed
    int finger;
    Vec3 offset;      // m
    double low, high; // the radius at 50 Hz lies within
  };
  const double gimbal_pitch = paper_radius_1d(2.0 * 400.0 * 9e-4 / (2.0 * 0.2 * 9e-4 / 3.0),
                                              2.0 * 4.0 * 9e-4 / (2.0 * 0.2 * 9e-4 / 3.0), 0.02);
  CHECK(gimbal_pitch == Approx(1.7165).epsilon(1e-4));
  const std::vector<Case> cases = {
      {"gravity_drop", 0.5, 0, Vec3(0.0, 0.0, 1e-4), 3.89 * 0.995, 3.89 * 1.005},
      {"two_finger_lift", 1.0, 0, Vec3(0.0, 0.0, -1e-4), 2.0 * 0.995, 2.0 * 1.005 + 0.005},
      {"gimbal_twist", 0.5, 1, Vec3(0.0, 0.0, 1e-4), gimbal_pitch, 1.1 * gimbal_pitch},
      {"three_finger_rotate", 0.5, 0, Vec3(0.0, 0.0, 1e-4), 1.5, 1.6},
  };
  for (const Case& c : cases) {
    const Reached r = reach(c.scenario, c.seconds, c.finger, c.offset);
    const Model& model = r.scenario.model();
    StabilityCheck check(model);
    const StabilityReport at50 = check.analyse(r.state, 50, Integrator::kPaper);
    const StabilityReport at100 = check.analyse(r.state, 100, Integrator::kPaper);
    INFO(c.scenario << ": " << at50.warning(model));
    REQUIRE(at50.unstable());
    const StabilityMode& mode = at50.groups[at50.worst];
    CHECK(mode.radius >= c.low);
    CHECK(mode.radius <= c.high);
    CHECK(mode.stable_physics == 100);
    CHECK(at50.warning(model).find("raise rates.physics to >= 100 Hz or use integrator = \"implicit\"") !=
          std::string::npos);
    // Every finger on the body carries the mode.
    for (std::size_t f = 0; f < model.fingers.size(); ++f) {
      CHECK(std::count(mode.springs.begin(), mode.springs.end(), "finger '" + model.fingers[f].name + "'") == 1);
    }
    CHECK_FALSE(at100.unstable());
    CHECK_FALSE(check.analyse(r.state, 50, Integrator::kImplicit).unstable());
  }
}

namespace {

// The period-2 content of a run: the largest over bodies of |w_k - 2 w_{k-1} + w_{k-2}| / 4
// (rad/s), averaged over the physics steps after 0.1 s. A motion flipping sign every step at
// amplitude A gives A; a smooth one h^2 |w''| / 4, which falls as the rate squared.
struct Run {
  double period2 = 0.0;     // rad/s
  bool bounded = true;      // every body under 100 m/s and 1000 rad/s
  bool flagged = false;     // the monitor gave a warning
  int stable_physics = 0;   // Hz: the first warning's suggestion
};

Run run(const std::string& name, int physics, bool disturbed) {
  std::vector<std::string> sets = {"integrator=paper"};   // the scheme the check watches
  if (physics > 0) sets.push_back("rates.physics=" + std::to_string(physics));
  // The disturbance: each body spun by 0.01 rad/s at t = 0 and each finger 0.1 mm off its path
  // (a direction of its own), the size of one encoder count of a real device's offset.
  if (disturbed) {
    const scripting::Scenario plain = load_scenario(name, sets);
    for (const BodyParams& b : plain.model().bodies)
      sets.push_back("objects." + b.name + ".angular_velocity=0.003,0.005,0.008");
  }
  const scripting::Scenario scenario = load_scenario(name, sets);
  const Model& model = scenario.model();
  Simulation sim(model);
  StabilityMonitor monitor(model);
  const std::size_t n = model.bodies.size();
  std::vector<Vec3> w1(n, Vec3::Zero()), w2(n, Vec3::Zero());
  Run out;
  int steps = 0;
  drive(scenario, sim, static_cast<std::int64_t>(std::llround(scenario.duration() * model.rates.servo)),
        [&](const Simulation& s) {
          if (!monitor.update(s.state()).empty() && !out.flagged) {
            out.flagged = true;
            out.stable_physics = monitor.report().groups[monitor.report().worst].stable_physics;
          }
          double e = 0.0;
          for (std::size_t b = 0; b < n; ++b) {
            const BodyState& bs = s.state().bodies[b];
            if (!(bs.velocity.norm() < 100.0 && bs.angular_velocity.norm() < 1000.0)) out.bounded = false;
            e = std::max(e, (bs.angular_velocity - 2.0 * w1[b] + w2[b]).norm() / 4.0);
            w2[b] = w1[b];
            w1[b] = bs.angular_velocity;
          }
          if (s.time() > 0.1) {
            out.period2 += e;
            ++steps;
          }
          return out.bounded;
        },
        [&](std::size_t f, double) {
          const double a = 2.1 * static_cast<double>(f);
          return disturbed ? Vec3(1e-4 * std::cos(a), 1e-4 * std::sin(a), f % 2 ? 3e-5 : -3e-5) : Vec3::Zero();
        });
  out.period2 /= std::max(1, steps);
  return out;
}

}  // namespace

// Every library scenario at its own rates under the paper's scheme. Those the check passes run
// bounded. Those it flags are listed below with the mode: each is a grasp or a stack whose
// coupled mode is unstable at the scenario's rate, and whose run stays bounded only because the
// scene is exactly symmetric (nothing excites the mode) or because a contact's friction or
// unilateral limit caps the period-2 cycle it grows into. The reason is checked, not taken on
// trust: disturbed by 0.1 mm at each finger and 0.01 rad/s on each body, the scene's period-2
// content at its own rate is at least 20 times that at the rate the warning names, where the
// check passes it (measured 51 to 1.8e6 times; a smooth motion's content falls only as the rate
// squared, 4 times from 50 to 100 Hz).
TEST_CASE("every library scenario the check passes runs bounded, and those it flags grow period-2 cycles",
          "[stability][scenario]") {
  const std::map<std::string, std::string> flagged = {
      {"dead_band", "the gravity_drop rod: sideways and yaw on two pads, 3.89 at 50 Hz"},
      {"gravity_drop", "a rod pinched 8 cm off centre: sideways and yaw on two pads, 3.89 at 50 Hz"},
      {"gimbal_twist", "a box pinched by 400 N/m pads: pitch, 1.9 to 2.4 at 50 Hz"},
      {"heavy_hold", "5 kg boxes squeezed on the floor: pitch on pads and floor, 1.48 at 50 Hz"},
      {"mesh_grasp", "a wedge pinched on the floor: yaw and roll, 3.28 at 50 Hz; the undisturbed run "
                     "already rocks at up to 25 rad/s, changing sign every step"},
      {"push_along_floor", "a box pushed on the floor: pitch on finger and floor, 1.48 at 50 Hz; the "
                           "undisturbed run already rocks every step"},
      {"stack_lift", "two boxes stacked: yaw on the floor and the pair contact, 1.41, and 3.11 once pinched"},
      {"three_finger_rotate", "a cube closed on by three fingers on its floor: pitch, 1.57 at 50 Hz"},
      {"two_finger_lift", "a box squeezed on its floor: pitch on pads and floor, 2.0 at 50 Hz"},
  };
  std::vector<std::string> names;
  for (const auto& e : std::filesystem::directory_iterator(std::string(GRASPSIM_SOURCE_DIR) + "/scenarios"))
    if (e.path().extension() == ".lua") names.push_back(e.path().stem().string());
  std::sort(names.begin(), names.end());
  REQUIRE(names.size() >= 20);
  int passed = 0;
  for (const std::string& name : names) {
    const Run own = run(name, 0, false);
    INFO(name);
    CHECK(own.bounded);
    CHECK(own.flagged == (flagged.count(name) == 1));
    if (!own.flagged) {
      ++passed;
      continue;
    }
    INFO("flagged: " << flagged.at(name));
    REQUIRE(own.stable_physics > 0);
    const Run disturbed = run(name, 0, true);
    const Run faster = run(name, own.stable_physics, true);
    INFO("period-2 content " << disturbed.period2 << " rad/s at its rate, " << faster.period2 << " at "
                             << own.stable_physics << " Hz");
    CHECK(disturbed.period2 >= 20.0 * faster.period2);
    CHECK_FALSE(faster.flagged);
    CHECK(faster.bounded);
  }
  CHECK(passed == static_cast<int>(names.size() - flagged.size()));
}
