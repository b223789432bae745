// The implicit step's solve: every contact point a spring-damper about the step's start, the bodies
// that push on one another solved at once for their velocities at the end of the step (backward
// Euler, or BDF2 for a body alone whose contacts have settled), under an active set that keeps
// each point consistent with its limits (engine/README.md, "Integrators"):
//   (M + h C + h^2 K) q1 = M q0 + h (Q + sum J^T (f + C u0)),  q = (v, w) per body, J = [I, -S(r)].
//
// Islands are the bodies joined by points in the active set, not by every point the gather found:
// a point the step may reach (negative depth) starts off and joins two bodies only if the solve
// carries them into it. So bodies side by side at rest are islands of one, a tower is one island.
//
// The active set, per island, round by round (each round one solve):
//   - the normal side, a linear complementarity problem (a point in the set pushes, a point out of
//     it stays clear) whose matrix is positive definite while the friction modes stand: principal
//     pivoting flips every point in the wrong state at once (one held but pulling lets go, one off
//     that the solve would carry into contact is taken in: an arrival) while their count falls,
//     then only the lowest-indexed one (Murty's rule); a count that stops falling first lets held
//     points out of their friction cone slide;
//   - once it holds, friction: a held point whose force leaves its cone slides, along the way it
//     pulled; a sliding point whose friction would push it along its own sliding sticks again
//     (once a step); each change makes a new normal problem. A point leaves its cone at most
//     twice a step (then it stays held), and one taken out and in again comes back held.
//   A force within rounding of zero (of the terms that make it, or of its bodies' weight) is
//   zero: boxes touching side by side with nothing pressing them flip on noise otherwise.
// Then arrivals between islands: a point off between two islands that the end velocities would
// close joins them, and the merged island is solved again from its parts' modes.
//
// Within an island: a block-sparse elimination (block_solve.hpp): O(n) for a chain, about O(n^1.5)
// for a planar contact graph, where a dense solve is O(n^3). A body alone: its 6 x 6 by blocks.
#pragma once

#include <array>
#include <cstdint>
#include <utility>
#include <vector>

#include "graspsim/engine/block_solve.hpp"
#include "graspsim/engine/coupling.hpp"
#include "graspsim/engine/grasp_rules.hpp"
#include "graspsim/engine/math.hpp"
#include "graspsim/engine/model.hpp"
#include "graspsim/engine/state.hpp"

namespace graspsim {

// What the second-order step needs of the last one, per body.
struct StepHistory {
  int order = 1;                            // 1: backward Euler everywhere; 2: BDF2 where the history allows
  std::vector<std::uint8_t> valid;          // stepped at the last physics tick (awake since)
  std::vector<std::uint64_t> signature;     // its island's couplings and their modes at the last step
  std::vector<int> steps;                   // 1: physics steps in a row its island kept that signature
};

// One step's problem: the scene, its couplings, and per body its start, load and rule.
struct StepProblem {
  const Model& model;
  const State& state;
  const std::vector<Coupling>& couplings;
  const std::vector<std::uint8_t>& awake;   // per body: 1 when it moves this step
  const std::vector<Vec3>& v0;              // m/s, world, per body: velocity at the start
  const std::vector<Vec3>& w0;              // rad/s, world, per body: after the gyroscopic change
  const std::vector<Vec3>& force;           // N, world, per body: external (gravity, fingers' window)
  const std::vector<Vec3>& torque;          // N m, world, per body
  const std::vector<AxisRule>& rules;       // per body: a grasp rule's hinge, w1 . u = rate
  const StepHistory& history;
  double h;                                 // s: the step
};

class IslandSolve {
 public:
  explicit IslandSolve(const Model& model);

  // Room for `couplings` contact points a step, so that solve() allocates nothing up to that.
  void reserve(std::size_t couplings);

  // Solves every island of `p` (engine/README.md, "Integrators", "Second order"). Results below.
  void solve(const StepProblem& p);

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
  // The last solve's work, for the benchmark: islands solved (merges counted again), rounds.
  int islands_solved() const { return islands_solved_; }
  int rounds() const { return rounds_; }

  // Most active-set rounds per island: principal pivoting ends in a few rounds (one at rest, two
  // or three where points arrive or let go), and a sliding point sticks again at most once a
  // step; the cap bounds the cost of a long cascade, whose last round's set is taken.
  static constexpr int kMaxRounds = 32;
  // Most passes that merge islands a point between them would join.
  static constexpr int kMaxMerges = 16;
  // Steps an island's contacts must keep unchanged before it takes BDF2: backward Euler damps
  // the transient of an arrival (a stiff spring's mode by 1 / sqrt(1 + h^2 k / m) a step, BDF2's
  // only by (4 h^2 k / m)^(-1/4)), so that a body bounced off a new contact settles into it
  // instead of overshooting out of reach of a one-sided point.
  static constexpr int kSettledSteps = 3;

  // Islands of this many bodies or more keep their ordering and factors from round to round and
  // step to step (IslandCache), up to kCachedIslands of them; smaller ones factor afresh each
  // round (their factorization costs about what a refinement would).
  static constexpr std::size_t kCacheFrom = 8;
  static constexpr int kCachedIslands = 4;
  static constexpr int kRefinements = 4;   // most refinement passes on kept factors


