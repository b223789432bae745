// TraceRecorder: one /servo row per servo tick, one /haptic and /physics row per tick of those
// loops. Columns and row values both come from the field tables of trace_schema.hpp; each
// record's offset into the row is worked out once in the constructor.
#include "graspsim/recordings/trace_recorder.hpp"

#include <iterator>
#include <stdexcept>
#include <string>
#include <utility>

#include "graspsim/engine/state_hash.hpp"
#include "graspsim/recordings/trace_schema.hpp"

namespace graspsim::recordings {
namespace {

using schema::Field;

void check_name(const std::string& what, const std::string& name) {
  if (name.empty() || name == "." || name == ".." || name.find('/') != std::string::npos) {
    throw std::invalid_argument("trace: " + what + " name '" + name +
                                "' cannot be an HDF5 group name (empty, '.', '..' or has '/')");
  }
}

// Rows of a loop that runs every `divisor` servo ticks in `chunk_ticks` servo ticks (0: the
// writer's default).
std::size_t chunk_rows(std::int64_t chunk_ticks, std::int64_t divisor) {
  if (chunk_ticks <= 0 || divisor <= 0) return 0;
  return static_cast<std::size_t>((chunk_ticks + divisor - 1) / divisor);
}

// Declares `fields` in `table` under `prefix`, in table order, with their units and notes;
// returns the offset of the first (the others follow it: add_column packs columns in order).
template <typename Record, std::size_t N>
std::size_t declare(TraceTable& table, const std::string& prefix, const Field<Record> (&fields)[N]) {
  std::size_t first = 0;
  for (std::size_t k = 0; k < N; ++k) {
    const Field<Record>& f = fields[k];
    const std::string path = prefix + std::string(f.name);
    const std::size_t offset = table.add_column(path, f.width, f.dtype, std::string(f.units));
    if (k == 0) first = offset;
    if (!f.note.name.empty()) table.set_attribute(path, std::string(f.note.name), std::string(f.note.value));
  }
  return first;
}

// Writes every field of `record` into `row` from `offset` on, in table order. The table is a
// template argument so that each field's put is a constant, called directly and inlined: the
// recorder then costs what hand-written stores into the row cost (tools/bench/trace_overhead.cpp,
// 40 s lift: the run loop's CPU time with the trace on is 33 to 35 ms either way; called through
// the pointers in a loop over the table, 37 to 41 ms).
template <const auto& Fields, std::size_t I, typename Record>
void put_field(const Record& record, double*& out) {
  constexpr auto put = Fields[I].put;
  constexpr int width = Fields[I].width;
  put(record, out);
  out += width;
}

template <const auto& Fields, typename Record>
void fill(double* row, std::size_t offset, const Record& record) {
  double* out = row + offset;
  [&]<std::size_t... I>(std::index_sequence<I...>) {
    (put_field<Fields, I>(record, out), ...);
  }(std::make_index_sequence<std::size(Fields)>{});
}

// Doubles and stored bytes of one copy of `fields`.
template <typename Record, std::size_t N>
RowSize size_of_fields(const Field<Record> (&fields)[N]) {
  RowSize size;
  for (const Field<Record>& f : fields) {
    size.values += static_cast<std::size_t>(f.width);
    size.bytes += static_cast<std::size_t>(f.width) * size_of(f.dtype);
  }
  return size;
}

RowSize operator+(RowSize a, RowSize b) { return {a.values + b.values, a.bytes + b.bytes}; }
RowSize operator*(std::size_t n, RowSize a) { return {n * a.values, n * a.bytes}; }

template <typename Record, std::size_t N>
void document(std::vector<schema::ColumnDoc>& out, const std::string& prefix,
              const Field<Record> (&fields)[N]) {
  for (const Field<Record>& f : fields)
    out.push_back({prefix + std::string(f.name), f.width, f.dtype, std::string(f.units), f.note});
}

}  // namespace

std::vector<schema::ColumnDoc> schema::recorded_columns() {
  std::vector<ColumnDoc> out;
  const auto under = [](std::string_view table) {
    std::string path = "/";
    path += table;
    path += '/';
    return path;
  };
  const std::string servo = under(kServo), haptic = under(kHaptic), physics = under(kPhysics);
  const std::string finger = std::string(kFingers) + "<finger>/", object = std::string(kObjects) + "<object>/";
  document(out, servo, kLoopFields);
  document(out, servo + finger, kServoFingerFields);
  document(out, haptic, kLoopFields);
  document(out, haptic + finger, kHapticFingerFields);
  document(out, physics, kLoopFields);
  document(out, physics, kPhysicsFields);
  document(out, physics + object, kBodyFields);
  return out;
}

TraceRecorder::Rows TraceRecorder::row_sizes(const graspsim::Model& model) {
  const std::size_t f = model.fingers.size(), b = model.bodies.size();
  const RowSize loop = size_of_fields(schema::kLoopFields);
  Rows r;
  r.servo = loop + f * size_of_fields(schema::kServoFingerFields);
  r.haptic = loop + f * size_of_fields(schema::kHapticFingerFields);
  r.physics = loop + size_of_fields(schema::kPhysicsFields) + b * size_of_fields(schema::kBodyFields);
  return r;
}

TraceRecorder::TraceRecorder(TraceWriter& writer, const graspsim::Model& model,
                             std::int64_t chunk_ticks)
    : servo_(writer.table(std::string(schema::kServo), chunk_rows(chunk_ticks, 1))),
      haptic_(writer.table(std::string(schema::kHaptic),
                           chunk_rows(chunk_ticks, divisors(model.rates).haptic))),
      physics_(writer.table(std::string(schema::kPhysics),
                            chunk_rows(chunk_ticks, divisors(model.rates).physics))),
      servo_rate_(static_cast<double>(model.rates.servo)) {
  for (const auto& f : model.fingers) check_name("finger", f.name);
  for (const auto& b : model.bodies) check_name("object", b.name);

  servo_loop_ = declare(servo_, "", schema::kLoopFields);
  haptic_loop_ = declare(haptic_, "", schema::kLoopFields);
  physics_loop_ = declare(physics_, "", schema::kLoopFields);
  physics_hash_ = declare(physics_, "", schema::kPhysicsFields);
  for (const auto& finger : model.fingers) {
    const std::string prefix = std::string(schema::kFingers) + finger.name + "/";
    servo_fingers_.push_back(declare(servo_, prefix, schema::kServoFingerFields));
    haptic_fingers_.push_back(declare(haptic_, prefix, schema::kHapticFingerFields));
  }
  std::string bodies;
  for (std::size_t k = 0; k < model.bodies.size(); ++k) {
    bodies += (k > 0 ? "\n" : "") + model.bodies[k].name;
  }
  haptic_.set_attribute(".", "bodies", bodies);
  for (const auto& body : model.bodies) {
    objects_.push_back(declare(physics_, std::string(schema::kObjects) + body.name + "/", schema::kBodyFields));
  }
}

void TraceRecorder::record(const graspsim::TickRecord& rec,
                           const std::vector<graspsim::Vec3>& rendered,
                           const graspsim::Input& input, const graspsim::State& after) {
  const std::size_t fingers = servo_fingers_.size();
  if (rec.servo.size() != fingers || rendered.size() != fingers ||
      input.fingers.size() != fingers ||
      (rec.haptic_ran && rec.haptic.size() != fingers) ||
      (rec.physics_ran && rec.physics.size() != objects_.size())) {
    throw std::invalid_argument("TraceRecorder::record: record sizes do not match the model");
  }
  const schema::LoopRow loop{rec.tick, static_cast<double>(rec.tick) / servo_rate_};

  double* row = servo_.append_row();
  fill<schema::kLoopFields>(row, servo_loop_, loop);
  for (std::size_t i = 0; i < fingers; ++i) {
    const schema::ServoFingerRow servo{rec.servo[i].hip, rendered[i], rec.servo[i].force,
                                       input.fingers[i].gimbal};
    fill<schema::kServoFingerFields>(row, servo_fingers_[i], servo);
  }

  if (rec.haptic_ran) {
    row = haptic_.append_row();
    fill<schema::kLoopFields>(row, haptic_loop_, loop);
    for (std::size_t i = 0; i < fingers; ++i)
      fill<schema::kHapticFingerFields>(row, haptic_fingers_[i], rec.haptic[i]);
  }

  if (rec.physics_ran) {
    row = physics_.append_row();
    fill<schema::kLoopFields>(row, physics_loop_, loop);
    fill<schema::kPhysicsFields>(row, physics_hash_, schema::PhysicsRow{state_hash(after)});
    for (std::size_t k = 0; k < objects_.size(); ++k)
      fill<schema::kBodyFields>(row, objects_[k], rec.physics[k]);
  }
}

}  // namespace graspsim::recordings
