// The implicit step's solve (island_solve.hpp): islands of bodies joined by points in the active
// set, each solved by blocks, round by round, then merged where a point between them arrives.
#include "graspsim/engine/island_solve.hpp"

#include <algorithm>
#include <cmath>
#include <iterator>

#include "graspsim/engine/dense_solve.hpp"

namespace graspsim {
namespace {

constexpr std::uint8_t kRestuck = 1;   // a sliding point stuck again this step (once a step)
constexpr std::uint8_t kMaxConeExits = 2;   // times a point may leave its friction cone in a step

// Two points apart by less than this are touching (m): a scene built touching has its depths
// zero to rounding, 1e-17 m either way for positions of order one metre.
constexpr double kTouching = 1e-9;
// A normal force within this fraction of the terms that make it is zero to rounding (1): it
// neither lets a held point go nor takes an arriving point in. Bodies stacked exactly touching and
// falling together have forces of 1e-12 N between them from terms of 1e3 N; a point let go or
// taken in on that noise would flicker from round to round.
constexpr double kForceRounding = 1e-9;
// And a force below this fraction of its bodies' weight (on Earth, whatever the scene's gravity)
// is zero too (1): boxes side by side touching, with nothing pressing them together, have normal
// forces of 1e-17 N from terms of the same size, which the relative test alone takes for a sign
// and flips from round to round. Its impulse over a step changes their velocities by a billionth
// of what gravity adds in that step.
constexpr double kWeightRounding = 1e-9;
constexpr double kStandardGravity = 9.80665;   // m/s^2

// A block of the island's system: where it starts and its row stride.
struct BlockRef {
  double* p;
  int stride;
  double& operator()(int r, int c) const { return p[r * stride + c]; }
};

// G = (h + lead) K + C of a coupling in its mode (3x3, world): the force's change per unit of
// relative velocity at the end of the step. While sliding along unit t (tangential, the way the
// held spring pulled) the tangential force is mu times the normal one: G = g_n (n + mu t) n^T.
// Kept in the shape that makes its products cheap (CouplingResponse).
CouplingResponse response_of(const Coupling& c, CouplingMode mode, const Vec3& slide, double h) {
  CouplingResponse r;
  const double reach = h + c.lead;   // s: the time the springs see the end velocity over
  const double g_n = reach * c.k_n + c.c_n;
  const double g_t = reach * c.k_t + c.c_t;
  if (mode == CouplingMode::kSlip) {
    r.shape = CouplingResponse::Shape::kRankOne;
    r.a = g_n * (c.normal + c.mu * slide);
    r.b = c.normal;
  } else if (g_n == g_t) {
    r.shape = CouplingResponse::Shape::kIsotropic;
    r.g = g_n;
  } else {
    r.shape = CouplingResponse::Shape::kGeneral;
    const Mat3 nn = c.normal * c.normal.transpose();
    r.full = g_n * nn + g_t * (Mat3::Identity() - nn);
  }
  return r;
}

// The constant part of the force, force + (C + lead K) u0 (`force`: the coupling's, less h/3 K
// u_mean under BDF2), in its mode; while sliding along t the tangential part is mu times the
// normal part, plus the viscous force.
Vec3 constant_force(const Coupling& c, const Vec3& force, CouplingMode mode, const Vec3& u0, const Vec3& slide) {
  const Vec3& n = c.normal;
  const double normal = n.dot(force) + (c.c_n + c.lead * c.k_n) * n.dot(u0);   // N
  if (mode == CouplingMode::kSlip) return normal * (n + c.mu * slide) + c.viscous * slide;
  const Vec3 tangential = force - n.dot(force) * n + (c.c_t + c.lead * c.k_t) * (u0 - n.dot(u0) * n);
  return normal * n + tangential;
}

// Adds s * J_x^T G J_y into the 6x6 block `a`, J = [I, -S(r)]:
//   J_x^T G J_y = [[G, -G S_y], [S_x G, -S_x G S_y]].
// Two shapes of G take a shortcut (the same matrix, fewer products): isotropic, G = g I, where
// S_x S_y = y x^T - (x . y) I; and rank one, G = a b^T, where J_x^T G J_y = (J_x^T a)(J_y^T b)^T
// and J^T v = (v, r x v).
void add_block(const BlockRef& a, const CouplingResponse& g, const Vec3& r_x, const Vec3& r_y, double s) {
  const auto add3 = [&a](int row, int col, const Mat3& m) {
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) a(row + i, col + j) += m(i, j);
  };
  if (g.shape == CouplingResponse::Shape::kIsotropic) {
    const double sg = s * g.g;
    Mat3 sxsy = r_y * r_x.transpose();
    sxsy.diagonal().array() -= r_x.dot(r_y);
    for (int i = 0; i < 3; ++i) a(i, i) += sg;
    add3(0, 3, -sg * skew(r_y));
    add3(3, 0, sg * skew(r_x));
    add3(3, 3, -sg * sxsy);
    return;
  }
  if (g.shape == CouplingResponse::Shape::kRankOne) {
    Eigen::Matrix<double, 6, 1> ja, jb;
    ja << g.a, r_x.cross(g.a);
    jb << g.b, r_y.cross(g.b);
    ja *= s;
    for (int i = 0; i < 6; ++i)
      for (int j = 0; j < 6; ++j) a(i, j) += ja[i] * jb[j];
    return;
  }
  const Mat3 sx = skew(r_x);
  const Mat3 gs = g.full * skew(r_y);
  add3(0, 0, s * g.full);
  add3(0, 3, -s * gs);
  add3(3, 0, s * (sx * g.full));
  add3(3, 3, -s * (sx * gs));
}

}  // namespace

