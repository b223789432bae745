// The trace schema as data: one table of fields per record. TraceRecorder and DeviceRecorder
// declare their columns and fill their rows from these tables, and
// tests/e2e/test_trace_schema.cpp checks recordings/README.md against them, so a new column is
// one line here (plus its member in the record and its row in the README).
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "graspsim/engine/math.hpp"
#include "graspsim/engine/record.hpp"
#include "graspsim/engine/state.hpp"
#include "graspsim/recordings/trace_writer.hpp"

namespace graspsim::recordings::schema {

// How a C++ member is stored: its dtype, its values per row, and how it goes into the row of
// doubles (TraceTable::append_row; integers exact, a uint64 as its raw bits).
template <typename T>
struct Stored;
template <>
struct Stored<double> {
  static constexpr DType dtype = DType::kFloat64;
  static constexpr int width = 1;
  static void put(double v, double* out) { out[0] = v; }
};
template <>
struct Stored<Vec3> {
  static constexpr DType dtype = DType::kFloat64;
  static constexpr int width = 3;   // x, y, z
  static void put(const Vec3& v, double* out) {
    out[0] = v.x();
    out[1] = v.y();
    out[2] = v.z();
  }
};
template <>
struct Stored<Quat> {
  static constexpr DType dtype = DType::kFloat64;
  static constexpr int width = 4;   // w, x, y, z (the column's `order` note says so)
  static void put(const Quat& q, double* out) {
    out[0] = q.w();
    out[1] = q.x();
    out[2] = q.y();
    out[3] = q.z();
  }
};
template <>
struct Stored<int> {
  static constexpr DType dtype = DType::kInt32;
  static constexpr int width = 1;
  static void put(int v, double* out) { out[0] = static_cast<double>(v); }
};
template <>
struct Stored<std::int64_t> {
  static constexpr DType dtype = DType::kInt64;
  static constexpr int width = 1;
  static void put(std::int64_t v, double* out) { out[0] = static_cast<double>(v); }
};
template <>
struct Stored<std::int8_t> {
  static constexpr DType dtype = DType::kInt8;
  static constexpr int width = 1;
  static void put(std::int8_t v, double* out) { out[0] = static_cast<double>(v); }
};
template <>
struct Stored<std::uint64_t> {
  static constexpr DType dtype = DType::kUInt64;
  static constexpr int width = 1;
  static void put(std::uint64_t v, double* out) { out[0] = uint64_in_row(v); }
};
template <>
struct Stored<ContactPhase> {
  static constexpr DType dtype = DType::kInt8;
  static constexpr int width = 1;
  static void put(ContactPhase v, double* out) { out[0] = static_cast<double>(static_cast<int>(v)); }
};

// A column attribute besides its units: what its values or components mean.
struct Note {
  std::string_view name;    // "order", "values", "hash"; empty: none
  std::string_view value;
};

// One column: a member of a record, its name below the table's prefix, its units.
template <typename Record>
struct Field {
  std::string_view name;    // column path below the prefix ("hip" -> fingers/<finger>/hip)
  std::string_view units;   // attribute "<column>/units"
  DType dtype;
  int width;                // values per row: (n) for 1, (n,width) otherwise
  void (*put)(const Record&, double* out);   // writes `width` values of the record to `out`
  Note note;
};

template <typename>
struct MemberOf;
template <typename Record, typename T>
struct MemberOf<T Record::*> {
  using Class = Record;
  using Type = T;
};

// The column of member `M`: dtype, width and conversion follow from the member's type.
template <auto M>
constexpr Field<typename MemberOf<decltype(M)>::Class> field(std::string_view name,
                                                             std::string_view units,
                                                             Note note = {}) {
  using Record = typename MemberOf<decltype(M)>::Class;
  using T = typename MemberOf<decltype(M)>::Type;
  return {name, units, Stored<T>::dtype, Stored<T>::width,
          [](const Record& r, double* out) { Stored<T>::put(r.*M, out); }, note};
}

// Columns every loop table starts with, one row per tick of its loop.
struct LoopRow {
  std::int64_t tick = 0;   // servo tick
  double time = 0.0;       // s: tick / rate_servo, from the tick, never accumulated
};
// /physics after tick and time.
struct PhysicsRow {
  std::uint64_t state_hash = 0;   // 1: graspsim::state_hash of the State after this tick's step
};
// /servo per finger: the device input of this tick and the forces it gave.
struct ServoFingerRow {
  Vec3 hip;            // m, world: ServoFingerRecord::hip
  Vec3 force;          // N, world: the force the device rendered, after clamping
  Vec3 force_demand;   // N, world: ServoFingerRecord::force, before clamping
  Vec3 gimbal;         // rad: FingerInput::gimbal (roll, pitch, yaw)
};

// /devices/<finger> per servo tick, for a finger driven by a device that is not scripted: the
// device's own view of the sample it gave and of the force it was sent (DeviceRecorder).
struct DeviceRow {
  std::int64_t tick = 0;       // servo tick the sample was used at
  double time = 0.0;           // s: tick / rate_servo
  double device_time = 0.0;    // s: when the device took the sample, on its own clock
  Vec3 position{0.0, 0.0, 0.0};   // m, device frame: before the workspace mapping
  Vec3 gimbal{0.0, 0.0, 0.0};     // rad: stylus gimbal angles (roll, pitch, yaw)
  std::int64_t buttons = 0;       // 1: bit i set while button i was pressed
  Vec3 force{0.0, 0.0, 0.0};      // N, device frame: the force requested of the device
  std::int8_t overrun = 0;        // 1 when this servo tick missed its real-time deadline
};
// /devices/<finger> after DeviceRow, when the run records the device's sample numbering.
struct DeviceCounterRow {
  std::int64_t sequence = -1;      // 1: the device's own number of the sample; -1 without one
  std::int64_t new_samples = -1;   // 1: new samples since the previous servo tick; -1 without
};

inline constexpr std::string_view kDevices = "devices/";   // + <finger>
inline constexpr std::string_view kServo = "servo";        // every servo tick
inline constexpr std::string_view kHaptic = "haptic";      // every haptic tick
inline constexpr std::string_view kPhysics = "physics";    // every physics tick
inline constexpr std::string_view kContacts = "contacts";  // a row per contact point per physics tick
// The entity groups (TraceTable::add_group): columns fingers/<finger>/<field> of /servo and
// /haptic, objects/<object>/<field> of /physics.
inline constexpr std::string_view kFingers = "fingers";
inline constexpr std::string_view kObjects = "objects";

// A column of one entity, relative to its table, as every reader names it whatever the layout
// (trace_reader.hpp): "fingers/thumb/hip" of /servo, "objects/box/position" of /physics.
inline std::string finger_column(std::string_view finger, std::string_view field) {
  return std::string(kFingers) + "/" + std::string(finger) + "/" + std::string(field);
}
inline std::string object_column(std::string_view object, std::string_view field) {
  return std::string(kObjects) + "/" + std::string(object) + "/" + std::string(field);
}

inline constexpr Field<LoopRow> kLoopFields[] = {
    field<&LoopRow::tick>("tick", "tick"),
    field<&LoopRow::time>("time", "s"),
};

inline constexpr Field<PhysicsRow> kPhysicsFields[] = {
    field<&PhysicsRow::state_hash>("state_hash", "1",
                                   {"hash", "FNV-1a-style word hash of the engine State after this tick's step "
                                            "(graspsim::state_hash, engine/README.md)"}),
};

inline constexpr Field<ServoFingerRow> kServoFingerFields[] = {
    field<&ServoFingerRow::hip>("hip", "m"),
    field<&ServoFingerRow::force>("force", "N"),
    field<&ServoFingerRow::force_demand>("force_demand", "N"),
    field<&ServoFingerRow::gimbal>("gimbal", "rad", {"order", "roll, pitch, yaw"}),
};

inline constexpr Field<HapticFingerRecord> kHapticFingerFields[] = {
    field<&HapticFingerRecord::god_object>("god_object", "m"),
    field<&HapticFingerRecord::surface_point>("surface_point", "m"),
    field<&HapticFingerRecord::depth>("depth", "m"),
    field<&HapticFingerRecord::friction_radius>("friction_radius", "m"),
    field<&HapticFingerRecord::force>("force", "N"),
    field<&HapticFingerRecord::phase>("state", "1", {"values", "0 free, 1 stick, 2 slip"}),
    field<&HapticFingerRecord::body>("body", "1", {"values", "-1 none, -2 floor, k = objects[k]"}),
    field<&HapticFingerRecord::slip>("slip", "m"),
};

inline constexpr Field<BodyRecord> kBodyFields[] = {
    field<&BodyRecord::position>("position", "m"),
    field<&BodyRecord::orientation>("quaternion", "1", {"order", "w, x, y, z"}),
    field<&BodyRecord::velocity>("velocity", "m/s"),
    field<&BodyRecord::angular_velocity>("angular_velocity", "rad/s"),
    field<&BodyRecord::force>("force", "N"),
    field<&BodyRecord::torque>("torque", "N m"),
    field<&BodyRecord::floor_contacts>("floor_contacts", "1"),
    field<&BodyRecord::body_contacts>("body_contacts", "1"),
    field<&BodyRecord::grasp_area>("grasp_area", "m^2"),
    field<&BodyRecord::torsion>("torsion", "N m"),
    field<&BodyRecord::twist>("twist", "rad"),
};

// /contacts after tick and time: one row per floor or body-body point of a physics step.
inline constexpr Field<ContactRecord> kContactFields[] = {
    field<&ContactRecord::a>("a", "1", {"values", "-2 floor, k = objects[k]"}),
    field<&ContactRecord::b>("b", "1", {"values", "k = objects[k]"}),
    field<&ContactRecord::point>("point", "m"),
    field<&ContactRecord::normal>("normal", "1"),
    field<&ContactRecord::force>("force", "N"),
};

inline constexpr Field<DeviceRow> kDeviceFields[] = {
    field<&DeviceRow::tick>("tick", "tick"),
    field<&DeviceRow::time>("time", "s"),
    field<&DeviceRow::device_time>("device_time", "s"),
    field<&DeviceRow::position>("position", "m"),
    field<&DeviceRow::gimbal>("gimbal", "rad", {"order", "roll, pitch, yaw"}),
    field<&DeviceRow::buttons>("buttons", "1"),
    field<&DeviceRow::force>("force", "N"),
    field<&DeviceRow::overrun>("overrun", "1"),
};

inline constexpr Field<DeviceCounterRow> kDeviceCounterFields[] = {
    field<&DeviceCounterRow::sequence>("sequence", "1"),
    field<&DeviceCounterRow::new_samples>("new_samples", "1"),
};

// One column as recordings/README.md documents it: "/servo/fingers/<finger>/hip", with the
// README's placeholders <finger> and <object> for the names.
struct ColumnDoc {
  std::string path;
  int width = 1;
  DType dtype = DType::kFloat64;
  std::string units;
  Note note;
};

// Every column TraceRecorder and DeviceRecorder write, in the order they declare them (one
// finger, one object, one device with counters).
std::vector<ColumnDoc> recorded_columns();

}  // namespace graspsim::recordings::schema
