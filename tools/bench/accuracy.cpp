// The contact accuracy cases of graspsim_bench: see accuracy.hpp.
#include "bench/accuracy.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>

#include "bench/contact_accuracy.hpp"

namespace graspsim::bench {

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kStickSlope = 24.0 * kPi / 180.0;   // rad: tan = 0.445 < mu 0.5, it sticks
constexpr double kSlideSlope = 30.0 * kPi / 180.0;   // rad: tan = 0.577 > mu 0.5, it slides

// The targets the table marks (a figure outside its target gets a '*').
constexpr double kRestDepthTarget = 1e-4;             // m
constexpr double kRestTiltTarget = 0.01 * kPi / 180;  // rad
constexpr double kCreepTarget = 1e-5;                 // m
constexpr double kSlideTarget = 0.005;                // 1: |slide / analytic - 1|
constexpr double kStepTarget = 1000.0;                // ns per physics step

// J: a run whose kinetic and gravitational energy ever rises this far above its start is marked
// unstable (contact_accuracy.hpp: a passive step gains none). The energy of lifting the 1 kg cube
// 0.1 mm, the rest target: far above round-off (1e-15 J) and far below a launch.
constexpr double kEnergyGainBound = 1e-3;

std::string status_of(bool diverged, double energy_gain) {
  if (diverged) return "unstable: diverged";
  if (energy_gain > kEnergyGainBound) return "unstable: energy gain";
  return "ok";
}

bool wants(const std::vector<std::string>& cases, const char* c) {
  return std::find(cases.begin(), cases.end(), c) != cases.end();
}

// Times one scene into `row`; a model that validate() refuses becomes the row's status.
template <class Run>
bool timed(Row& row, int repeats, double simulated, Run&& run) {
  try {
    time_it(row, repeats, simulated, run);
    return true;
  } catch (const std::invalid_argument& e) {
    row.status = std::string("refused: ") + e.what();
    row.error = NAN;
    return false;
  }
}

// The status of a scheme x rate: the first of its scenes' that is not ok.
void merge_status(AccuracyFigures& f, const Row& row) {
  if (f.status == "ok" && row.status != "ok") f.status = row.name + " " + row.status;
}

}  // namespace

std::vector<AccuracyFigures> run_contact_accuracy(const std::vector<std::string>& cases,
                                                  const std::vector<int>& rates, int repeats,
                                                  std::vector<Row>& rows) {
  const ContactSetup setup;
  std::vector<AccuracyFigures> out;
  if (std::none_of(kAccuracyCases.begin(), kAccuracyCases.end(), [&](const std::string& c) { return wants(cases, c.c_str()); }))
    return out;
  for (Integrator scheme : kSchemes)
    for (int rate : rates) {
      AccuracyFigures f;
      f.scheme = scheme;
      f.rate = rate;
      const Gyroscopic g = Model{}.gyroscopic;   // the contact scenes keep the default
      if (wants(cases, "cube_rest")) {
        Row row = make_row("cube_rest", rate, g, scheme);
        row.measure = "|z - 0.05 m| at 1 s (m)";
        RestResult r;
        if (timed(row, repeats, setup.duration, [&] { r = run_rest(rate, scheme, setup); })) {
          row.error = r.height_error;
          row.status = status_of(r.diverged, r.energy_gain);
          if (!r.diverged) {
            f.rest_depth = r.height_error;
            f.rest_tilt = r.tilt;
          }
          row.note = "tilt " + num(r.tilt * 180 / kPi) + " deg; speed " + num(r.speed) + " m/s; energy gain " +
                     num(r.energy_gain) + " J";
        }
        merge_status(f, row);
        rows.push_back(row);
      }
      if (wants(cases, "slope_stick")) {
        Row row = make_row("slope_stick", rate, g, scheme);
        row.measure = "creep on 24 deg in 1 s (m)";
        SlopeResult r;
        if (timed(row, repeats, setup.duration, [&] { r = run_slope(rate, scheme, kStickSlope, setup); })) {
          // Creep: the centre's distance moved over the floor (x down the slope, y across).
          row.error = std::hypot(r.slide, r.sideways);
          row.status = status_of(r.diverged, r.energy_gain);
          if (!r.diverged) {
            f.creep = row.error;
            f.creep_late = r.late;
          }
          row.note = "second half " + num(r.late) + " m; sink " + num(r.sink) + " m; energy gain " +
                     num(r.energy_gain) + " J";
        }
        merge_status(f, row);
        rows.push_back(row);
      }
      if (wants(cases, "slope_slide")) {
        Row row = make_row("slope_slide", rate, g, scheme);
        row.measure = "|slide / analytic - 1| on 30 deg in 1 s";
        SlopeResult r;
        const double ref = analytic_slide(kSlideSlope, setup.mu, setup.duration);
        if (timed(row, repeats, setup.duration, [&] { r = run_slope(rate, scheme, kSlideSlope, setup); })) {
          row.error = std::abs(r.slide / ref - 1.0);
          row.status = status_of(r.diverged, r.energy_gain);
          if (!r.diverged) {
            f.slide = r.slide;
            f.slide_ref = ref;
          }
          row.note = "slide " + num(r.slide) + " m (analytic " + num(ref) + " m); sink " + num(r.sink) +
                     " m; energy gain " + num(r.energy_gain) + " J";
        }
        merge_status(f, row);
        rows.push_back(row);
      }
      if (wants(cases, "cube_settle")) {
        Row row = make_row("cube_settle", rate, g, scheme);
        row.measure = "|z - 0.05 m| at 2 s (m)";
        SettleResult r;
        if (timed(row, repeats, setup.settle_duration, [&] { r = run_settle(rate, scheme, setup); })) {
          row.error = r.height_error;
          row.status = status_of(r.diverged, r.energy_gain);
          if (!r.diverged) {
            // ns per physics step: wall s per simulated s over physics steps per simulated s.
            f.step_ns = row.cost / rate * 1e9;
            f.step_ns_min = row.cost_min / rate * 1e9;
            f.step_ns_max = row.cost_max / rate * 1e9;
            f.step_ns_cpu = row.cpu / rate * 1e9;
          }
          row.note = "tilt " + num(r.tilt * 180 / kPi) + " deg; energy gain " + num(r.energy_gain) + " J; " +
                     num(row.cost / rate * 1e9) + " ns per physics step";
          // The same with every loop at the physics rate: the physics stage without the idle
          // servo and haptic ticks of the 3000 Hz clock.
          ContactSetup alone = setup;
          alone.loops_at_physics_rate = true;
          Row timing = row;
          time_it(timing, repeats, alone.settle_duration, [&] { run_settle(rate, scheme, alone); });
          f.step_ns_alone = timing.cost / rate * 1e9;
          row.note += " (" + num(f.step_ns_alone) + " with every loop at the physics rate)";
        }
        merge_status(f, row);
        rows.push_back(row);
      }
      out.push_back(f);
    }
  return out;
}

