// TraceRecorder: one /servo row per servo tick, one /haptic and /physics row per tick of those
// loops. Columns and row values both come from the field tables of trace_schema.hpp; each
// record's offset into the row is worked out once in the constructor.
#include "graspsim/recordings/trace_recorder.hpp"

#include <stdexcept>
#include <string>

#include "graspsim/engine/state_hash.hpp"
#include "graspsim/recordings/trace_schema.hpp"
#include "field_rows.hpp"

namespace graspsim::recordings {
namespace {

using schema::declare;
using schema::declare_group;
using schema::Field;
using schema::fill;
using schema::size_of_fields;

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
  const std::string finger = std::string(kFingers) + "/<finger>/", object = std::string(kObjects) + "/<object>/";
  document(out, servo, kLoopFields);
  document(out, servo + finger, kServoFingerFields);
  document(out, haptic, kLoopFields);
  document(out, haptic + finger, kHapticFingerFields);
  document(out, physics, kLoopFields);
  document(out, physics, kPhysicsFields);
  document(out, physics + object, kBodyFields);
  document(out, under(kContacts), kLoopFields);
  document(out, under(kContacts), kContactFields);
  std::string device = "/";
  device += kDevices;
  device += "<finger>/";
  document(out, device, kDeviceFields);
  document(out, device, kDeviceCounterFields);
  return out;
}

TraceRecorder::Rows TraceRecorder::row_sizes(const graspsim::Model& model) {
  const std::size_t f = model.fingers.size(), b = model.bodies.size();
  const RowSize loop = size_of_fields(schema::kLoopFields);
  Rows r;
  r.servo = loop + f * size_of_fields(schema::kServoFingerFields);
  r.haptic = loop + f * size_of_fields(schema::kHapticFingerFields);
  r.physics = loop + size_of_fields(schema::kPhysicsFields) + b * size_of_fields(schema::kBodyFields);
  r.contacts = loop + size_of_fields(schema::kContactFields);
  return r;
}

TraceRecorder::TraceRecorder(TraceWriter& writer, const graspsim::Model& model,
                             std::int64_t chunk_ticks, const RecordSelection& select)
    : servo_rate_(static_cast<double>(model.rates.servo)),
      servo_every_(select.of(RecordedLoop::kServo)),
      haptic_every_(select.of(RecordedLoop::kHaptic)),
      physics_every_(select.of(RecordedLoop::kPhysics)),
      contacts_every_(select.of(RecordedLoop::kContacts)) {
  for (const auto& f : model.fingers) check_name("finger", f.name);
  for (const auto& b : model.bodies) check_name("object", b.name);
  // A table's chunk covers chunk_ticks servo ticks of its kept rows.
  const Divisors d = divisors(model.rates);
  const auto table = [&](std::string_view name, std::int64_t every, std::int64_t divisor) -> TraceTable* {
    return every > 0 ? &writer.table(std::string(name), chunk_rows(chunk_ticks, divisor * every)) : nullptr;
  };
  servo_ = table(schema::kServo, servo_every_, 1);
  haptic_ = table(schema::kHaptic, haptic_every_, d.haptic);
  physics_ = table(schema::kPhysics, physics_every_, d.physics);
  // A variable number of rows per tick: the writer's default block.
  contacts_ = contacts_every_ > 0 ? &writer.table(std::string(schema::kContacts), 0) : nullptr;
  if (contacts_) {
    contacts_loop_ = declare(*contacts_, "", schema::kLoopFields);
    contact_fields_ = declare(*contacts_, "", schema::kContactFields);
  }

  if (servo_) servo_loop_ = declare(*servo_, "", schema::kLoopFields);
  if (haptic_) haptic_loop_ = declare(*haptic_, "", schema::kLoopFields);
  if (physics_) {
    physics_loop_ = declare(*physics_, "", schema::kLoopFields);
    physics_hash_ = declare(*physics_, "", schema::kPhysicsFields);
  }
  // Fingers and bodies as entity groups: one member of the row each, whatever their number.
  std::vector<std::string> fingers, bodies;
  for (const auto& f : model.fingers) fingers.push_back(f.name);
  for (const auto& b : model.bodies) bodies.push_back(b.name);
  const auto group = [](TraceTable* t, std::string_view name, const std::vector<std::string>& entities,
                        const auto& fields, std::vector<std::size_t>& offsets) {
    const std::size_t first = t && !entities.empty() ? declare_group(*t, std::string(name), entities, fields) : 0;
    const std::size_t stride = size_of_fields(fields).values;
    for (std::size_t k = 0; k < entities.size(); ++k) offsets.push_back(t ? first + k * stride : 0);
  };
  group(servo_, schema::kFingers, fingers, schema::kServoFingerFields, servo_fingers_);
  group(haptic_, schema::kFingers, fingers, schema::kHapticFingerFields, haptic_fingers_);
  group(physics_, schema::kObjects, bodies, schema::kBodyFields, objects_);
  if (haptic_) {
    std::string names;
    for (std::size_t k = 0; k < bodies.size(); ++k) names += (k > 0 ? "\n" : "") + bodies[k];
    haptic_->set_attribute(".", "bodies", names);
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
  // Tick k of a loop is kept when k % every == 0: the countdown is 0 at kept ticks.
  const auto kept = [](TraceTable* table, std::int64_t every, std::int64_t& wait) {
    if (!table) return false;
    const bool keep = wait == 0;
    wait = keep ? every - 1 : wait - 1;
    return keep;
  };

  if (kept(servo_, servo_every_, servo_wait_)) {
    double* row = servo_->append_row();
    fill<schema::kLoopFields>(row, servo_loop_, loop);
    for (std::size_t i = 0; i < fingers; ++i) {
      const schema::ServoFingerRow servo{rec.servo[i].hip, rendered[i], rec.servo[i].force,
                                         input.fingers[i].gimbal};
      fill<schema::kServoFingerFields>(row, servo_fingers_[i], servo);
    }
  }

  if (rec.haptic_ran && kept(haptic_, haptic_every_, haptic_wait_)) {
    double* row = haptic_->append_row();
    fill<schema::kLoopFields>(row, haptic_loop_, loop);
    for (std::size_t i = 0; i < fingers; ++i)
      fill<schema::kHapticFingerFields>(row, haptic_fingers_[i], rec.haptic[i]);
  }

  if (rec.physics_ran && kept(physics_, physics_every_, physics_wait_)) {
    double* row = physics_->append_row();
    fill<schema::kLoopFields>(row, physics_loop_, loop);
    fill<schema::kPhysicsFields>(row, physics_hash_, schema::PhysicsRow{state_hash(after)});
    for (std::size_t k = 0; k < objects_.size(); ++k)
      fill<schema::kBodyFields>(row, objects_[k], rec.physics[k]);
  }

  if (rec.physics_ran && kept(contacts_, contacts_every_, contacts_wait_)) {
    for (const graspsim::ContactRecord& c : rec.contacts) {
      double* row = contacts_->append_row();
      fill<schema::kLoopFields>(row, contacts_loop_, loop);
      fill<schema::kContactFields>(row, contact_fields_, c);
    }
  }
}

}  // namespace graspsim::recordings
