// The scene as JSON and the blob of columns the page animates.
#include "view/server/pack.hpp"

#include "app/json.hpp"

#include <bit>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <vector>

namespace graspsim::view {
namespace {

using app::json_string;

static_assert(std::endian::native == std::endian::little, "the blob is little-endian, as typed arrays read it");

std::string number(double x) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.17g", x);
  return buf;
}

// Appends arrays to the blob, each at an 8-byte offset, and lists them for the JSON.
class Blob {
 public:
  template <typename T>
  void add(const std::string& name, const std::vector<T>& values, const char* type) {
    blob_.resize((blob_.size() + 7) / 8 * 8, '\0');
    layout_ += std::string(layout_.empty() ? "" : ",\n    ") + "{\"name\": " + json_string(name) + ", \"type\": \"" +
               type + "\", \"offset\": " + std::to_string(blob_.size()) + ", \"length\": " +
               std::to_string(values.size()) + "}";
    const std::size_t at = blob_.size();
    blob_.resize(at + values.size() * sizeof(T));
    if (!values.empty()) std::memcpy(blob_.data() + at, values.data(), values.size() * sizeof(T));
  }
  void add_ticks(const std::string& name, const std::vector<std::int64_t>& ticks) {
    add(name, std::vector<double>(ticks.begin(), ticks.end()), "f64");   // exact below 2^53
  }
  std::string& bytes() { return blob_; }
  const std::string& layout() const { return layout_; }

 private:
  std::string blob_, layout_;
};

std::string vec3(const Vec3& v) {
  char buf[96];
  std::snprintf(buf, sizeof buf, "[%.17g, %.17g, %.17g]", v.x(), v.y(), v.z());
  return buf;
}

const char* kind_name(ShapeKind k) {
  switch (k) {
    case ShapeKind::kBox: return "box";
    case ShapeKind::kSphere: return "sphere";
    case ShapeKind::kCylinder: return "cylinder";
    case ShapeKind::kCapsule: return "capsule";
    case ShapeKind::kConvex: return "convex";
    case ShapeKind::kMesh: return "mesh";
  }
  return "box";
}

// One body's shape: kind and sizes (m); convex and mesh shapes with their vertices (m, body
// frame, 3 per vertex) and triangles (3 indices each, counter-clockwise seen from outside).
std::string shape_json(const BodyView& b) {
  if (!b.shape_known) return "{\"kind\": \"unknown\"}";
  const Shape& s = b.shape;
  std::string j = std::string("{\"kind\": \"") + kind_name(s.kind) + "\", \"half_extents\": " + vec3(s.half_extents) +
                  ", \"radius\": " + number(s.radius) + ", \"half_length\": " + number(s.half_length);
  if ((s.kind == ShapeKind::kConvex || s.kind == ShapeKind::kMesh) && s.mesh) {
    j += ", \"vertices\": [";
    for (std::size_t i = 0; i < s.mesh->vertices.size(); ++i) {
      const Vec3& v = s.mesh->vertices[i];
      j += (i ? ", " : "") + number(v.x()) + ", " + number(v.y()) + ", " + number(v.z());
    }
    j += "], \"triangles\": [";
    for (std::size_t i = 0; i < s.mesh->triangles.size(); ++i) {
      const auto& t = s.mesh->triangles[i];
      j += (i ? ", " : "") + std::to_string(t[0]) + ", " + std::to_string(t[1]) + ", " + std::to_string(t[2]);
    }
    j += "]";
  }
  return j + "}";
}

}  // namespace

Packed pack_scene(const ViewScene& s) {
  Blob blob;
  blob.add_ticks("physics_tick", s.physics_tick);
  blob.add_ticks("haptic_tick", s.haptic_tick);
  std::string bodies, fingers;
  for (std::size_t i = 0; i < s.bodies.size(); ++i) {
    const BodyView& b = s.bodies[i];
    blob.add("body/" + std::to_string(i) + "/position", b.position, "f64");
    blob.add("body/" + std::to_string(i) + "/quaternion", b.quaternion, "f64");
    for (const auto& [name, values] : {std::pair{"grasp_area", &b.grasp_area}, {"torsion", &b.torsion},
                                       {"floor_contacts", &b.floor_contacts}, {"body_contacts", &b.body_contacts}})
      blob.add("body/" + std::to_string(i) + "/" + name, *values, "f64");
    bodies += std::string(i ? ",\n    " : "") + "{\"name\": " + json_string(b.name) + ", \"shape\": " + shape_json(b) + "}";
  }
  for (std::size_t j = 0; j < s.fingers.size(); ++j) {
    const FingerView& f = s.fingers[j];
    const std::string p = "finger/" + std::to_string(j) + "/";
    blob.add(p + "hip", f.hip, "f64");
    blob.add(p + "god_object", f.god_object, "f64");
    blob.add(p + "force", f.force, "f64");
    blob.add(p + "surface_point", f.surface_point, "f64");
    blob.add(p + "friction_radius", f.friction_radius, "f64");
    blob.add(p + "state", f.state, "i8");
    blob.add(p + "depth", f.depth, "f64");
    blob.add(p + "slip", f.slip, "f64");
    blob.add(p + "body", f.body, "f64");
    fingers += std::string(j ? ",\n    " : "") + "{\"name\": " + json_string(f.name) + ", \"radius\": " + number(f.radius) + "}";
  }
  blob.add_ticks("contact_tick", s.contact_tick);
  blob.add("contact/a", s.contact_a, "f64");
  blob.add("contact/b", s.contact_b, "f64");
  blob.add("contact/point", s.contact_point, "f64");
  blob.add("contact/force", s.contact_force, "f64");
  Packed out;
  out.json = "{\n  \"live\": " + std::string(s.live ? "true" : "false") + ",\n  \"trace\": " + json_string(s.trace) + ",\n  \"scenario\": " + json_string(s.scenario_name) +
             ",\n  \"status\": " + json_string(s.status) + ",\n  \"note\": " + json_string(s.note) +
             ",\n  \"rates\": {\"servo\": " + std::to_string(s.rate_servo) + ", \"haptic\": " +
             std::to_string(s.rate_haptic) + ", \"physics\": " + std::to_string(s.rate_physics) +
             "},\n  \"duration\": " + number(s.duration) + ",\n  \"floor\": {\"enabled\": " +
             (s.floor ? "true" : "false") + ", \"height\": " + number(s.floor_height) + "},\n  \"contacts\": " +
             (s.contacts ? "true" : "false") + ",\n  \"bodies\": [\n    " +
             bodies + "],\n  \"fingers\": [\n    " + fingers + "],\n  \"blob\": [\n    " + blob.layout() + "]\n}\n";
  out.blob = std::move(blob.bytes());
  return out;
}

}  // namespace graspsim::view
