// The physics stage under integrator = "implicit" (engine/README.md, "Integrators"): every contact
// point (fingers, floor, other bodies) a spring-damper about this tick's state, the islands of
// bodies that push on each other solved at once (island_solve.hpp), then body by body the grasp
// rules and the move. Owns everything only this scheme needs.
#pragma once

#include <cstdint>
#include <vector>

#include "graspsim/engine/contact_gather.hpp"
#include "graspsim/engine/contact_law.hpp"
#include "graspsim/engine/coupling.hpp"
#include "graspsim/engine/grasp_rules.hpp"
#include "graspsim/engine/island_solve.hpp"
#include "graspsim/engine/model.hpp"
#include "graspsim/engine/record.hpp"
#include "graspsim/engine/state.hpp"

namespace graspsim {

class ImplicitStage {
 public:
  explicit ImplicitStage(const Model& model);

  // One physics step of every body. `input` holds the HIPs at this tick; `finger_point` (m, world,
  // per finger) where each finger's force acted at the last servo tick; `ticks_per_step` servo
  // ticks make the step; `pitch_change` (rad) is the gimbal finger's since the last step. With
  // `record_contacts`, each floor and body point with its solved force goes to record.contacts.
  void step(const Model& model, State& state, ContactGather& contacts, const Input& input,
            const std::vector<Vec3>& finger_point, std::int64_t ticks_per_step, double pitch_change,
            bool record_contacts, TickRecord& record);

  // This step's contact points (fingers, then the gather's), their modes and forces as solved.
  const std::vector<Coupling>& couplings() const { return couplings_; }
  const IslandSolve& solve() const { return solve_; }

 private:
  void finger_couplings(const Model& model, State& state, const Input& input, const std::vector<Vec3>& finger_point,
                        std::int64_t ticks_per_step);
  void loads(const Model& model, const State& state, std::int64_t ticks_per_step, double pitch_change);
  void keep_modes(const Model& model, State& state);
  void record_points(TickRecord& record) const;
  void body_step(const Model& model, State& state, int b, TickRecord& record);

  IslandSolve solve_;
  StepHistory history_;                   // per body: what the BDF2 step needs of the last step
  std::vector<Coupling> couplings_;       // this step's contact points
  std::vector<std::uint8_t> awake_;       // per body: 1 when stepped
  std::vector<Vec3> v0_, w0_;             // m/s, rad/s, per body: velocities at the start of the step
                                          //   (w0 after the gyroscopic change)
  std::vector<Vec3> external_force_;      // N, per body: fingers' window mean and gravity
  std::vector<Vec3> external_torque_;     // N m, per body: fingers' window mean
  std::vector<Wrench> contact_wrench_;    // per body: floor and bodies at the start, pushing only
                                          //   (what the grasp rules see)
  std::vector<AxisRule> rules_;           // per body: its grasp rule this step
  std::vector<int> floor_points_, body_points_;   // per body: points the solve keeps pushing
};

}  // namespace graspsim
