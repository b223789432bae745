// The scale scenes in MuJoCo 2.2.2 (Debian's libmujoco-dev), from an MJCF string made here:
// each box a body with a free joint and one box geom (mass 1 kg, so its inertia m s^2 / 6),
// the floor a plane geom, friction 0.6 on every geom (MuJoCo takes the larger of a pair's, so
// 0.6 for every contact; its torsional and rolling terms are unused at the default condim 3).
// Everything else is MuJoCo's default: <option timestep = 1/rate> only, so the Euler
// integrator, the Newton solver (100 iterations, tolerance 1e-8), pyramidal friction cones,
// soft contacts with the default solref (0.02 s, damping ratio 1) and solimp. The contact list
// and the arena (nconmax, njmax, nstack) are MuJoCo's default for Scene::room 0, and
// <size nconmax = room n, njmax = 4 room n> otherwise (main.cpp raises room while contacts are
// dropped). A step is mj_step. What MuJoCo counts as a warning (too many contacts or
// constraints, a bad qacc, after which mj_step resets the data to the model's start) is the
// run's trouble; an mju_error (an allocation or the stack allocator out of its arena) fails it.
#include <mujoco/mujoco.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <stdexcept>

#include "peers.hpp"

namespace graspsim::bench::peers {
namespace {

void mujoco_error(const char* msg) { fail_run(std::string("mujoco error: ") + msg); }
void mujoco_warning(const char*) {}   // counted in mjData::warning, read by trouble()

// The scene as MJCF. Poses printed with 17 significant digits, so that the model's boxes are
// the header's to the last bit; the yaw as a quaternion about z.
std::string mjcf(const Scene& scene) {
  char line[512];
  std::string xml = "<mujoco model=\"scale\">\n";
  std::snprintf(line, sizeof line, "  <option timestep=\"%.17g\"/>\n  <worldbody>\n", scene.dt);
  xml += line;
  std::snprintf(line, sizeof line, "    <geom name=\"floor\" type=\"plane\" size=\"0 0 1\" friction=\"%.17g 0.005 0.0001\"/>\n",
                scale::kMu);
  xml += line;
  const double half = 0.5 * scale::kSide;
  for (const scale::BoxPose& b : scene.boxes) {
    std::snprintf(line, sizeof line,
                  "    <body pos=\"%.17g %.17g %.17g\" quat=\"%.17g 0 0 %.17g\"><freejoint/>"
                  "<geom type=\"box\" size=\"%.17g %.17g %.17g\" mass=\"%.17g\" friction=\"%.17g 0.005 0.0001\"/></body>\n",
                  b.x, b.y, b.z, std::cos(0.5 * b.yaw), std::sin(0.5 * b.yaw), half, half, half, scale::kMass,
                  scale::kMu);
    xml += line;
  }
  xml += "  </worldbody>\n</mujoco>\n";
  if (scene.room > 0) {   // condim 3 in a pyramidal cone: 4 constraint rows per contact
    const long contacts = static_cast<long>(scene.room) * static_cast<long>(scene.boxes.size());
    std::snprintf(line, sizeof line, "  <size nconmax=\"%ld\" njmax=\"%ld\"/>\n", contacts, 4 * contacts);
    xml.insert(xml.find("  <worldbody>"), line);
  }
  return xml;
}

class MujocoWorld final : public World {
 public:
  explicit MujocoWorld(const Scene& scene) {
    mju_user_error = mujoco_error;
    mju_user_warning = mujoco_warning;
    const std::string xml = mjcf(scene);
    auto vfs = std::make_unique<mjVFS>();
    mj_defaultVFS(vfs.get());
    if (mj_makeEmptyFileVFS(vfs.get(), "scale.xml", static_cast<int>(xml.size())) != 0)
      throw std::runtime_error("mujoco: cannot make the in-memory file");
    std::memcpy(vfs->filedata[0], xml.data(), xml.size());
    char error[1000] = "";
    model_ = mj_loadXML("scale.xml", vfs.get(), error, sizeof error);
    mj_deleteVFS(vfs.get());
    const std::string arena = scene.room > 0 ? " (arena for " + std::to_string(scene.room) + " contacts a box)" : "";
    if (!model_) throw std::runtime_error("mujoco: MJCF refused" + arena + ": " + error);
    data_ = mj_makeData(model_);
    if (!data_) throw std::runtime_error("mujoco: mj_makeData failed" + arena);
    mj_forward(model_, data_);
  }

  ~MujocoWorld() override {
    mj_deleteData(data_);
    mj_deleteModel(model_);
  }

  void step() override { mj_step(model_, data_); }

  // qpos of a free joint: position, quaternion (w x y z); qvel: linear velocity in the world
  // frame, angular velocity in the body's, turned here to the world's.
  void read(std::vector<BoxState>& out) const override {
    out.resize(static_cast<std::size_t>(model_->njnt));
    for (int j = 0; j < model_->njnt; ++j) {
      const mjtNum* q = data_->qpos + model_->jnt_qposadr[j];
      const mjtNum* v = data_->qvel + model_->jnt_dofadr[j];
      BoxState& s = out[static_cast<std::size_t>(j)];
      mju_rotVecQuat(s.w, v + 3, q + 3);
      for (int k = 0; k < 3; ++k) {
        s.p[k] = q[k];
        s.v[k] = v[k];
      }
    }
  }

  std::string trouble() const override {
    static const char* const kNames[mjNWARNING] = {"inertia", "contact list full", "constraints full",
                                                   "visual geoms full", "bad qpos", "bad qvel",
                                                   "bad qacc (data reset)", "bad ctrl"};
    std::string text;
    for (int k = 0; k < mjNWARNING; ++k) {
      if (data_->warning[k].number == 0) continue;
      text += (text.empty() ? "mujoco: " : "; ") + std::string(kNames[k]) + " x" +
              std::to_string(data_->warning[k].number);
    }
    return text;
  }

  bool out_of_room() const override {
    return data_->warning[mjWARN_CONTACTFULL].number > 0 || data_->warning[mjWARN_CNSTRFULL].number > 0;
  }

  std::string notes() const override {   // the arena MuJoCo sized for the model
    return "nstack " + std::to_string(model_->nstack) + " njmax " + std::to_string(model_->njmax) + " nconmax " +
           std::to_string(model_->nconmax) +
           " maxuse_con " + std::to_string(data_->maxuse_con) + " maxuse_efc " + std::to_string(data_->maxuse_efc) +
           " maxuse_stack " + std::to_string(data_->maxuse_stack) + " nbuffer " + std::to_string(model_->nbuffer);
  }

 private:
  mjModel* model_ = nullptr;
  mjData* data_ = nullptr;
};

}  // namespace

std::unique_ptr<World> make_mujoco_world(const Scene& scene) { return std::make_unique<MujocoWorld>(scene); }

}  // namespace graspsim::bench::peers
