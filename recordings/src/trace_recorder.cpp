// TraceRecorder: one /servo row per servo tick, one /haptic and /physics row per tick of those
// loops, with column offsets worked out once in the constructor.
#include "graspsim/recordings/trace_recorder.hpp"

#include <stdexcept>
#include <string>

#include "graspsim/engine/state_hash.hpp"

namespace graspsim::recordings {
namespace {

void check_name(const std::string& what, const std::string& name) {
  if (name.empty() || name == "." || name == ".." || name.find('/') != std::string::npos) {
    throw std::invalid_argument("trace: " + what + " name '" + name +
                                "' cannot be an HDF5 group name (empty, '.', '..' or has '/')");
  }
}

void put(double* row, std::size_t offset, const Vec3& v) {
  row[offset + 0] = v.x();
  row[offset + 1] = v.y();
  row[offset + 2] = v.z();
}

// Rows of a loop that runs every `divisor` servo ticks in `chunk_ticks` servo ticks (0: the
// writer's default).
std::size_t chunk_rows(std::int64_t chunk_ticks, std::int64_t divisor) {
  if (chunk_ticks <= 0 || divisor <= 0) return 0;
  return static_cast<std::size_t>((chunk_ticks + divisor - 1) / divisor);
}

}  // namespace

// Counted from the columns the constructor declares (tests/recordings/test_trace_recorder.cpp
// checks both against a written file): tick and time (int64, float64) in every table; per
// finger, 4 vectors in /servo, and 3 vectors and 3 scalars (12 float64), an int8 and an int32
// in /haptic; the state hash (uint64), then per body 5 vectors, a quaternion and 3 scalars (22
// float64) and 2 int32 in /physics.
TraceRecorder::Rows TraceRecorder::row_sizes(const graspsim::Model& model) {
  const std::size_t f = model.fingers.size(), b = model.bodies.size();
  Rows r;
  r.servo = {2 + 12 * f, 16 + 96 * f};
  r.haptic = {2 + 14 * f, 16 + (12 * 8 + 1 + 4) * f};
  r.physics = {3 + 24 * b, 24 + (22 * 8 + 2 * 4) * b};
  return r;
}

TraceRecorder::TraceRecorder(TraceWriter& writer, const graspsim::Model& model,
                             std::int64_t chunk_ticks)
    : servo_(writer.table("servo", chunk_rows(chunk_ticks, 1))),
      haptic_(writer.table("haptic", chunk_rows(chunk_ticks, divisors(model.rates).haptic))),
      physics_(writer.table("physics", chunk_rows(chunk_ticks, divisors(model.rates).physics))),
      servo_rate_(static_cast<double>(model.rates.servo)) {
  for (const auto& f : model.fingers) check_name("finger", f.name);
  for (const auto& b : model.bodies) check_name("object", b.name);

  auto time_columns = [](TraceTable& t) {
    TimeColumns c{};
    c.tick = t.add_column("tick", 1, DType::kInt64, "tick");
    c.time = t.add_column("time", 1, DType::kFloat64, "s");
    return c;
  };
  servo_time_ = time_columns(servo_);
  haptic_time_ = time_columns(haptic_);
  physics_time_ = time_columns(physics_);
  state_hash_ = physics_.add_column("state_hash", 1, DType::kUInt64, "1");
  physics_.set_attribute("state_hash", "hash",
                         "FNV-1a-style word hash of the engine State after this tick's step "
                         "(graspsim::state_hash, engine/README.md)");

  for (const auto& finger : model.fingers) {
    const std::string p = "fingers/" + finger.name + "/";
    ServoColumns s{};
    s.hip = servo_.add_column(p + "hip", 3, DType::kFloat64, "m");
    s.force = servo_.add_column(p + "force", 3, DType::kFloat64, "N");
    s.force_demand = servo_.add_column(p + "force_demand", 3, DType::kFloat64, "N");
    s.gimbal = servo_.add_column(p + "gimbal", 3, DType::kFloat64, "rad");
    servo_.set_attribute(p + "gimbal", "order", "roll, pitch, yaw");
    servo_fingers_.push_back(s);

    HapticColumns h{};
    h.god_object = haptic_.add_column(p + "god_object", 3, DType::kFloat64, "m");
    h.surface_point = haptic_.add_column(p + "surface_point", 3, DType::kFloat64, "m");
    h.depth = haptic_.add_column(p + "depth", 1, DType::kFloat64, "m");
    h.friction_radius = haptic_.add_column(p + "friction_radius", 1, DType::kFloat64, "m");
    h.force = haptic_.add_column(p + "force", 3, DType::kFloat64, "N");
    h.state = haptic_.add_column(p + "state", 1, DType::kInt8, "1");
    haptic_.set_attribute(p + "state", "values", "0 free, 1 stick, 2 slip");
    h.body = haptic_.add_column(p + "body", 1, DType::kInt32, "1");
    haptic_.set_attribute(p + "body", "values", "-1 none, -2 floor, k = objects[k]");
    h.slip = haptic_.add_column(p + "slip", 1, DType::kFloat64, "m");
    haptic_fingers_.push_back(h);
  }
  std::string bodies;
  for (std::size_t k = 0; k < model.bodies.size(); ++k) {
    bodies += (k > 0 ? "\n" : "") + model.bodies[k].name;
  }
  haptic_.set_attribute(".", "bodies", bodies);

  for (const auto& body : model.bodies) {
    const std::string p = "objects/" + body.name + "/";
    PhysicsColumns o{};
    o.position = physics_.add_column(p + "position", 3, DType::kFloat64, "m");
    o.quaternion = physics_.add_column(p + "quaternion", 4, DType::kFloat64, "1");
    physics_.set_attribute(p + "quaternion", "order", "w, x, y, z");
    o.velocity = physics_.add_column(p + "velocity", 3, DType::kFloat64, "m/s");
    o.angular_velocity = physics_.add_column(p + "angular_velocity", 3, DType::kFloat64, "rad/s");
    o.force = physics_.add_column(p + "force", 3, DType::kFloat64, "N");
    o.torque = physics_.add_column(p + "torque", 3, DType::kFloat64, "N m");
    o.floor_contacts = physics_.add_column(p + "floor_contacts", 1, DType::kInt32, "1");
    o.body_contacts = physics_.add_column(p + "body_contacts", 1, DType::kInt32, "1");
    o.grasp_area = physics_.add_column(p + "grasp_area", 1, DType::kFloat64, "m^2");
    o.torsion = physics_.add_column(p + "torsion", 1, DType::kFloat64, "N m");
    o.twist = physics_.add_column(p + "twist", 1, DType::kFloat64, "rad");
    objects_.push_back(o);
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
  const double tick = static_cast<double>(rec.tick);
  const double time = tick / servo_rate_;   // s, from the tick, never accumulated

  double* row = servo_.append_row();
  row[servo_time_.tick] = tick;
  row[servo_time_.time] = time;
  for (std::size_t i = 0; i < fingers; ++i) {
    const ServoColumns& c = servo_fingers_[i];
    put(row, c.hip, rec.servo[i].hip);
    put(row, c.force, rendered[i]);
    put(row, c.force_demand, rec.servo[i].force);
    put(row, c.gimbal, input.fingers[i].gimbal);
  }

  if (rec.haptic_ran) {
    row = haptic_.append_row();
    row[haptic_time_.tick] = tick;
    row[haptic_time_.time] = time;
    for (std::size_t i = 0; i < fingers; ++i) {
      const HapticColumns& c = haptic_fingers_[i];
      const HapticFingerRecord& h = rec.haptic[i];
      put(row, c.god_object, h.god_object);
      put(row, c.surface_point, h.surface_point);
      row[c.depth] = h.depth;
      row[c.friction_radius] = h.friction_radius;
      put(row, c.force, h.force);
      row[c.state] = static_cast<double>(static_cast<int>(h.phase));
      row[c.body] = static_cast<double>(h.body);
      row[c.slip] = h.slip;
    }
  }

  if (rec.physics_ran) {
    row = physics_.append_row();
    row[physics_time_.tick] = tick;
    row[physics_time_.time] = time;
    row[state_hash_] = uint64_in_row(state_hash(after));
    for (std::size_t k = 0; k < objects_.size(); ++k) {
      const PhysicsColumns& c = objects_[k];
      const BodyRecord& b = rec.physics[k];
      put(row, c.position, b.position);
      row[c.quaternion + 0] = b.orientation.w();
      row[c.quaternion + 1] = b.orientation.x();
      row[c.quaternion + 2] = b.orientation.y();
      row[c.quaternion + 3] = b.orientation.z();
      put(row, c.velocity, b.velocity);
      put(row, c.angular_velocity, b.angular_velocity);
      put(row, c.force, b.force);
      put(row, c.torque, b.torque);
      row[c.floor_contacts] = static_cast<double>(b.floor_contacts);
      row[c.body_contacts] = static_cast<double>(b.body_contacts);
      row[c.grasp_area] = b.grasp_area;
      row[c.torsion] = b.torsion;
      row[c.twist] = b.twist;
    }
  }
}

}  // namespace graspsim::recordings
