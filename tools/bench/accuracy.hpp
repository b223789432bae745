// The contact accuracy scenes (contact_accuracy.hpp) as cases of graspsim_bench: rows of
// bench.csv for the work-precision chart, and one table of their figures per scheme and rate.
#pragma once

#include <string>
#include <vector>

#include "bench/row.hpp"

namespace graspsim::bench {

// The case names, in the order they run: a cube at rest, on a 24 degree slope (sticks), on a
// 30 degree slope (slides), and settling after a drop (its cost per physics step).
inline const std::vector<std::string> kAccuracyCases{"cube_rest", "slope_stick", "slope_slide", "cube_settle"};

// The figures of one scheme at one physics rate; NaN where a scene was not run, was refused by
// validate() or diverged (its status says which).
struct AccuracyFigures {
  Integrator scheme = Integrator::kPaper;
  int rate = 0;                                             // Hz: physics
  std::string status = "ok";                                // the first of its scenes' that is not ok
  double rest_depth = NAN;                                  // m: |z - 0.05| of the resting cube at 1 s
  double rest_tilt = NAN;                                   // rad: its tilt at 1 s
  double creep = NAN;                                       // m: along the 24 degree slope in 1 s
  double creep_late = NAN;                                  // m: of which in the second half second
  double slide = NAN, slide_ref = NAN;                      // m: down the 30 degree slope in 1 s
  double step_ns = NAN, step_ns_min = NAN, step_ns_max = NAN;   // ns wall per physics step,
                                                                //   settling (median, min, max)
  double step_ns_cpu = NAN;     // ns of this thread's CPU per physics step, settling (median):
                                //   steadier than wall time on a loaded machine
  double step_ns_alone = NAN;   // ns wall per physics step, settling, every loop at the physics
                                //   rate (no idle servo and haptic ticks between physics steps)
};

// Runs the wanted cases at every rate under both schemes, `repeats` timed runs each after a
// warm-up; appends one Row per case x scheme x rate to `rows` and returns the figures (none when
// no contact accuracy case is wanted).
std::vector<AccuracyFigures> run_contact_accuracy(const std::vector<std::string>& cases,
                                                  const std::vector<int>& rates, int repeats,
                                                  std::vector<Row>& rows);

// Prints the figures as one table, with the targets, to stdout.
void print_contact_accuracy(const std::vector<AccuracyFigures>& figures);

}  // namespace graspsim::bench