namespace {

// Where an island's system goes (IslandSolve::assemble's sink, chosen at compile time: the one
// body's 6 x 6 system is assembled at every step of every resting body): the block solver's
// storage, or one dense row-major matrix. Local body indices.
class BlockSink {
 public:
  explicit BlockSink(BlockSparseSolver& s) : s_(s) {}
  BlockRef diagonal(int i) { return {s_.diagonal(i), s_.size(i)}; }
  BlockRef block(int i, int j) { return {s_.block(i, j), s_.size(j)}; }
  double* rhs(int i) { return s_.rhs(i); }

 private:
  BlockSparseSolver& s_;
};

class DenseSink {
 public:
  DenseSink(double* m, double* r, int n, const std::vector<int>& offset) : m_(m), r_(r), n_(n), offset_(offset) {}
  BlockRef diagonal(int i) { return block(i, i); }
  BlockRef block(int i, int j) { return {m_ + offset_[i] * n_ + offset_[j], n_}; }
  double* rhs(int i) { return r_ + offset_[i]; }

 private:
  double* m_;
  double* r_;
  int n_;
  const std::vector<int>& offset_;
};

}  // namespace

IslandSolve::IslandSolve(const Model& model) {
  const std::size_t n = model.bodies.size();
  parent_.resize(n);
  island_of_.resize(n);
  local_.resize(n);
  v1_.resize(n);
  w1_.resize(n);
  vq_.resize(n);
  wq_.resize(n);
  v_mean_.resize(n);
  w_mean_.resize(n);
  second_order_.resize(n);
  signature_.resize(n);
  iso_.resize(n);
  current_.reserve(n);
  sizes_.reserve(n);
  island_bodies_.resize(n);
  body_begin_.reserve(n + 1);
  coupling_begin_.reserve(n + 1);
  dirty_.reserve(n);
  arrived_body_.reserve(n);
  offsets_.reserve(n);
  blocks_.reserve(static_cast<int>(n), 12);   // a box in a pile touches about a dozen others
  b_.reserve(7 * n);
  x_.reserve(7 * n);
  r_.reserve(7 * n);
}

void IslandSolve::reserve(std::size_t couplings) {
  mode_.reserve(couplings);
  reversed_.reserve(couplings);
  slide_.reserve(couplings);
  solved_.reserve(couplings);
  u0_.reserve(couplings);
  constant_.reserve(couplings);
  response_.reserve(couplings);
  start_force_.reserve(couplings);
  least_force_.reserve(couplings);
  cone_exits_.reserve(couplings);
  coupling_island_.reserve(couplings);
  island_couplings_.reserve(couplings);
  current_couplings_.reserve(couplings);
  between_.reserve(couplings);
  wrong_.reserve(couplings);
  modes_before_.reserve(couplings);
  edges_.reserve(couplings);
  merged_edges_.reserve(couplings);
}

int IslandSolve::find(int body) {
  while (parent_[body] != body) body = parent_[body] = parent_[parent_[body]];
  return body;
}

Vec3 IslandSolve::relative_velocity(const StepProblem& p, const Coupling& c, const std::vector<Vec3>& v,
                                    const std::vector<Vec3>& w) const {
  const auto point_velocity = [&](int body) -> Vec3 {
    if (body < 0 || !p.awake[body]) return Vec3::Zero();
    return v[body] + w[body].cross(c.point - p.state.bodies[body].position);
  };
  return point_velocity(c.b) - (c.a < 0 ? c.world_velocity : point_velocity(c.a));
}

