// A run's memory and disk, estimated before it starts (see run_budget.hpp).
#include "app/run_budget.hpp"

#include <sys/statvfs.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "graspsim/recordings/device_recorder.hpp"
#include "graspsim/recordings/trace_recorder.hpp"

namespace graspsim::app {
namespace {

std::string bytes_text(double bytes) {
  const char* units[] = {"bytes", "kB", "MB", "GB", "TB", "PB", "EB"};
  int u = 0;
  while (bytes >= 1000.0 && u < 6) bytes /= 1000.0, ++u;
  char buf[48];
  std::snprintf(buf, sizeof buf, u == 0 ? "%.0f %s" : "%.1f %s", bytes, units[u]);
  return buf;
}

}  // namespace

RunFootprint estimate_footprint(const scripting::Scenario& scenario, const RunOptions& options) {
  const Model& model = scenario.model();
  RunFootprint out;
  const double ticks = std::round(scenario.duration() * model.rates.servo);
  out.servo_ticks = static_cast<std::int64_t>(ticks);
  if (options.stop.max_ticks >= 0) out.servo_ticks = std::min(out.servo_ticks, options.stop.max_ticks);
  const double run = static_cast<double>(out.servo_ticks);
  const Divisors d = divisors(model.rates);
  const double flush = static_cast<double>(flush_interval_ticks(model));
  const auto block = [&](double divisor) {
    return options.trace.block_rows > 0 ? static_cast<double>(options.trace.block_rows) : std::ceil(flush / divisor);
  };
  const recordings::TraceRecorder::Rows rows = recordings::TraceRecorder::row_sizes(model);
  // A table of a loop recorded every `every`-th tick (--record) holds one row per divisor *
  // every servo ticks; a loop not recorded, or no trace at all (--no-trace), has none.
  using recordings::RecordedLoop;
  const auto table = [&](std::string name, recordings::RowSize row, double divisor, RecordedLoop loop) {
    const auto every = static_cast<double>(options.trace.record.of(loop));
    if (!options.trace.write || every <= 0) return;
    out.tables.push_back({std::move(name), row.values, row.bytes, block(divisor * every), std::ceil(run / (divisor * every))});
  };
  table("/servo", rows.servo, 1.0, RecordedLoop::kServo);
  table("/haptic", rows.haptic, static_cast<double>(d.haptic), RecordedLoop::kHaptic);
  table("/physics", rows.physics, static_cast<double>(d.physics), RecordedLoop::kPhysics);
  // /contacts: rows per physics tick vary; counted as four per body (a box resting on its corners).
  if (options.trace.write && options.trace.record.records(RecordedLoop::kContacts)) {
    const double every = static_cast<double>(options.trace.record.of(RecordedLoop::kContacts));
    const double per_tick = 4.0 * static_cast<double>(model.bodies.size());
    out.tables.push_back({"/contacts", rows.contacts.values, rows.contacts.bytes,
                          static_cast<double>(options.trace.block_rows > 0 ? options.trace.block_rows : recordings::TraceOptions{}.block_rows),
                          std::ceil(run / (static_cast<double>(d.physics) * every)) * per_tick});
  }
  for (std::size_t f = 0; f < options.devices.record.size() && f < model.fingers.size(); ++f)
    if (options.devices.record[f])
      table("/devices/" + model.fingers[f].name, recordings::DeviceRecorder::row_size(options.devices.counters), 1.0,
            RecordedLoop::kDevices);
  const double pool = options.trace.background_writer ? 4.0 : 1.0;   // TraceTable's blocks (trace_writer.cpp)
  double largest = -1.0;
  for (const TableFootprint& t : out.tables) {
    const double memory = pool * t.block_rows * static_cast<double>(t.values) * 8.0 + t.block_rows * static_cast<double>(t.bytes);
    out.memory += memory;
    out.disk += t.rows * static_cast<double>(t.bytes);
    if (memory > largest) {
      largest = memory;
      std::ostringstream detail;
      detail << t.name << ": " << pool << " blocks of " << static_cast<long long>(t.block_rows) << " rows of " << t.values
             << " values, one flush interval (" << flush / model.rates.servo << " s) at rates.servo = " << model.rates.servo
             << " Hz";
      out.memory_detail = detail.str();
    }
  }
  return out;
}

MachineRoom machine_room(const std::string& out_path) {
  MachineRoom room;
  std::ifstream meminfo("/proc/meminfo");
  for (std::string key; meminfo >> key;) {
    double kib = 0.0;
    std::string unit;
    meminfo >> kib >> unit;
    if (key == "MemAvailable:") {
      room.memory_available = kib * 1024.0;
      break;
    }
  }
  std::filesystem::path dir = std::filesystem::path(out_path).parent_path();
  if (dir.empty()) dir = ".";
  struct statvfs fs {};
  if (::statvfs(dir.c_str(), &fs) == 0) room.disk_free = static_cast<double>(fs.f_bavail) * static_cast<double>(fs.f_frsize);
  return room;
}

std::string refusal(const RunFootprint& need, const MachineRoom& room, int compression, std::string* warning) {
  // A table's chunk (its block: one flush interval of rows) must fit in one HDF5 chunk, whatever
  // the machine (recordings/README.md "Limits"): refused here, before the run, not at its first row.
  for (const TableFootprint& t : need.tables) {
    if (t.block_rows * static_cast<double>(t.bytes) > static_cast<double>(recordings::kMaxChunkBytes)) {
      return "the trace's " + t.name + " table would need chunks of " + bytes_text(t.block_rows * static_cast<double>(t.bytes)) +
             " (" + std::to_string(static_cast<long long>(t.block_rows)) + " rows of " + bytes_text(static_cast<double>(t.bytes)) +
             "), more than HDF5's limit of 4.3 GB (2^32 - 1 bytes) a chunk: run fewer fingers and objects, lower the rates, "
             "or run without a trace (--no-trace)";
    }
  }
  if (room.memory_available >= 0.0 && need.memory > room.memory_available) {
    return "the run's trace buffers need " + bytes_text(need.memory) + " of memory (" + need.memory_detail +
           "), and this machine has " + bytes_text(room.memory_available) +
           " available: lower the rates, or run fewer fingers and objects";
  }
  if (room.disk_free >= 0.0 && need.disk > room.disk_free) {
    const std::string what = "the trace needs about " + bytes_text(need.disk) + " of disk (" +
                             std::to_string(need.servo_ticks) + " servo ticks, its rows uncompressed), and its directory has " +
                             bytes_text(room.disk_free) + " free";
    if (compression > 0) {
      if (warning) *warning = what + "; compressed it may fit";
      return "";
    }
    return what + ": shorten --duration, lower rates.servo, write it elsewhere (--out) or compress it (--compress N)";
  }
  return "";
}

std::string check_run_fits(const scripting::Scenario& scenario, const RunOptions& options, std::string* warning) {
  const std::string out = options.out.empty() ? scenario.name() + ".h5" : options.out;
  return refusal(estimate_footprint(scenario, options), machine_room(out), options.trace.compression, warning);
}

}  // namespace graspsim::app