 private:
  // A large island's structure, its system as assembled, and the factors of an earlier system of
  // the same structure (the last round's or the last step's).
  struct IslandCache {
    int root = -1;                                 // the island's lowest body (-1: unused)
    std::uint64_t used = 0;                        // when it was last used (clock_)
    std::vector<int> bodies, sizes;
    std::vector<std::pair<int, int>> edges;        // local body indices, sorted
    BlockSparseSolver system, factors;
  };
  void structure(const StepProblem& p);
  bool solve_blocks(const StepProblem& p, double h);
  bool solve_cached(const StepProblem& p, double h);
  void form_islands(const StepProblem& p);
  void solve_island(const StepProblem& p, int island);
  bool try_second_order(const StepProblem& p, std::uint64_t last);
  void run_rounds(const StepProblem& p, double h);
  void forces_at_end(const StepProblem& p);
  void wrong_normal(const StepProblem& p, double h, std::vector<int>& wrong) const;
  bool leave_cones(const StepProblem& p);
  bool stick_again(const StepProblem& p);
  bool arrives(const Coupling& c, int i, const Vec3& u1, double h) const;
  bool merge_arrivals(const StepProblem& p);
  void assemble_and_solve(const StepProblem& p, double h);
  template <class Sink>   // BlockSink or DenseSink (island_solve.cpp)
  void assemble(const StepProblem& p, double h, Sink& sink);
  std::uint64_t island_signature(const std::vector<Coupling>& couplings) const;
  Vec3 relative_velocity(const StepProblem& p, const Coupling& c, const std::vector<Vec3>& v,
                         const std::vector<Vec3>& w) const;
  int find(int body);

  // Per body.
  std::vector<int> parent_;                 // union-find over bodies joined by points in the set
  std::vector<int> island_of_;              // body -> island, -1 when asleep
  std::vector<int> local_;                  // body -> index inside its island
  std::vector<std::uint8_t> dirty_;         // per island: to be solved (again)
  std::vector<Vec3> v1_, w1_;               // the solved velocities
  std::vector<Vec3> vq_, wq_;               // m/s, rad/s: q0, or q^ under BDF2
  std::vector<Vec3> v_mean_, w_mean_;       // m/s, rad/s under BDF2: the last step's displacement rates
  std::vector<std::uint8_t> second_order_;  // its island took the BDF2 step
  std::vector<std::uint64_t> signature_;    // its island's couplings and modes
  // Per coupling.
  std::vector<CouplingMode> mode_;
  std::vector<std::uint8_t> reversed_;      // stuck again after sliding this step (once a step)
  std::vector<Vec3> slide_;                 // 1, world: unit direction of the sliding force while kSlip
  std::vector<Vec3> solved_;                // N, world: force at the end of the step
  std::vector<Vec3> u0_;                    // m/s, world: relative velocity at the start
  std::vector<Vec3> constant_;              // N, world: the constant part of its force in this round's mode
  std::vector<CouplingResponse> response_;  // its response in this round's mode
  std::vector<double> least_force_;         // N: a force below this is zero to rounding
  std::vector<std::uint8_t> cone_exits_;    // times the point left its friction cone this step
  std::vector<Vec3> start_force_;           // N, world: `force`, less h/3 K u_mean under BDF2
  std::vector<int> coupling_island_;        // its island (-1: between islands, or none awake)
  // Islands, as ranges into the two lists below (counting sort by island).
  std::vector<int> body_begin_, coupling_begin_;
  std::vector<int> island_bodies_, island_couplings_;
  std::vector<int> between_;                // couplings off between two islands: arrivals to check
  std::vector<int> wrong_;                  // the island's points in the wrong normal state
  // The island being solved: its bodies and couplings.
  std::vector<int> current_, current_couplings_;
  std::vector<int> sizes_;                  // unknowns per body of the island (6, 7 with a rule)
  BlockSparseSolver blocks_;                // a small island's, factored afresh each round
  std::array<IslandCache, kCachedIslands> caches_;
  IslandCache* cache_ = nullptr;            // the island being solved's, or none
  std::uint64_t clock_ = 0;
  std::vector<std::pair<int, int>> edges_;  // the island's pairs of bodies with points
  std::vector<std::pair<int, int>> merged_edges_;   // edges_ with the cached structure's
  std::vector<double> b_, x_, r_;           // a cached island's right side, solution, residual
  std::vector<double> dense_, dense_rhs_;   // a dense copy when the blocks fail
  std::vector<int> offsets_;                // per body of the island: its first unknown
  std::vector<CouplingMode> modes_before_;  // the island's modes before a BDF2 attempt
  std::vector<std::uint8_t> arrived_body_;  // per body: a point between islands arrived on it
  // Per body of the island: its isotropic points' g, g r and g S(r)^2 summed (N s/m, N s, N s m).
  struct IsotropicSum {
    double g = 0.0;
    Vec3 g_arm = Vec3::Zero();
    Mat3 g_arm2 = Mat3::Zero();
  };
  std::vector<IsotropicSum> iso_;
  int islands_ = 0;
  int islands_solved_ = 0, rounds_ = 0;
};

}  // namespace graspsim