void IslandSolve::solve(const StepProblem& p) {
  const std::vector<Coupling>& couplings = p.couplings;
  const int nb = static_cast<int>(p.model.bodies.size());
  const std::size_t nc = couplings.size();
  mode_.resize(nc);
  reversed_.assign(nc, 0);
  cone_exits_.assign(nc, 0);
  slide_.assign(nc, Vec3::Zero());
  solved_.assign(nc, Vec3::Zero());
  u0_.resize(nc);
  start_force_.resize(nc);
  least_force_.resize(nc);
  constant_.resize(nc);
  response_.resize(nc);
  for (int b = 0; b < nb; ++b) {
    v1_[b] = p.v0[b];
    w1_[b] = p.w0[b];
    second_order_[b] = 0;
    signature_[b] = 0;
  }
  for (std::size_t i = 0; i < nc; ++i) {
    const Coupling& c = couplings[i];
    u0_[i] = relative_velocity(p, c, p.v0, p.w0);
    start_force_[i] = c.force;
    const double mass = (c.a >= 0 ? p.model.bodies[c.a].mass : 0.0) + (c.b >= 0 ? p.model.bodies[c.b].mass : 0.0);
    least_force_[i] = kWeightRounding * kStandardGravity * mass;
    // A one-sided point not yet touching (a point the step may reach) starts off: it takes part
    // only if the solve carries the bodies into it.
    mode_[i] = (c.mu >= 0.0 && !(c.depth > -kTouching)) ? CouplingMode::kOff : CouplingMode::kHold;
  }
  islands_solved_ = rounds_ = 0;
  form_islands(p);
  dirty_.assign(islands_, 1);
  for (int pass = 0; pass <= kMaxMerges; ++pass) {
    for (int i = 0; i < islands_; ++i) {
      if (dirty_[i]) solve_island(p, i);
    }
    if (pass == kMaxMerges || !merge_arrivals(p)) break;
  }
  for (std::size_t i = 0; i < nc; ++i) {
    if (mode_[i] == CouplingMode::kOff) solved_[i].setZero();
  }
}

// Islands: awake bodies joined by points in the active set (a sleeping body stays put, as the
// world does), numbered by their lowest body; bodies and couplings listed island by island, in
// index order. A point off between two islands waits in between_ for an arrival.
void IslandSolve::form_islands(const StepProblem& p) {
  const std::vector<Coupling>& couplings = p.couplings;
  const int nb = static_cast<int>(p.model.bodies.size());
  for (int b = 0; b < nb; ++b) parent_[b] = b;
  for (std::size_t i = 0; i < couplings.size(); ++i) {
    const Coupling& c = couplings[i];
    if (mode_[i] == CouplingMode::kOff || c.a < 0 || c.b < 0 || !p.awake[c.a] || !p.awake[c.b]) continue;
    const int ra = find(c.a), rb = find(c.b);
    if (ra != rb) parent_[std::max(ra, rb)] = std::min(ra, rb);
  }
  islands_ = 0;
  body_begin_.assign(1, 0);
  for (int b = 0; b < nb; ++b) {
    island_of_[b] = -1;
    if (!p.awake[b]) continue;
    const int root = find(b);
    if (root == b) {
      island_of_[b] = islands_++;
      body_begin_.push_back(0);
    } else {
      island_of_[b] = island_of_[root];
    }
    ++body_begin_[island_of_[b] + 1];
  }
  for (int i = 0; i < islands_; ++i) body_begin_[i + 1] += body_begin_[i];
  std::vector<int>& fill = current_;   // scratch: next slot per island
  fill.assign(body_begin_.begin(), body_begin_.end() - 1);
  for (int b = 0; b < nb; ++b) {
    if (island_of_[b] >= 0) island_bodies_[fill[island_of_[b]]++] = b;
  }
  coupling_island_.resize(couplings.size());
  coupling_begin_.assign(islands_ + 1, 0);
  between_.clear();
  for (std::size_t i = 0; i < couplings.size(); ++i) {
    const Coupling& c = couplings[i];
    const int ib = c.b >= 0 ? island_of_[c.b] : -1, ia = c.a >= 0 ? island_of_[c.a] : -1;
    int island = ib >= 0 ? ib : ia;
    if (ia >= 0 && ib >= 0 && ia != ib) {   // off, between two islands
      between_.push_back(static_cast<int>(i));
      island = -1;
    }
    coupling_island_[i] = island;
    if (island >= 0) ++coupling_begin_[island + 1];
  }
  for (int i = 0; i < islands_; ++i) coupling_begin_[i + 1] += coupling_begin_[i];
  island_couplings_.resize(static_cast<std::size_t>(coupling_begin_[islands_]));
  fill.assign(coupling_begin_.begin(), coupling_begin_.end() - 1);
  for (std::size_t i = 0; i < couplings.size(); ++i) {
    if (coupling_island_[i] >= 0) island_couplings_[fill[coupling_island_[i]]++] = static_cast<int>(i);
  }
}

// A point off between two islands that the islands' end velocities would carry into contact joins
// them (once a step). Returns whether any did: the islands are then formed again, and those that
// grew are solved again, from their parts' modes.
bool IslandSolve::merge_arrivals(const StepProblem& p) {
  bool merged = false;
  std::fill(dirty_.begin(), dirty_.end(), 0);
  std::vector<std::uint8_t>& touched = arrived_body_;
  touched.assign(p.model.bodies.size(), 0);
  for (int i : between_) {
    const Coupling& c = p.couplings[i];
    if (!arrives(c, i, relative_velocity(p, c, v1_, w1_), p.h)) continue;
    mode_[i] = CouplingMode::kHold;
    touched[c.a] = touched[c.b] = 1;
    merged = true;
  }
  if (!merged) return false;
  form_islands(p);
  dirty_.assign(islands_, 0);
  for (int b = 0; b < static_cast<int>(p.model.bodies.size()); ++b) {
    if (island_of_[b] >= 0 && touched[b]) dirty_[island_of_[b]] = 1;
  }
  return true;
}

