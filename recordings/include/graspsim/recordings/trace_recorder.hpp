// TraceRecorder: maps the engine's per-tick records onto the trace schema (/servo, /haptic,
// /physics; the columns are the field tables of trace_schema.hpp, documented in
// recordings/README.md).
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "graspsim/engine/math.hpp"
#include "graspsim/engine/model.hpp"
#include "graspsim/engine/record.hpp"
#include "graspsim/engine/state.hpp"
#include "graspsim/recordings/record_selection.hpp"
#include "graspsim/recordings/trace_writer.hpp"

namespace graspsim::recordings {

// The trace schema this graspsim writes (root attribute "schema_version", recordings/README.md).
// 4: one compound dataset per loop (/servo, /haptic, /physics); the per-finger and per-object
//    columns stored as one member per group, an array of one compound element per finger or
//    object, so the row type does not grow with them.
// 3: the same, one member per column (fingers/thumb/hip, ...).
// 2: one group per loop, one dataset per column. Readers here read all three.
inline constexpr std::int64_t kSchemaVersion = 4;
// The oldest schema this graspsim reads (and replays).
inline constexpr std::int64_t kOldestSchemaVersion = 2;

// One row of a table: doubles in the writer's memory blocks, bytes in the file.
struct RowSize {
  std::size_t values = 0;   // doubles per row in memory (TraceTable::row_width)
  std::size_t bytes = 0;    // bytes per stored compound row
};

class TraceRecorder {
 public:
  // The rows the constructor declares for `model`, for estimates before a run (the memory a
  // writer holds, the disk a trace takes): /servo, /haptic, /physics, and one /contacts row.
  struct Rows {
    RowSize servo, haptic, physics, contacts;
  };
  static Rows row_sizes(const graspsim::Model& model);

  // Declares every table and column (and their attributes) in `writer`, which must outlive
  // the recorder. Throws std::invalid_argument for a finger or object name that cannot be an
  // HDF5 group name (empty, ".", "..", or containing '/'). `chunk_ticks` > 0: each table's
  // chunk (and write block) covers that many servo ticks, i.e. chunk_ticks / (servo ticks per
  // tick of its loop) rows, rounded up; a runner that flushes every chunk_ticks ticks then
  // writes each chunk once, whole. 0: TraceOptions::block_rows rows for every table.
  // `select`: the loops declared and how often each keeps a row (the /devices entry is the
  // runner's, DeviceRecorder); a loop it does not record has no table at all.
  TraceRecorder(TraceWriter& writer, const graspsim::Model& model, std::int64_t chunk_ticks = 0,
                const RecordSelection& select = {});

  // Appends one /servo row, plus a /haptic row if rec.haptic_ran and a /physics row if
  // rec.physics_ran, each only if its loop is recorded and this is one of its kept ticks, and
  // at a kept physics tick of /contacts one /contacts row per rec.contacts entry. `rendered` (one per finger): the force each device actually rendered after
  // clamping (N, world). `input`: the device input the step was given (its gimbal angles go to
  // /servo, so the trace alone can replay the run). `after`: the State after the step, whose
  // state_hash goes to /physics/state_hash. time = tick / servo rate, computed from the tick,
  // never accumulated. Allocates nothing (after each table's first row). Throws
  // std::invalid_argument if a record or input vector does not match the model's finger or
  // body count.
  void record(const graspsim::TickRecord& rec, const std::vector<graspsim::Vec3>& rendered,
              const graspsim::Input& input, const graspsim::State& after);

 private:
  TraceTable* servo_;     // null: the loop is not recorded
  TraceTable* haptic_;
  TraceTable* physics_;
  TraceTable* contacts_;
  double servo_rate_;   // Hz
  // Decimation (RecordSelection::every): ticks of each loop to its next kept row, a countdown
  // rather than a division per tick.
  std::int64_t servo_every_, haptic_every_, physics_every_, contacts_every_;
  std::int64_t servo_wait_ = 0, haptic_wait_ = 0, physics_wait_ = 0, contacts_wait_ = 0;
  // Offsets into a row of each record's first column; its fields follow it in table order
  // (trace_schema.hpp).
  std::size_t servo_loop_ = 0, haptic_loop_ = 0, physics_loop_ = 0;   // tick, time
  std::size_t physics_hash_ = 0;                                      // state_hash
  std::size_t contacts_loop_ = 0, contact_fields_ = 0;                // tick, time; a, b, ...
  std::vector<std::size_t> servo_fingers_;    // Model::fingers order
  std::vector<std::size_t> haptic_fingers_;   // Model::fingers order
  std::vector<std::size_t> objects_;          // Model::bodies order
};

}  // namespace graspsim::recordings
