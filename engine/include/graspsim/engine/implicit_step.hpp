// The linearly implicit physics step: every body, and every group of bodies that touch, moved at
// once over all of its spring-damper couplings (fingers, floor points, other bodies), so that no
// stiffness, damping or physics rate can make the step gain energy (engine/README.md,
// "Integrators").
#pragma once

#include <cstdint>
#include <vector>

#include "graspsim/engine/coupling.hpp"
#include "graspsim/engine/math.hpp"
#include "graspsim/engine/model.hpp"
#include "graspsim/engine/state.hpp"

namespace graspsim {

// What the second-order step needs of the last one, per body (ImplicitStep::solve).
struct StepHistory {
  int order = 1;                            // 1: backward Euler everywhere; 2: BDF2 where the history allows
  std::vector<std::uint8_t> valid;          // stepped at the last physics tick (awake since)
  std::vector<std::uint64_t> signature;     // its island's couplings and their modes at the last step
  std::vector<int> steps;                   // 1: physics steps in a row its island kept that signature
};

// The solver's buffers, sized once for the model so that the step allocates nothing.
class ImplicitStep {
 public:
  explicit ImplicitStep(const Model& model);

  // Room for `couplings` contact points a step, so that solve() allocates nothing up to that.
  void reserve(std::size_t couplings);

  // Solves (M + h C + h^2 K) q1 = M q0 + h (Q + sum J^T (force + C u0)) for the bodies'
  // velocities q1 = (v1, w1) at the end of the step, island by island, with the active set of
  // the couplings' unilateral and friction limits (backward Euler). Under `history.order` 2 an
  // island whose bodies all kept the same couplings in the same modes for kSettledSteps, with no
  // axis rule, no finger, no other body and the gyroscopic term neglected (a body alone, free or
  // on the floor), takes the BDF2 step instead
  // (engine/README.md, "Second order"):
  //   (M + h2 C + h2^2 K) q1 = M q^ + h2 (Q + sum J^T (force + C u0 - h/3 K u_mean)),
  //   h2 = 2h/3,  q^ = (4 q0 - q_-1) / 3,  displacement h (q_mean + 2 q1) / 3,
  // and if the solve's modes differ from the last step's, the island is solved again by backward
  // Euler (a restart: BDF2 across a change of the active set can throw a body off a new contact
  // faster than it came). `q0` holds each body's (v, w) at the start
  // (after the gyroscopic change), `wrench` the external force and torque on each body over the
  // step (gravity, fingers' window), `awake` which bodies move. Results: velocities(), mode(i)
  // and force(i) for every coupling, solved at the end of the step.
  // `axis[b]`, where `axis_active[b]`, holds a body's rotation rate about a unit axis through
  // `axis_point[b]` (m, world) at the end of the step: w1 . axis = axis_rate (a grasp rule's
  // hinge), by a multiplier that turns the body about that line.
  void solve(const Model& model, const State& state, const std::vector<Coupling>& couplings,
             const std::vector<std::uint8_t>& awake, const std::vector<Vec3>& v0,
             const std::vector<Vec3>& w0, const std::vector<Vec3>& force,
             const std::vector<Vec3>& torque, const std::vector<std::uint8_t>& axis_active,
             const std::vector<Vec3>& axis, const std::vector<Vec3>& axis_point,
             const std::vector<double>& axis_rate, const StepHistory& history, double h);

  const Vec3& velocity(int body) const { return v1_[body]; }            // m/s, world
  const Vec3& angular_velocity(int body) const { return w1_[body]; }    // rad/s, world
  CouplingMode mode(std::size_t coupling) const { return mode_[coupling]; }
  // N, world, on b: the coupling's force at the end of the step (zero when kOff).
  const Vec3& force(std::size_t coupling) const { return solved_[coupling]; }
  // Whether the body's island took the BDF2 step, and its signature (couplings and modes) now.
  bool second_order(int body) const { return second_order_[body] != 0; }
  std::uint64_t signature(int body) const { return signature_[body]; }
  // Under BDF2, the last step's displacement rates: (x0 - x_-1) / h, m/s, and its rotation
  // vector / h, rad/s (world), from BodyState's pose before the step.
  const Vec3& mean_velocity(int body) const { return v_mean_[body]; }
  const Vec3& mean_angular_velocity(int body) const { return w_mean_[body]; }