namespace {

// A figure in the table's unit (scale), with '*' when it misses its target.
std::string cell(double v, double scale, bool missed, const char* format = "%.3g") {
  if (std::isnan(v)) return "-";
  char b[32];
  std::snprintf(b, sizeof b, format, v * scale);
  return std::string(b) + (missed ? "*" : "");
}

}  // namespace

void print_contact_accuracy(const std::vector<AccuracyFigures>& figures) {
  if (figures.empty()) return;
  std::printf("\ncontact accuracy: 10 cm, 1 kg cube, mu 0.5, floor z = 0; paper: soft floor 250 N/m and "
              "2.5 N s/m per vertex; implicit: default stiffness\n");
  std::printf("%-9s %6s  %10s %9s  %14s %10s  %14s %11s %8s  %14s %15s %7s %7s\n", "scheme", "Hz", "rest dz mm",
              "tilt deg", "24deg creep mm", "(late mm)", "30deg slide mm", "analytic mm", "error %", "settle ns/step",
              "(min - max)", "cpu", "alone");
  std::printf("%-9s %6s  %10s %9s  %14s %10s  %14s %11s %8s  %14s\n", "target", "", "<= 0.1", "<= 0.01", "<= 0.01", "",
              "", "", "+-0.5", "<= 1000");
  for (const AccuracyFigures& f : figures) {
    const double slide_error = f.slide / f.slide_ref - 1.0;
    std::string range = "-";
    if (!std::isnan(f.step_ns_min)) {
      char b[48];
      std::snprintf(b, sizeof b, "(%.0f - %.0f)", f.step_ns_min, f.step_ns_max);
      range = b;
    }
    std::printf("%-9s %6d  %10s %9s  %14s %10s  %14s %11s %8s  %14s %15s %7s %7s", scheme_name(f.scheme), f.rate,
                cell(f.rest_depth, 1e3, f.rest_depth > kRestDepthTarget).c_str(),
                cell(f.rest_tilt, 180 / kPi, f.rest_tilt > kRestTiltTarget).c_str(),
                cell(f.creep, 1e3, f.creep > kCreepTarget).c_str(), cell(f.creep_late, 1e3, false).c_str(),
                cell(f.slide, 1e3, false, "%.2f").c_str(),
                cell(f.slide_ref, 1e3, false, "%.2f").c_str(),
                cell(slide_error, 100, std::abs(slide_error) > kSlideTarget, "%+.3g").c_str(),
                cell(f.step_ns, 1, f.step_ns > kStepTarget, "%.0f").c_str(), range.c_str(),
                cell(f.step_ns_cpu, 1, false, "%.0f").c_str(), cell(f.step_ns_alone, 1, false, "%.0f").c_str());
    if (f.status != "ok") std::printf("  %s", f.status.c_str());
    std::printf("\n");
  }
  std::printf("  '*': outside the target; '-': not run, refused or diverged (the status says which)\n"
              "  late: moved in the second half second (a cube that holds has stopped; the rest is its springs' set)\n"
              "  settle: wall ns per physics step, median (min - max) of the repeats, and this thread's CPU ns\n"
              "  (median), with servo 3000 Hz and haptic 500 Hz ticking idle between physics steps (no fingers);\n"
              "  alone: wall ns per physics step with every loop at the physics rate\n");
}

}  // namespace graspsim::bench