void IslandSolve::solve_island(const StepProblem& p, int island) {
  ++islands_solved_;
  current_.assign(island_bodies_.begin() + body_begin_[island], island_bodies_.begin() + body_begin_[island + 1]);
  current_couplings_.assign(island_couplings_.begin() + coupling_begin_[island],
                            island_couplings_.begin() + coupling_begin_[island + 1]);
  sizes_.clear();
  for (int b : current_) {
    local_[b] = static_cast<int>(sizes_.size());
    sizes_.push_back(p.rules[b].active ? 7 : 6);
  }
  if (current_.size() > 1 || sizes_[0] != 6) structure(p);   // the island's, for every round
  // BDF2 where every body of the island stepped in this same island for kSettledSteps, with no
  // axis rule (a rule sets the rate about its axis outright, a jump the history cannot carry), no
  // finger (its force is the fast loops' mean over the window, measured while its god-object slid
  // on the surface: its stretch over a step is not the bodies' displacement, which is what BDF2's
  // history term takes it to be), no point between two bodies (BDF2's lighter damping of an
  // arrival's bounce let lift_and_place's box rock ten times faster than backward Euler) and the
  // gyroscopic term neglected (its step is backward Euler's one Newton step; BDF2 on the world
  // angular velocity would drift |L| by 21 % in spin_flip).
  const std::uint64_t last = p.history.order == 2 && p.model.gyroscopic == Gyroscopic::kNeglect
                                 ? p.history.signature[current_.front()]
                                 : 0;
  bool bdf2 = last != 0 && try_second_order(p, last);
  if (!bdf2) {
    for (int b : current_) {
      vq_[b] = p.v0[b];
      wq_[b] = p.w0[b];
    }
    for (int i : current_couplings_) start_force_[i] = p.couplings[i].force;
    run_rounds(p, p.h);
  }
  const std::uint64_t signature = bdf2 ? last : island_signature(p.couplings);
  for (int b : current_) {
    second_order_[b] = bdf2 ? 1 : 0;
    signature_[b] = signature;
  }
}

// The BDF2 step of an island that qualifies; false (modes restored) when it does not, or when
// its solve changed the island's modes (a restart: BDF2 across a change of the active set can
// throw a body off a new contact faster than it came).
bool IslandSolve::try_second_order(const StepProblem& p, std::uint64_t last) {
  for (int i : current_couplings_) {
    if (p.couplings[i].source != Coupling::Source::kFloor) return false;
  }
  for (int b : current_) {
    if (!p.history.valid[b] || p.rules[b].active || p.history.signature[b] != last ||
        p.history.steps[b] < kSettledSteps)
      return false;
  }
  const double h = p.h, third = 1.0 / 3.0;
  for (int b : current_) {
    const BodyState& bs = p.state.bodies[b];
    v_mean_[b] = (bs.position - bs.position_before_step) / h;
    const Eigen::AngleAxisd turn(bs.rotation * bs.rotation_before_step.transpose());
    w_mean_[b] = (turn.angle() / h) * turn.axis();
    vq_[b] = third * (4.0 * p.v0[b] - bs.velocity_before_step);
    wq_[b] = third * (4.0 * p.w0[b] - bs.angular_velocity_before_step);
  }
  // The springs' displacement over the step is h (u_mean + 2 u1) / 3: the part already known
  // joins the force at the start (in a sliding point only its normal part counts).
  std::vector<CouplingMode>& start_modes = modes_before_;
  start_modes.clear();
  for (int i : current_couplings_) {
    const Coupling& c = p.couplings[i];
    const Vec3 u = relative_velocity(p, c, v_mean_, w_mean_);
    const double u_n = c.normal.dot(u);
    start_force_[i] = c.force - (third * h) * (c.k_n * u_n * c.normal + c.k_t * (u - u_n * c.normal));
    start_modes.push_back(mode_[i]);
  }
  run_rounds(p, 2.0 * third * h);
  if (island_signature(p.couplings) == last) return true;
  for (std::size_t k = 0; k < current_couplings_.size(); ++k) {
    const int i = current_couplings_[k];
    mode_[i] = start_modes[k];
    cone_exits_[i] = 0;
    reversed_[i] = 0;
    slide_[i].setZero();
    solved_[i].setZero();
  }
  return false;
}

