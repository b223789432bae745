// The robustness harness: a library scenario run through the real run loop with its waypoints
// perturbed (LoadOptions::jitter) and/or fingers on the simulated Phantom, and what the run did:
// its expectations, any non-finite number anywhere in its trace, how far each body went, and how
// many fingers held one body at once. Shared by tests/e2e/test_robustness.cpp (10 seeds, CI) and
// graspsim_bench --cases robustness (100 seeds per scenario, tools/bench/README.md).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "graspsim/scripting/scenario.hpp"

namespace graspsim::robustness {

// The scene a body may not leave. Its centre stays within kSceneRadius of where it started: the
// library's intended motions move a centre at most 0.28 m (lift_and_place's carry and lift; the
// others 0.14 m or less, measured unperturbed), so 1 m is room for every intended motion and for
// a dropped body, while a body thrown by an unstable step (17 to 39 m in gravity_drop) is far
// outside it. Its centre stays above the floor less kFloorMargin: a body at rest has its centre
// above the floor by half its height less its sink (m g / (4 k) per corner: 9.8 mm at most in the
// library, under any body's half height), so a centre below the floor means the body went half
// through it; 1 cm below allows the thinnest body (plate_push's 2 mm plate, centre 1 mm up)
// its sink and a bounce.
inline constexpr double kSceneRadius = 1.0;    // m
inline constexpr double kFloorMargin = 0.01;   // m

// A period-2 cycle: a velocity component of a body that reverses sign at every physics step, above
// kFlipSpeed (m/s) or kFlipSpin (rad/s), for kFlipSteps steps in a row. That is the step's own
// Nyquist mode (a period of two steps: 25 Hz at 50 Hz), which an explicit step shows when a coupled
// mode is too stiff for it (its eigenvalue near or beyond -1: the lift rocking at 11 rad/s,
// README.md "Stability warnings"). It is no motion of the scene: a physical oscillation sampled
// every step reverses at every step only near half the physics rate, far above the soft couplings
// of the library's scenes (two 400 N/m fingers on a 0.4 kg box: sqrt(2 k / m) = 45 rad/s, 7 Hz, a
// reversal every 3.5 steps at 50 Hz), and backward Euler damps what it cannot resolve without
// alternating (its eigenvalues 1 / (1 + i w h) have a positive real part). Eight reversals in a row
// (0.16 s at 50 Hz) are no transient of a settling contact; the thresholds are a hundred times the
// speeds the scenarios call "at rest" (0.1 mm/s and 1e-3 rad/s in their checks).
inline constexpr int kFlipSteps = 8;            // 1
inline constexpr double kFlipSpeed = 0.01;     // m/s
inline constexpr double kFlipSpin = 0.1;       // rad/s

struct Perturbation {
  double jitter = 0.0;                    // m: each waypoint offset component uniform in [-jitter, jitter)
  std::uint64_t seed = 0;                 // the jitter's seed
  std::vector<std::string> sim_phantom;   // fingers (by name) on `sim-phantom`, the others scripted
  std::vector<std::string> sets;          // --set overrides, e.g. "integrator=paper"
  std::string describe() const;           // "jitter 0.5 mm seed 3; sim-phantom on thumb; integrator=paper"
};

struct BodyPath {
  std::string name;
  double excursion = 0.0;        // m: largest |centre - initial centre| over the physics rows
  double lowest = 0.0;           // m: lowest centre height above the floor (+inf without a floor)
  double left_at = -1.0;         // s: first physics row outside the scene (-1: never)
  double max_turn = 0.0;         // rad: largest angle of its rotation from the initial orientation
  Vec3 final_position{0.0, 0.0, 0.0};   // m: centre at the last physics row
  int flips = 0;                 // 1: longest run of physics steps over which one velocity
                                 //    component reversed at every step, above kFlipSpeed/kFlipSpin
  double flip_at = -1.0;         // s: when the longest such run ended (-1: none)
  double flip_peak = 0.0;        // m/s or rad/s: the largest |component| in it
  std::string flip_what;         // "angular_velocity y" ...
};

struct Outcome {
  std::string scenario;   // scenario name
  std::string label;      // Perturbation::describe()
  std::vector<scripting::ExpectationResult> expectations;
  std::string error;      // the run stopped early (divergence, script error); "" if it ran to its end
  std::string nonfinite;  // the first trace column holding a NaN or an infinity, with its row ("" none)
  std::vector<BodyPath> bodies;   // Model::bodies order
  std::vector<std::vector<Vec3>> jitter_offsets;   // m: Scenario::jitter_offsets() of the run
  int most_fingers_on_a_body = 0; // largest number of fingers touching one body at one haptic tick
  double worst_excursion() const;   // m: over the bodies
  bool left_scene() const;          // some body left it
  bool period_two() const;          // some body had a period-2 cycle of kFlipSteps steps or more
  std::string period_two_detail() const;   // "box angular_velocity y reversed 52 steps in a row ..."
  std::string left_scene_detail() const;   // "rod left at 1.2 s: 35.3 m from its start" ("" if none)
  // The result of the expectation whose sentence contains `what`; throws std::out_of_range if none.
  const scripting::ExpectationResult& expectation(const std::string& what) const;
  const BodyPath& body(const std::string& name) const;   // throws std::out_of_range if none
};

// Runs `scenario_path` perturbed by `p`, tracing into `trace` (read back for the checks, then
// removed unless keep_trace). Throws scripting::ScenarioError or app::DeviceError on bad input
// (a scenario that does not load, an unknown finger); everything that goes wrong while it runs is
// in the Outcome.
Outcome run(const std::string& scenario_path, const Perturbation& p, const std::string& trace, bool keep_trace = false);

// The scenarios of `directory` (*.lua) that have at least one finger, by file stem, sorted.
std::vector<std::string> scenarios_with_fingers(const std::string& directory);

}  // namespace graspsim::robustness
