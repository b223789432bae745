// The trace of one run: claim, root attributes, rows, flushes on schedule, finish.
#include "app/run_trace.hpp"
#include "graspsim_version.hpp"

#include <algorithm>
#include <cinttypes>
#include <cmath>
#include <cstdio>
#include <exception>
#include <numeric>

#include "graspsim/engine/state_hash.hpp"

#ifndef GRASPSIM_BUILD_FLAGS
#define GRASPSIM_BUILD_FLAGS "unknown"
#endif

namespace graspsim::app {
namespace {

std::string join_lines(const std::vector<std::string>& lines) {
  std::string out;
  for (const std::string& l : lines) out += l + "\n";
  return out;
}

// "fnv1a64:" and 16 lower-case hex digits of the FNV-1a 64 hash of the text's bytes.
std::string source_hash(const std::string& text) {
  char hex[17];
  std::snprintf(hex, sizeof hex, "%016" PRIx64, fnv1a64(text.data(), text.size()));
  return std::string("fnv1a64:") + hex;
}

double seconds_since(RunClock::time_point start) {
  return std::chrono::duration<double>(RunClock::now() - start).count();
}

}  // namespace

// Servo ticks between flushes on simulated time: the largest whole number of physics (and
// haptic) periods within kFlushSimulated / (kFlushesInFlight + 1), so that every flush interval
// holds the same number of rows of every loop and each table's chunk can be exactly one interval
// (each chunk is then written once, whole: recordings/README.md "Cost"). 360 ticks (0.12 s) at
// 3000/500/50 Hz. If one physics period is longer than that: that limit, floor(kFlushSimulated /
// (kFlushesInFlight + 1) * rate_servo).
std::int64_t flush_interval_ticks(const Model& model) {
  const std::int64_t limit = std::max<std::int64_t>(
      1, static_cast<std::int64_t>(std::floor(kFlushSimulated / (kFlushesInFlight + 1) * model.rates.servo)));
  const Divisors d = divisors(model.rates);
  const std::int64_t period = std::lcm(d.haptic, d.physics);
  return period <= limit ? limit / period * period : limit;
}

std::vector<InputFile> run_inputs(const scripting::Scenario& scenario, const RunOptions& options) {
  std::vector<InputFile> inputs = options.inputs;
  inputs.push_back({scenario.path(), "the scenario"});
  for (const std::string& f : scenario.files()) inputs.push_back({f, "a mesh file of the scenario"});
  return inputs;
}

RunTrace::RunTrace(const scripting::Scenario& scenario, const RunOptions& options)
    : path_(options.out.empty() ? default_trace_name(scenario.name()) : options.out),
      record_(options.trace.record) {
  if (!options.trace.write) {
    path_.clear();
    finished_ = true;   // nothing to abandon
  }
  try {
    if (options.trace.write) {
      refuse_input_as_output(path_, run_inputs(scenario, options), options.trace.naming.option);   // throws OutputError
      claim_.emplace(path_, options.trace.naming);                 // throws OutputError
      recordings::TraceOptions trace_options;
      if (options.trace.block_rows > 0) trace_options.block_rows = options.trace.block_rows;
      trace_options.compression = options.trace.compression;
      // HDF5 writes and flushes run on a writer thread: the run loop only fills memory
      // (recordings/README.md "Cost"); the file is the same as without it.
      trace_options.background = options.trace.background_writer;
      writer_.emplace(claim_->partial(), trace_options);   // throws TraceError if it cannot
    }
    const Model& model = scenario.model();
    // The file explains and replays itself: the scenario text, every parameter, rates, seed, build.
    set_attribute("schema_version", recordings::kSchemaVersion);
    set_attribute("scenario_path", scenario.path());
    set_attribute("scenario_name", scenario.name());
    set_attribute("scenario_source", scenario.source());
    set_attribute("scenario_source_hash", source_hash(scenario.source()));
    set_attribute("overrides", join_lines(options.overrides));
    // What the trace holds (--record): compare and replay read it back.
    set_attribute("record", options.trace.record.text());
    set_attribute("integrator", std::string(model.integrator == Integrator::kPaper ? "paper" : "implicit"));
    set_attribute("local_model", static_cast<std::int64_t>(model.local_model ? 1 : 0));
    set_attribute("parameters", join_lines(scenario.parameters()));
    // Perturbed waypoints (README.md "Perturbed waypoints"): a replay loads the scenario with the
    // same jitter; the offsets themselves, to read and to check the generator against.
    if (scenario.jitter().amplitude > 0.0) {
      set_attribute("jitter_amplitude", scenario.jitter().amplitude);
      set_attribute("jitter_seed", static_cast<std::int64_t>(scenario.jitter().seed));
      set_attribute("jitter_offsets", join_lines(scenario.jitter_lines()));
    }
    set_attribute("rate_servo", std::int64_t{model.rates.servo});
    set_attribute("rate_haptic", std::int64_t{model.rates.haptic});
    set_attribute("rate_physics", std::int64_t{model.rates.physics});
    set_attribute("seed", static_cast<std::int64_t>(scenario.seed()));
    set_attribute("duration", scenario.duration());
    set_attribute("graspsim_version", GRASPSIM_VERSION);
#if defined(__clang__)
    set_attribute("compiler", std::string("clang++ ") + __VERSION__);   // "clang++ Debian Clang 14.0.6"
#else
    set_attribute("compiler", std::string("g++ ") + __VERSION__);       // "g++ 12.2.0"
#endif
    set_attribute("build_flags", GRASPSIM_BUILD_FLAGS);
    for (const auto& [name, value] : options.attributes) set_attribute(name, value);
  } catch (...) {
    abandon();
    throw;
  }
}

RunTrace::~RunTrace() {
  if (!finished_) abandon();
}

void RunTrace::abandon() {
  finished_ = true;
  try {
    if (writer_) writer_->close("error: the run could not start");
  } catch (...) {
  }
  if (claim_) claim_->abandon();
}

void RunTrace::open_tables(const Model& model, std::size_t block_rows, RunClock::time_point start) {
  block_rows_ = block_rows;
  flush_ticks_ = until_flush_ = flush_interval_ticks(model);
  last_flush_ = start;
  if (writer_) recorder_.emplace(*writer_, model, block_rows > 0 ? 0 : flush_ticks_, record_);
}

void RunTrace::flush_if_due(std::int64_t n) {
  if (!recorder_) return;
  // A countdown, not (n + 1) % flush_ticks: a 64-bit division every tick would be an eighth
  // of what logging cost the run loop (perf, the 40 s lift).
  if (--until_flush_ == 0 || (n % kWallCheckTicks == 0 && seconds_since(last_flush_) >= kFlushWall)) {
    // The flush kFlushesInFlight before this one must be on disk first (kFlushSimulated).
    writer_->wait(tickets_[oldest_]);
    tickets_[oldest_] = writer_->flush();
    oldest_ = (oldest_ + 1) % tickets_.size();
    last_flush_ = RunClock::now();
    until_flush_ = flush_ticks_ - (n + 1) % flush_ticks_;   // rare: keep the simulated phase
  }
}

void RunTrace::finish(RunResult& result, bool started, const std::string& warnings) {
  finished_ = true;
  result.trace_path = path_;
  std::string summary;
  for (const auto& e : result.expectations)
    summary += (e.passed ? "PASS " : "FAIL ") + e.what + (e.detail.empty() ? "" : ": " + e.detail) + "\n";
  try {
    set_attribute("expectations", summary);
    set_attribute("warnings", warnings);
    if (writer_) writer_->close(result.error.empty() ? "complete" : "error: " + result.error);
  } catch (const std::exception& e) {
    result.trace_error = e.what();
    if (result.error.empty()) result.error = std::string("writing the trace: ") + e.what();
  }
  if (!started) {
    // A device could not be built: the run never began, and nothing of it is kept.
    result.not_started = true;
    result.trace_error.clear();
    result.trace_path.clear();
    if (claim_) claim_->abandon();
  } else if (claim_ && writer_ && writer_->marked()) {
    // Complete, or marked with its error: it may now take the output path.
    try {
      claim_->commit();
    } catch (const OutputError& e) {
      result.trace_error = e.what();
      result.trace_path = claim_->partial();
    }
  } else if (claim_) {
    // Not even its status could be written: it stays under its partial name, like a cut trace.
    result.trace_path = claim_->partial();
  }
}

}  // namespace graspsim::app