// Rounds: solve, then change modes where the solution breaks a limit (island_solve.hpp). `h` is the
// step's implicit coefficient: the step for backward Euler, 2/3 of it for BDF2.
//
// The normal side first: which points push is a linear complementarity problem (a point in the set
// pushes, a point out of it stays clear), whose matrix is positive definite while no point changes
// its friction (M + h (h K + C) projected on the normals): it has one solution, which principal
// pivoting finds (Judice and Pires): every point in the wrong state changes at once while that
// makes the count of wrong points fall, and after three rounds that do not, only the one of lowest
// index (Murty's rule). When the count has not fallen for two rounds, the friction modes are what
// is wrong first: a box sliding down a slope at 1.6 m/s with its four points held is stopped dead
// in the solve and pitches onto its front edge, whose points let go and come back round after round
// (it ended the step stuck, spinning at 7 rad/s). So held points whose force leaves the cone slide
// then, and the pivoting starts again. Once the normal side holds, the same for every held point;
// last, a sliding point whose friction would push it along its own sliding sticks again (once a
// step), which makes a new problem.
// A point the normal side takes out and in again comes back held (a sliding direction from an
// earlier solve may push it along its motion, and took a pyramid's landing boxes to 10^4 m/s), and
// leaves its cone at most kMaxConeExits times a step, after which it stays held (a spring and
// damper: passive, if stickier than Coulomb for the rest of the step): the rounds end. With no
// such limit, friction checked before the normal side flipped the points of a pile of boxes from
// sliding to off to held to sliding, round after round, to the cap, and left modes no solve had
// checked (2300 J gained at 500 Hz).
void IslandSolve::run_rounds(const StepProblem& p, double h) {
  std::size_t fewest = static_cast<std::size_t>(-1);
  int stalled = 0;
  for (int round = 0; round < kMaxRounds; ++round) {
    ++rounds_;
    assemble_and_solve(p, h);
    forces_at_end(p);
    wrong_normal(p, h, wrong_);
    if (!wrong_.empty()) {
      stalled = wrong_.size() < fewest ? 0 : stalled + 1;
      fewest = std::min(fewest, wrong_.size());
      if (stalled >= 2 && leave_cones(p)) {
        fewest = static_cast<std::size_t>(-1);
        stalled = 0;
        continue;
      }
      if (stalled >= 3) wrong_.resize(1);   // Murty: the lowest index alone
      for (int i : wrong_) {
        mode_[i] = mode_[i] == CouplingMode::kOff ? CouplingMode::kHold : CouplingMode::kOff;
        if (mode_[i] == CouplingMode::kOff) solved_[i].setZero();
      }
      continue;
    }
    if (leave_cones(p)) {
      fewest = static_cast<std::size_t>(-1);
      stalled = 0;
      continue;
    }
    if (!stick_again(p)) break;
    fewest = static_cast<std::size_t>(-1);
    stalled = 0;
  }
}

// Each point in the set: its force at the end velocities.
void IslandSolve::forces_at_end(const StepProblem& p) {
  for (int i : current_couplings_) {
    if (mode_[i] == CouplingMode::kOff) continue;
    solved_[i] = constant_[i] - response_[i].times(relative_velocity(p, p.couplings[i], v1_, w1_));
  }
}

// The one-sided points in the wrong normal state, by index: in the set but pulling, or out of it
// but carried into contact (held, it would push), each beyond rounding.
void IslandSolve::wrong_normal(const StepProblem& p, double h, std::vector<int>& wrong) const {
  wrong.clear();
  for (int i : current_couplings_) {
    const Coupling& c = p.couplings[i];
    if (c.mu < 0.0) continue;
    if (mode_[i] == CouplingMode::kOff) {
      if (arrives(c, i, relative_velocity(p, c, v1_, w1_), h)) wrong.push_back(i);
      continue;
    }
    const double f_n = c.normal.dot(solved_[i]);
    const double scale = std::abs(c.normal.dot(constant_[i])) + std::abs(c.normal.dot(solved_[i] - constant_[i]));
    if (f_n < -(kForceRounding * scale + least_force_[i])) wrong.push_back(i);
  }
}

// Held points whose force leaves their friction cone (a pulling one always does, beyond rounding)
// slide, the way they pulled. Returns whether one did.
bool IslandSolve::leave_cones(const StepProblem& p) {
  bool changed = false;
  for (int i : current_couplings_) {
    const Coupling& c = p.couplings[i];
    if (c.mu < 0.0 || mode_[i] != CouplingMode::kHold || cone_exits_[i] >= kMaxConeExits) continue;
    const double f_n = c.normal.dot(solved_[i]);
    const Vec3 f_t = solved_[i] - f_n * c.normal;
    const double f_t_norm = f_t.norm();
    if (f_t_norm > c.mu * std::max(0.0, f_n) + c.viscous + least_force_[i]) {
      mode_[i] = CouplingMode::kSlip;
      ++cone_exits_[i];
      slide_[i] = f_t / f_t_norm;
      changed = true;
    }
  }
  return changed;
}

// Sliding points whose friction would push them along their own sliding stop: held again, once a
// step. Returns whether one did.
bool IslandSolve::stick_again(const StepProblem& p) {
  bool changed = false;
  for (int i : current_couplings_) {
    const Coupling& c = p.couplings[i];
    if (c.mu < 0.0 || mode_[i] != CouplingMode::kSlip || (reversed_[i] & kRestuck)) continue;
    const Vec3 u1 = relative_velocity(p, c, v1_, w1_);
    if (slide_[i].dot(u1 - c.normal.dot(u1) * c.normal) > 0.0) {
      mode_[i] = CouplingMode::kHold;
      reversed_[i] |= kRestuck;
      changed = true;
    }
  }
  return changed;
}

