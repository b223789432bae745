// graspsim_bench: the work-precision benchmark (README.md, "Speed against error").
// For every case x physics rate x gyroscopic option (the hard cases) or x integration scheme (the
// contact accuracy cases, accuracy.hpp): the wall time per simulated second (median of --repeats
// runs in this process, after one warm-up run that is dropped) and the error against the analytic
// solution or, where there is none, against the same case at the finest rate.
// Writes OUT/bench.csv and OUT/stability.csv and prints them and the contact accuracy figures as
// tables. Not a test: it times.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "bench/accuracy.hpp"
#include "bench/cases.hpp"
#include "bench/lift.hpp"
#include "bench/robustness_case.hpp"
#include "bench/row.hpp"

using namespace graspsim;
using namespace graspsim::bench;

namespace {

const std::vector<std::string> kCases = [] {
  std::vector<std::string> c{"spin_flip", "gyro_precession", "corner_drop", "two_finger_lift"};
  c.insert(c.end(), kAccuracyCases.begin(), kAccuracyCases.end());
  return c;
}();
// Cases run only when --cases names them: robustness runs thousands of scenarios (minutes).
const std::vector<std::string> kOnRequest{"robustness"};
constexpr double kSpinEnergyGainBound = 0.05;   // 1: relative energy gain over 10 s that marks a
                                                //    torque-free run unstable
constexpr double kCornerStiffness = 300.0;      // N/m per vertex: corner_drop's rows (stable at
                                                //    every rate; its boundary is 367 N/m at 50 Hz)

struct Options {
  bool quick = false;
  int repeats = 5;
  std::string out = "bench-out";
  std::vector<std::string> cases = kCases;
  std::string lift = GRASPSIM_SOURCE_DIR "/scenarios/two_finger_lift.lua";
  RobustnessOptions robustness;   // --seeds, --jitter, --set, --scenarios
};

[[noreturn]] void usage(const std::string& error) {
  std::cerr << "graspsim_bench: " << error << "\n"
            << "usage: graspsim_bench [--quick] [--repeats N] [--out DIR] [--cases a,b,...] [--lift FILE.lua]\n"
            << "                      [--seeds N] [--jitter M] [--set NAME=VALUE]... [--scenarios a,b,...]\n"
            << "cases: spin_flip, gyro_precession, corner_drop, two_finger_lift, cube_rest, slope_stick, slope_slide,\n"
            << "       cube_settle (the default: all of them);\n"
            << "       robustness (only when named: --seeds jitter seeds per scenario, default 100, --quick 5;\n"
            << "       --jitter amplitude in m, default 0.5e-3; --set for every run; --scenarios a subset)\n";
  std::exit(2);
}

Options parse(int argc, char** argv) {
  Options o;
  bool repeats_set = false, seeds_set = false;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    const auto value = [&]() -> std::string {
      if (i + 1 >= argc) usage(a + " needs a value");
      return argv[++i];
    };
    if (a == "--quick") o.quick = true;
    else if (a == "--repeats") {
      const std::string v = value();
      char* end = nullptr;
      const long n = std::strtol(v.c_str(), &end, 10);
      if (*end != '\0' || n < 1 || n > 1000) usage("--repeats wants a whole number 1..1000, got '" + v + "'");
      o.repeats = static_cast<int>(n);
      repeats_set = true;
    } else if (a == "--seeds") {
      const std::string v = value();
      char* end = nullptr;
      const long n = std::strtol(v.c_str(), &end, 10);
      if (*end != '\0' || n < 1 || n > 100000) usage("--seeds wants a whole number 1..100000, got '" + v + "'");
      o.robustness.seeds = static_cast<int>(n);
      seeds_set = true;
    } else if (a == "--jitter") {
      const std::string v = value();
      char* end = nullptr;
      o.robustness.jitter = std::strtod(v.c_str(), &end);
      if (*end != '\0' || !(o.robustness.jitter > 0.0) || !std::isfinite(o.robustness.jitter))
        usage("--jitter wants an amplitude in m > 0, got '" + v + "'");
    } else if (a == "--set") o.robustness.sets.push_back(value());
    else if (a == "--scenarios") {
      std::stringstream ss(value());
      for (std::string c; std::getline(ss, c, ',');) o.robustness.scenarios.push_back(c);
    } else if (a == "--out") o.out = value();
    else if (a == "--lift") o.lift = value();
    else if (a == "--cases") {
      o.cases.clear();
      std::stringstream ss(value());
      std::string c;
      while (std::getline(ss, c, ',')) {
        if (std::find(kCases.begin(), kCases.end(), c) == kCases.end() &&
            std::find(kOnRequest.begin(), kOnRequest.end(), c) == kOnRequest.end())
          usage("unknown case '" + c + "'");
        o.cases.push_back(c);
      }
      if (o.cases.empty()) usage("--cases is empty");
    } else if (a == "--help" || a == "-h") usage("help");
    else usage("unknown argument '" + a + "'");
  }
  if (o.quick && !repeats_set) o.repeats = 1;
  if (o.quick && !seeds_set) o.robustness.seeds = 5;
  o.robustness.scenario_dir = GRASPSIM_SOURCE_DIR "/scenarios";
  o.robustness.out = o.out;
  return o;
}

}  // namespace