  // Most active-set rounds per island: each round changes at least one point's mode, hold ->
  // slip -> off, never back, so the set settles; the cap bounds the cost of a rare long cascade.
  static constexpr int kMaxRounds = 8;
  // Steps an island's contacts must keep unchanged before it takes BDF2: backward Euler damps
  // the transient of an arrival (a stiff spring's mode by 1 / sqrt(1 + h^2 k / m) a step, BDF2's
  // only by (4 h^2 k / m)^(-1/4)), so that a body bounced off a new contact settles into it
  // instead of overshooting out of reach of a one-sided point.
  static constexpr int kSettledSteps = 3;

 private:
  // What every island of one solve() reads: the scene, the couplings, each body's external
  // wrench and grasp rule.
  struct Inputs {
    const Model& model;
    const State& state;
    const std::vector<Coupling>& couplings;
    const std::vector<Vec3>& force;                // N, world, per body
    const std::vector<Vec3>& torque;               // N m, world, per body
    const std::vector<std::uint8_t>& axis_active;  // per body
    const std::vector<Vec3>& axis;                 // 1, world, per body
    const std::vector<Vec3>& axis_point;           // m, world, per body
    const std::vector<double>& axis_rate;          // rad/s, per body
  };

  int find(int body);
  void solve_island(const Inputs& in, double h);
  std::uint64_t island_signature(const std::vector<Coupling>& couplings) const;
  void assemble_and_solve(const Inputs& in, double h);
  // assemble_and_solve for an island of N unknowns (6: one body, no axis rule), N = 0 for any
  // size (then `n` is the size).
  template <int N>
  void assemble_and_solve_n(const Inputs& in, int n, double h);
  Vec3 relative_velocity(const State& state, const Coupling& c, const std::vector<Vec3>& v,
                         const std::vector<Vec3>& w) const;

  std::vector<int> parent_;                 // union-find over bodies joined by body points
  std::vector<int> island_of_;              // body -> island index, or -1 (asleep)
  std::vector<int> local_;                  // body -> index inside its island
  std::vector<double> matrix_;              // (7 n)^2, row-major: the island's system (6 per body, and
                                            //    a row per axis constraint), then its factor
  std::vector<double> rhs_;                 // 7 n: right side, then the solution
  std::vector<Vec3> v1_, w1_;               // per body: the solved velocities
  std::vector<CouplingMode> mode_;          // per coupling
  std::vector<Vec3> slide_;                 // 1, world, per coupling: unit direction of the sliding
                                            //    force while kSlip
  std::vector<Vec3> solved_;                // N, world, per coupling: force at the end of the step
  std::vector<Vec3> u0_;                    // m/s, world, per coupling: relative velocity at the start
  std::vector<Vec3> constant_;              // N, world, per coupling: the constant part of its force
                                            //    in this round's mode (assemble_and_solve)
  std::vector<CouplingResponse> response_;  // per coupling: its response in this round's mode
  std::vector<Vec3> start_force_;           // N, world, per coupling: `force`, less h/3 K u_mean under BDF2
  std::vector<Vec3> vq_, wq_;               // m/s, rad/s, per body: q0, or q^ under BDF2
  std::vector<Vec3> v_mean_, w_mean_;       // m/s, rad/s, per body under BDF2: the last step's
                                            //    displacement rates
  std::vector<std::uint8_t> second_order_;  // per body: its island took the BDF2 step
  std::vector<std::uint64_t> signature_;    // per body: its island's couplings and modes
  // Per body of the island: its isotropic points' g, g r and g S(r)^2 summed (N s/m, N s, N s m).
  struct IsotropicSum {
    double g = 0.0;
    Vec3 g_arm = Vec3::Zero();
    Mat3 g_arm2 = Mat3::Zero();
  };
  std::vector<IsotropicSum> iso_;
  std::vector<int> current_;                // the island being solved: its bodies, couplings
  std::vector<int> current_couplings_;
};

}  // namespace graspsim