// Whether point i, off, would push at the end of the step if it were held: its normal force
// n . (force + (C + lead K) u0) - g_n n . u1 (g_n = (h + lead) k_n + c_n) beyond rounding.
bool IslandSolve::arrives(const Coupling& c, int i, const Vec3& u1, double h) const {
  const double g_n = (h + c.lead) * c.k_n + c.c_n;
  const double start = c.normal.dot(start_force_[i]) + (c.c_n + c.lead * c.k_n) * c.normal.dot(u0_[i]);
  const double change = g_n * c.normal.dot(u1);
  return start - change > kForceRounding * (std::abs(start) + std::abs(change)) + least_force_[i];
}

// A hash of the island's bodies and its couplings' identities, whether each pushed at the start
// of the step, and their modes: equal from one step to the next only while the same points act on
// the same bodies in the same way. (A point the step reaches is a coupling before the body
// arrives; its arrival is the step its force starts to push.) Word by word, FNV-1a's multiply
// with an xor-shift after it, so that every bit of a word reaches the high and the low bits.
std::uint64_t IslandSolve::island_signature(const std::vector<Coupling>& couplings) const {
  std::uint64_t hash = 14695981039346656037ull;
  const auto mix = [&hash](std::uint64_t word) {
    hash = (hash ^ word) * 1099511628211ull;
    hash ^= hash >> 29;
  };
  const auto low = [](int value) { return static_cast<std::uint64_t>(static_cast<std::uint32_t>(value)); };
  for (int b : current_) mix(low(b));
  for (int i : current_couplings_) {
    const Coupling& c = couplings[i];
    const std::uint64_t pushed = c.normal.dot(c.force) > 0.0 ? 1 : 0;
    mix(static_cast<std::uint64_t>(c.source) | static_cast<std::uint64_t>(mode_[i]) << 8 | pushed << 16 | low(c.slot) << 32);
    mix(low(c.a) | low(c.b) << 32);
  }
  return hash == 0 ? 1 : hash;   // 0 means no history
}

// The island's structure: its bodies' unknowns and the pairs of them with points between them.
// A large island's is compared with the one its cache last held: the same, and its ordering and
// last factors are kept.
void IslandSolve::structure(const StepProblem& p) {
  edges_.clear();
  for (int i : current_couplings_) {
    const Coupling& c = p.couplings[i];
    if (c.a < 0 || c.b < 0 || !p.awake[c.a] || !p.awake[c.b]) continue;
    edges_.emplace_back(std::min(local_[c.a], local_[c.b]), std::max(local_[c.a], local_[c.b]));
  }
  std::sort(edges_.begin(), edges_.end());
  edges_.erase(std::unique(edges_.begin(), edges_.end()), edges_.end());
  cache_ = nullptr;
  if (current_.size() >= kCacheFrom) {
    ++clock_;
    IslandCache* slot = &caches_[0];
    for (IslandCache& c : caches_) {   // this island's, else the least recently used
      if (c.root == current_.front()) {
        slot = &c;
        break;
      }
      if (c.used < slot->used) slot = &c;
    }
    cache_ = slot;
    slot->used = clock_;
    const bool same_bodies = slot->root == current_.front() && slot->bodies == current_ && slot->sizes == sizes_;
    if (same_bodies && std::includes(slot->edges.begin(), slot->edges.end(), edges_.begin(), edges_.end())) return;
    if (same_bodies && slot->edges.size() < 2 * edges_.size()) {
      // Pairs of bodies that touch at a corner come and go from step to step: the structure keeps
      // the pairs it had as well (their blocks stay zero while they have no point), so that one
      // analysis serves while the island keeps its bodies.
      merged_edges_.clear();
      std::set_union(slot->edges.begin(), slot->edges.end(), edges_.begin(), edges_.end(), std::back_inserter(merged_edges_));
      edges_.swap(merged_edges_);
    }
    slot->root = current_.front();
    slot->bodies.assign(current_.begin(), current_.end());
    slot->sizes.assign(sizes_.begin(), sizes_.end());
    slot->edges.assign(edges_.begin(), edges_.end());
    for (BlockSparseSolver* s : {&slot->system, &slot->factors}) {
      s->reset(sizes_);
      for (const auto& [i, j] : edges_) s->add_edge(i, j);
      s->analyse();
    }
    return;
  }
  blocks_.reset(sizes_);
  for (const auto& [i, j] : edges_) blocks_.add_edge(i, j);
  blocks_.analyse();
}