int main(int argc, char** argv) {
  const Options opt = parse(argc, argv);
  const std::vector<int> rates = opt.quick ? std::vector<int>{50, 500, 3000}
                                           : std::vector<int>{50, 100, 250, 500, 1000, 3000};
  const int finest = rates.back();
  const auto wants = [&](const std::string& c) {
    return std::find(opt.cases.begin(), opt.cases.end(), c) != opt.cases.end();
  };
  std::vector<Row> rows;
  std::vector<std::string> notes;

  if (wants("spin_flip")) {
    SpinFlipSetup s;
    for (Gyroscopic g : kIntegrators)
      for (int rate : rates) {
        Row row = make_row("spin_flip", rate, g);
        SpinFlipResult r;
        time_it(row, opt.repeats, s.duration, [&] { r = run_spin_flip(rate, g, s); });
        row.measure = "max rel. drift of E and |L|";
        row.error = std::max(r.energy_drift, r.momentum_drift);
        row.energy_drift = r.energy_drift;
        row.momentum_drift = r.momentum_drift;
        row.period = r.period > 0.0 ? r.period : NAN;
        row.period_ref = r.period_ref;
        if (r.diverged) row.status = "unstable: diverged";
        else if (!std::isfinite(row.error)) row.status = "unstable: NaN";
        else if (r.energy_gain > kSpinEnergyGainBound) row.status = "unstable: energy gain";
        if (r.period < 0.0) row.note = "no flip";
        rows.push_back(row);
      }
  }

  if (wants("gyro_precession")) {
    PrecessionSetup s;
    if (opt.quick) s.duration = 3.0;
    for (Gyroscopic g : kIntegrators)
      for (int rate : rates) {
        Row row = make_row("gyro_precession", rate, g);
        PrecessionResult r;
        time_it(row, opt.repeats, s.duration, [&] { r = run_precession(rate, g, s); });
        row.measure = "rel. error of precession rate";
        row.error = std::abs(r.rate - r.rate_ref) / r.rate_ref;
        row.precession = r.rate;
        row.precession_ref = r.rate_ref;
        if (r.diverged) row.status = "unstable: diverged";
        else if (r.lost_contact) row.status = "unstable: fell off the pivot";
        else if (!std::isfinite(row.error)) row.status = "unstable: NaN";
        row.note = "tilt change " + num(r.max_tilt_change) + " rad";
        rows.push_back(row);
      }
    notes.push_back("gyro_precession: steady precession (slow root) " + num(steady_precession_rate(s)) +
                    " rad/s; fast-top m g l / (I3 w3) " + num(fast_top_precession_rate(s)) + " rad/s");
  }

  if (wants("corner_drop")) {
    CornerDropSetup s;
    for (Gyroscopic g : kIntegrators) {
      std::map<int, std::vector<Vec3>> samples;
      std::map<int, CornerDropResult> results;
      for (int rate : rates) {
        Row row = make_row("corner_drop", rate, g);
        time_it(row, opt.repeats, s.duration,
                [&] { results[rate] = run_corner_drop(rate, g, kCornerStiffness, s, &samples[rate]); });
        rows.push_back(row);
      }
      for (Row& row : rows) {
        if (row.name != "corner_drop" || row.g != g) continue;
        const CornerDropResult& r = results[row.rate];
        row.measure = "max |x - x(" + std::to_string(finest) + " Hz)| m";
        row.error = row.rate == finest ? 0.0 : max_distance(samples[row.rate], samples[finest]);
        if (r.diverged) row.status = "unstable: diverged";
        else if (!r.stable()) row.status = "unstable: energy gain";
        row.note = "k " + num(kCornerStiffness) + " N/m; max energy gain " + num(r.max_gain) + " J";
      }
      if (rates.size() >= 2) {
        const int next = rates[rates.size() - 2];
        notes.push_back(std::string("corner_drop ") + integrator_name(g) + ": reference " + std::to_string(finest) +
                        " Hz; its distance to " + std::to_string(next) + " Hz " +
                        num(max_distance(samples[next], samples[finest])) + " m");
      }
    }
  }

  if (wants("two_finger_lift")) {
    scripting::Scenario scenario = [&] {
      try {
        return scripting::Scenario::load(opt.lift);
      } catch (const std::exception& e) {
        std::cerr << "graspsim_bench: " << e.what() << "\n";
        std::exit(2);
      }
    }();
    for (Gyroscopic g : kIntegrators) {
      std::map<int, LiftResult> results;
      for (int rate : rates) {
        Row row = make_row("two_finger_lift", rate, g, scenario.model().integrator);
        time_it(row, opt.repeats, scenario.duration(), [&] { run_lift(scenario, rate, g, results[rate]); });
        rows.push_back(row);
      }
      for (Row& row : rows) {
        if (row.name != "two_finger_lift" || row.g != g) continue;
        const LiftResult& r = results[row.rate];
        row.measure = "max |x - x(" + std::to_string(finest) + " Hz)| m";
        row.error = row.rate == finest ? 0.0 : max_distance(r.samples, results[finest].samples);
        if (r.diverged) row.status = "unstable: diverged";
      }
      if (rates.size() >= 2) {
        const int next = rates[rates.size() - 2];
        notes.push_back(std::string("two_finger_lift ") + integrator_name(g) + ": reference " + std::to_string(finest) +
                        " Hz; its distance to " + std::to_string(next) + " Hz " +
                        num(max_distance(results[next].samples, results[finest].samples)) + " m");
      }
    }
  }

  std::vector<AccuracyFigures> accuracy = run_contact_accuracy(opt.cases, rates, opt.repeats, rows);

  // Stability boundary of the corner drop: the largest stable floor stiffness per rate.
  struct Boundary {
    int rate;
    Gyroscopic g;
    double k_max, estimate;
  };
  std::vector<Boundary> boundaries;
  if (wants("corner_drop"))
    for (Gyroscopic g : kIntegrators)
      for (int rate : rates) boundaries.push_back({rate, g, corner_drop_boundary(rate, g), corner_drop_estimate(rate)});

  if (wants("robustness")) {
    const int status = run_robustness_case(opt.robustness);
    if (status != 0) return status;
    if (rows.empty() && boundaries.empty()) return 0;   // nothing else was asked for
  }

  // ---- output -----------------------------------------------------------------------------
  std::error_code ec;
  std::filesystem::create_directories(opt.out, ec);
  const std::string csv_path = opt.out + "/bench.csv", stab_path = opt.out + "/stability.csv";
  std::ofstream csv(csv_path);
  if (!csv) {
    std::cerr << "graspsim_bench: cannot write " << csv_path << "\n";
    return 2;
  }
  // A cell never holds a comma (a refusal's message may): it would split the row.
  const auto cell = [](std::string text) {
    std::replace(text.begin(), text.end(), ',', ';');
    return text;
  };
  // integrator: the gyroscopic option; scheme: Model::integrator.
  csv << "case,rate_hz,integrator,status,wall_per_sim_s,wall_min,wall_max,cpu_per_sim_s,repeats,error,error_measure,"
         "energy_drift,momentum_drift,period_s,period_ref_s,precession_rad_s,precession_ref_rad_s,note,scheme\n";
  std::printf("%-16s %6s %-9s %-9s %-28s %11s %11s %11s  %s\n", "case", "Hz", "scheme", "gyro", "status", "wall/sim s",
              "cpu/sim s", "error", "details");
  for (const Row& r : rows) {
    csv << r.name << ',' << r.rate << ',' << integrator_name(r.g) << ',' << cell(r.status) << ',' << num(r.cost) << ','
        << num(r.cost_min) << ',' << num(r.cost_max) << ',' << num(r.cpu) << ',' << r.repeats << ',' << num(r.error) << ','
        << cell(r.measure) << ',' << num(r.energy_drift) << ',' << num(r.momentum_drift) << ',' << num(r.period) << ','
        << num(r.period_ref) << ',' << num(r.precession) << ',' << num(r.precession_ref) << ',' << cell(r.note) << ','
        << r.scheme << '\n';
    std::string details;
    if (!std::isnan(r.period_ref))
      details = "E " + num(r.energy_drift) + ", L " + num(r.momentum_drift) + ", period " +
                (std::isnan(r.period) ? std::string("none") : num(r.period)) + " s (" + num(r.period_ref) + ")";
    if (!std::isnan(r.precession_ref))
      details = "precession " + num(r.precession) + " rad/s (" + num(r.precession_ref) + ")";
    if (!r.note.empty()) details += (details.empty() ? "" : "; ") + r.note;
    std::printf("%-16s %6d %-9s %-9s %-28s %11.3e %11.3e %11.3e  %s\n", r.name.c_str(), r.rate, r.scheme.c_str(),
                integrator_name(r.g),
                r.status.c_str(), r.cost, r.cpu, r.error, details.c_str());
  }
  for (const std::string& n : notes) std::printf("  %s\n", n.c_str());
  print_contact_accuracy(accuracy);

  std::ofstream stab(stab_path);
  stab << "rate_hz,integrator,k_max_n_per_m,estimate_n_per_m\n";
  if (!boundaries.empty()) {
    std::printf("\ncorner_drop stability boundary: largest stable floor stiffness (N/m per vertex, bisection to 9%%)\n");
    std::printf("%6s %-9s %12s %12s\n", "Hz", "gyro", "k_max", "estimate");
  }
  for (const Boundary& b : boundaries) {
    stab << b.rate << ',' << integrator_name(b.g) << ',' << num(b.k_max) << ',' << num(b.estimate) << '\n';
    std::printf("%6d %-9s %12.4g %12.4g\n", b.rate, integrator_name(b.g), b.k_max, b.estimate);
  }
  std::printf("\nwrote %s and %s\n", csv_path.c_str(), stab_path.c_str());
  return 0;
}
