// graspsim_peers (tools/bench/README.md, "Peers"): what each engine (graspsim and its peers)
// provides, a World built from the scale scenes' box poses (bench/scale_scenes.hpp), and the
// record measured for one (engine, layout, n, rate) run. Engine types stay inside graspsim.cpp,
// ode.cpp, mujoco.cpp and bullet.cpp.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "bench/scale_scenes.hpp"

namespace graspsim::bench::peers {

// What an engine is built from: the boxes exactly as layout_boxes() gives them, the floor z = 0,
// every constant of scale_scenes.hpp (kSide, kMass, kMu, kGravity), and the step.
struct Scene {
  std::vector<scale::BoxPose> boxes;
  double dt = 0.0;      // s: one step
  bool sleep = false;   // leave the engine's own sleeping on (Bullet's deactivation; --sleep)
  int room = 0;         // 1: contacts per box to make room for where the engine sizes its
                        // contact arrays up front (MuJoCo 2.2); 0: the engine's default
};

// One box, world frame.
struct BoxState {
  double p[3];   // m: centre
  double v[3];   // m/s: velocity of the centre
  double w[3];   // rad/s: angular velocity
};

// A built scene in one engine.
class World {
 public:
  virtual ~World() = default;
  virtual void step() = 0;                                   // one step of Scene::dt (the timed call)
  virtual void read(std::vector<BoxState>& out) const = 0;   // every box, in Scene::boxes' order
  virtual std::string trouble() const { return {}; }         // what the engine reported going wrong
                                                             // so far ("" nothing)
  virtual bool out_of_room() const { return false; }         // contacts dropped: Scene::room too small
  virtual std::string notes() const { return {}; }           // settings chosen by the engine (--verbose)
};

std::unique_ptr<World> make_graspsim_world(const Scene& scene);
std::unique_ptr<World> make_ode_world(const Scene& scene);
std::unique_ptr<World> make_mujoco_world(const Scene& scene);
std::unique_ptr<World> make_bullet_world(const Scene& scene);

// Ends the measuring child process now, its run failed for `why`: for an engine's error handler
// that must not return into the engine (main.cpp sends the record so far to the parent).
[[noreturn]] void fail_run(const std::string& why);

// What one run measured, sent from the child process that ran it to the parent through a pipe:
// plain data, no pointers.
struct Record {
  int steps = 0;                  // steps taken (fewer than planned when it failed)
  int room = 0;                   // 1: the Scene::room the run had (MuJoCo's arena)
  double us_median = 0.0;         // us: wall time of one step, median over the run's steps
  double us_min = 0.0;            // us
  double us_max = 0.0;            // us
  double cpu_us_median = 0.0;     // us: this thread's CPU time of one step, median over the run's steps
  double rss_mb = 0.0;            // MB (2^20 B): peak RSS growth from before the World was built
  double energy_start = 0.0;      // J: E at t = 0
  double energy_rise = 0.0;       // J: max over the run of E(t) - E(0), >= 0
  double drift_end = 0.0;         // m: largest distance of a box's centre from its built pose, at the end
  double speed_end = 0.0;         // m/s: largest speed of a box's centre, at the end
  double thrown = 0.0;            // m: highest any centre got above its start, over the run
  char failed[240] = {};          // why the run failed ("" it did not)
};

}  // namespace graspsim::bench::peers