// The island's system in this round's modes, solved into (v1_, w1_): a body alone by its 6 x 6
// blocks; a large island by its kept factors and refinement when they still fit (refine); else by
// the block-sparse elimination, or a dense one if a pivot block fails.
void IslandSolve::assemble_and_solve(const StepProblem& p, double h) {
  if (current_.size() == 1 && sizes_[0] == 6) {
    double m[36], r[6];
    std::fill(m, m + 36, 0.0);
    std::fill(r, r + 6, 0.0);
    offsets_.assign(1, 0);
    DenseSink sink(m, r, 6, offsets_);
    assemble(p, h, sink);
    dense::solve_one_body(m, r);
    v1_[current_[0]] = Vec3(r[0], r[1], r[2]);
    w1_[current_[0]] = Vec3(r[3], r[4], r[5]);
    return;
  }
  offsets_.assign(current_.size(), 0);
  int n = 0;
  for (std::size_t k = 0; k < current_.size(); ++k) {
    offsets_[k] = n;
    n += sizes_[k];
  }
  const double* x = nullptr;
  if (cache_ != nullptr ? solve_cached(p, h) : solve_blocks(p, h)) {
    for (std::size_t k = 0; k < current_.size(); ++k) {
      x = cache_ != nullptr ? x_.data() + offsets_[k] : blocks_.rhs(static_cast<int>(k));
      v1_[current_[k]] = Vec3(x[0], x[1], x[2]);
      w1_[current_[k]] = Vec3(x[3], x[4], x[5]);
    }
    return;
  }
  dense_.assign(static_cast<std::size_t>(n) * n, 0.0);
  dense_rhs_.assign(static_cast<std::size_t>(n), 0.0);
  DenseSink dense(dense_.data(), dense_rhs_.data(), n, offsets_);
  assemble(p, h, dense);
  dense::lu_solve(dense_.data(), dense_rhs_.data(), n);
  for (std::size_t k = 0; k < current_.size(); ++k) {
    x = dense_rhs_.data() + offsets_[k];
    v1_[current_[k]] = Vec3(x[0], x[1], x[2]);
    w1_[current_[k]] = Vec3(x[3], x[4], x[5]);
  }
}

bool IslandSolve::solve_blocks(const StepProblem& p, double h) {
  blocks_.clear();
  BlockSink sink(blocks_);
  assemble(p, h, sink);
  return blocks_.solve();
}

// A large island: assembled into its cache's system; solved by the factors the cache kept (from an
// earlier round or step, of the same structure) with iterative refinement, x += F^-1 (b - A x),
// while that converges to the tolerance of a direct solve: the correction under 1e-12 of the
// velocities plus 1e-10 of what gravity adds in a step. (A backward-stable elimination is good to
// about cond(A) eps of the momenta it balances: bodies at rest on 400 boxes side by side come out
// of a direct solve at 2e-13 m/s, with the gravity step's 2e-2 m/s balanced against the contacts,
// and refinement stalls at 5e-14 to 8e-14 m/s, under the 2e-12 m/s this allows at 500 Hz.) A step whose system has moved too far from the factors (a body
// turned, a point began to slide) takes them anew. At rest this is two substitutions and a product
// with the matrix, O(stored blocks), where a factorization costs O(n^1.5) for a planar island.
bool IslandSolve::solve_cached(const StepProblem& p, double h) {
  IslandCache& c = *cache_;
  c.system.clear();
  BlockSink sink(c.system);
  assemble(p, h, sink);
  const std::size_t n = c.system.unknowns();
  b_.assign(c.system.rhs(0), c.system.rhs(0) + n);
  x_.assign(b_.begin(), b_.end());
  const double floor = 1e-10 * p.h * p.model.gravity.norm() + 1e-300;   // m/s
  if (c.factors.factored() && c.factors.substitute(x_.data())) {
    double last = kInfinity;
    for (int iteration = 0; iteration < kRefinements; ++iteration) {
      r_.resize(n);
      c.system.multiply(x_.data(), r_.data());
      for (std::size_t i = 0; i < n; ++i) r_[i] = b_[i] - r_[i];
      if (!c.factors.substitute(r_.data())) break;
      double correction = 0.0, size = 0.0;
      for (std::size_t i = 0; i < n; ++i) {
        x_[i] += r_[i];
        correction = std::max(correction, std::abs(r_[i]));
        size = std::max(size, std::abs(x_[i]));
      }
      if (correction <= 1e-12 * size + floor) return true;
      if (!(correction < 0.5 * last)) break;   // not converging fast: the factors are stale
      last = correction;
    }
  }
  c.factors.copy_values(c.system);
  x_.assign(b_.begin(), b_.end());
  return c.factors.factor() && c.factors.substitute(x_.data());
}

