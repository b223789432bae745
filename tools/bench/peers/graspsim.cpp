// The scale scenes in graspsim, as a new user sets them up: the default scheme (implicit, BDF2)
// and the default contact law (no stiffness or damping set, engine/README.md, "Default contact"),
// friction kMu on every box and the floor, sleep off (the engine's default, as the peers' own
// sleeping is off unless --sleep). One World::step is one physics step: every loop runs at the
// scene's rate, and no finger, so a Simulation::step is the physics stage and nothing else.
#include <cmath>

#include "graspsim/engine/simulation.hpp"
#include "peers.hpp"

namespace graspsim::bench::peers {
namespace {

class GraspsimWorld final : public World {
 public:
  explicit GraspsimWorld(const Scene& scene) : sim_(model(scene)), input_(make_input(sim_.model())),
                                               record_(make_tick_record(sim_.model())) {}

  void step() override {
    sim_.step(input_, record_);
    if (record_.diverged_body >= 0 && trouble_.empty()) {
      trouble_ = "graspsim: body " + std::to_string(record_.diverged_body) + " diverged";
    }
  }

  void read(std::vector<BoxState>& out) const override {
    const State& state = sim_.state();
    out.resize(state.bodies.size());
    for (std::size_t i = 0; i < state.bodies.size(); ++i) {
      const BodyState& b = state.bodies[i];
      for (int k = 0; k < 3; ++k) {
        out[i].p[k] = b.position[k];
        out[i].v[k] = b.velocity[k];
        out[i].w[k] = b.angular_velocity[k];
      }
    }
  }

  std::string trouble() const override { return trouble_; }
  std::string notes() const override { return "implicit, BDF2, default contact law, sleep off"; }

 private:
  static Model model(const Scene& scene) {
    Model m;
    m.integrator = Integrator::kImplicit;
    const int rate = static_cast<int>(std::lround(1.0 / scene.dt));
    m.rates = Rates{rate, rate, rate};
    m.gravity = Vec3(0.0, 0.0, -scale::kGravity);
    m.floor.enabled = true;
    m.floor.material.mu = scale::kMu;
    m.sleep.enabled = scene.sleep;
    const Vec3 half = Vec3::Constant(0.5 * scale::kSide);
    for (const scale::BoxPose& p : scene.boxes) {
      BodyParams b;
      b.name = "box" + std::to_string(m.bodies.size());
      b.shape = box_shape(half);
      b.mass = scale::kMass;
      b.inertia = box_inertia(scale::kMass, half);
      b.position = Vec3(p.x, p.y, p.z);
      b.orientation = Quat(Eigen::AngleAxisd(p.yaw, Vec3::UnitZ()));
      b.material.mu = scale::kMu;
      m.bodies.push_back(b);
    }
    return m;
  }

  Simulation sim_;
  Input input_;
  TickRecord record_;
  std::string trouble_;
};

}  // namespace

std::unique_ptr<World> make_graspsim_world(const Scene& scene) { return std::make_unique<GraspsimWorld>(scene); }

}  // namespace graspsim::bench::peers