// M q^ + h Q and the couplings' h J^T G J and h J^T (force + C u0) into `sink` (local body
// indices), in this round's modes; a rule's row and column in its body's diagonal block.
template <class Sink>
void IslandSolve::assemble(const StepProblem& p, double h, Sink& sink) {
  const State& state = p.state;
  for (int b : current_) {
    const int l = local_[b];
    const BodyParams& bp = p.model.bodies[b];
    const Mat3& R = state.bodies[b].rotation;
    const Mat3 inertia = R * bp.inertia.asDiagonal() * R.transpose();   // kg m^2, world
    const Vec3 momentum = bp.mass * vq_[b] + h * p.force[b];
    const Vec3 spin = inertia * wq_[b] + h * p.torque[b];
    const BlockRef d = sink.diagonal(l);
    double* r = sink.rhs(l);
    for (int i = 0; i < 3; ++i) {
      d(i, i) += bp.mass;
      for (int j = 0; j < 3; ++j) d(3 + i, 3 + j) += inertia(i, j);
      r[i] += momentum[i];
      r[3 + i] += spin[i];
    }
    iso_[l] = IsotropicSum{};
  }
  // An isotropic point's block on its own body, g [[I, -S(r)], [S(r), -S(r)^2]], is linear in g,
  // g r and g S(r)^2 = g (r r^T - (r . r) I): summed over the body's points first, added once.
  const auto own_block = [&](int body, const CouplingResponse& g, const Vec3& arm) {
    const int l = local_[body];
    if (g.shape != CouplingResponse::Shape::kIsotropic) return add_block(sink.diagonal(l), g, arm, arm, h);
    IsotropicSum& sum = iso_[l];
    sum.g += g.g;
    sum.g_arm += g.g * arm;
    Mat3 arm2 = arm * arm.transpose();
    arm2.diagonal().array() -= arm.dot(arm);
    sum.g_arm2 += g.g * arm2;
  };
  for (int i : current_couplings_) {
    if (mode_[i] == CouplingMode::kOff) continue;
    const Coupling& c = p.couplings[i];
    response_[i] = response_of(c, mode_[i], slide_[i], h);
    const CouplingResponse& g = response_[i];
    constant_[i] = constant_force(c, start_force_[i], mode_[i], u0_[i], slide_[i]);
    Vec3 fc = constant_[i];
    if (c.a < 0) fc += g.times(c.world_velocity);   // the world side moves on: u1 = J q1 - v_world
    const bool in_b = c.b >= 0 && p.awake[c.b];
    const bool in_a = c.a >= 0 && p.awake[c.a];
    const Vec3 r_b = in_b ? Vec3(c.point - state.bodies[c.b].position) : Vec3::Zero();
    const Vec3 r_a = in_a ? Vec3(c.point - state.bodies[c.a].position) : Vec3::Zero();
    if (in_b) {
      own_block(c.b, g, r_b);
      double* r = sink.rhs(local_[c.b]);
      const Vec3 t = r_b.cross(fc);
      for (int k = 0; k < 3; ++k) {
        r[k] += h * fc[k];
        r[3 + k] += h * t[k];
      }
    }
    if (in_a) {
      own_block(c.a, g, r_a);
      double* r = sink.rhs(local_[c.a]);
      const Vec3 t = r_a.cross(fc);
      for (int k = 0; k < 3; ++k) {
        r[k] -= h * fc[k];
        r[3 + k] -= h * t[k];
      }
    }
    if (in_a && in_b) {
      add_block(sink.block(local_[c.b], local_[c.a]), g, r_b, r_a, -h);
      add_block(sink.block(local_[c.a], local_[c.b]), g, r_a, r_b, -h);
    }
  }
  for (int b : current_) {
    const IsotropicSum& sum = iso_[local_[b]];
    if (sum.g == 0.0) continue;
    const BlockRef d = sink.diagonal(local_[b]);
    const Mat3 s = h * skew(sum.g_arm);
    for (int i = 0; i < 3; ++i) {
      d(i, i) += h * sum.g;
      for (int j = 0; j < 3; ++j) {
        d(i, 3 + j) -= s(i, j);
        d(3 + i, j) += s(i, j);
        d(3 + i, 3 + j) -= h * sum.g_arm2(i, j);
      }
    }
  }
  // Axis constraints: w1 . u = rate. The multiplier turns the body about the axis line through
  // the first god-object, as a hinge (momentum M d, d = (u x (c - p), u) the twist of a unit turn
  // about that line), so that setting the rate does not move the axis itself: the fingers on it
  // are not asked for the pivot's force (grasp_rules.hpp). Unsymmetric: the block LU pivots.
  for (int b : current_) {
    const AxisRule& rule = p.rules[b];
    if (!rule.active) continue;
    const BodyParams& bp = p.model.bodies[b];
    const Mat3& R = state.bodies[b].rotation;
    const Vec3& u = rule.grasp.axis;
    const Vec3 dv = u.cross(state.bodies[b].position - rule.grasp.go_first);    // m/s per rad/s
    const Vec3 dl = R * bp.inertia.cwiseProduct(R.transpose() * u);             // kg m^2
    const BlockRef d = sink.diagonal(local_[b]);
    for (int i = 0; i < 3; ++i) {
      d(6, 3 + i) = u[i];
      d(i, 6) = bp.mass * dv[i];
      d(3 + i, 6) = dl[i];
    }
    sink.rhs(local_[b])[6] = rule.rate;
  }
}

}  // namespace graspsim
