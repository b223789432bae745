// The linearly implicit step (backward Euler on each island's velocities, linearised couplings)
// and its active set of unilateral, frictional points.
#include "graspsim/engine/implicit_step.hpp"
#include "graspsim/engine/dense_solve.hpp"

#include <algorithm>
#include <cmath>

namespace graspsim {
namespace {

// G = h K + C of a coupling in its mode (3x3, world): the force's change per unit of relative
// velocity at the end of the step. While sliding along unit t (tangential, the way the held
// spring pulled) the tangential force is mu times the normal one: G = g_n (n + mu t) n^T.
Mat3 response(const Coupling& c, CouplingMode mode, const Vec3& slide, double h) {
  const double reach = h + c.lead;   // s: the time the springs see the end velocity over
  const double g_n = reach * c.k_n + c.c_n;
  if (mode == CouplingMode::kSlip) return g_n * (c.normal + c.mu * slide) * c.normal.transpose();
  const Mat3 nn = c.normal * c.normal.transpose();
  const double g_t = reach * c.k_t + c.c_t;
  return g_n * nn + g_t * (Mat3::Identity() - nn);
}

// The constant part of the force, force + (C + lead K) u0 (`force`: the coupling's, less h/3 K
// u_mean under BDF2), in its mode; while sliding along t the
// tangential part is mu times the normal part, plus the viscous force.
Vec3 constant_force(const Coupling& c, const Vec3& force, CouplingMode mode, const Vec3& u0, const Vec3& slide) {
  const Vec3& n = c.normal;
  const double normal = n.dot(force) + (c.c_n + c.lead * c.k_n) * n.dot(u0);   // N
  if (mode == CouplingMode::kSlip) return normal * (n + c.mu * slide) + c.viscous * slide;
  const Vec3 tangential = force - n.dot(force) * n + (c.c_t + c.lead * c.k_t) * (u0 - n.dot(u0) * n);
  return normal * n + tangential;
}

// Adds s * J_x^T G J_y into the 6x6 block at (row, col) of the n-wide matrix, J = [I, -S(r)]:
//   J_x^T G J_y = [[G, -G S_y], [S_x G, -S_x G S_y]].
// Two shapes of G take a shortcut (the same matrix, fewer products): isotropic, G = g I (a held
// point whose normal and tangential laws are one), where S_x S_y = y x^T - (x . y) I; and rank
// one, G = a b^T (a sliding point, a = g_n (n + mu t), b = n), where J_x^T G J_y = (J_x^T a)(J_y^T b)^T
// and J^T v = (v, r x v).
using Response = CouplingResponse;

template <int N>
void add_block(double* m, int size, int row, int col, const Response& g, const Vec3& r_x, const Vec3& r_y, double s) {
  constexpr int kSize = N > 0 ? N : Eigen::Dynamic;
  Eigen::Map<Eigen::Matrix<double, kSize, kSize, Eigen::RowMajor>> a(m, N > 0 ? N : size, N > 0 ? N : size);
  if (g.shape == Response::Shape::kIsotropic) {
    const double sg = s * g.g;
    const Mat3 sy = skew(r_y), sx = skew(r_x);
    a.template block<3, 3>(row, col).diagonal().array() += sg;
    a.template block<3, 3>(row, col + 3) -= sg * sy;
    a.template block<3, 3>(row + 3, col) += sg * sx;
    Mat3 sxsy = r_y * r_x.transpose();
    sxsy.diagonal().array() -= r_x.dot(r_y);
    a.template block<3, 3>(row + 3, col + 3) -= sg * sxsy;
    return;
  }
  if (g.shape == Response::Shape::kRankOne) {
    Eigen::Matrix<double, 6, 1> ja, jb;
    ja << g.a, r_x.cross(g.a);
    jb << g.b, r_y.cross(g.b);
    a.template block<6, 6>(row, col) += (s * ja) * jb.transpose();
    return;
  }
  const Mat3 sx = skew(r_x);
  const Mat3 gs = g.full * skew(r_y);
  a.template block<3, 3>(row, col) += s * g.full;
  a.template block<3, 3>(row, col + 3) -= s * gs;
  a.template block<3, 3>(row + 3, col) += s * (sx * g.full);
  a.template block<3, 3>(row + 3, col + 3) -= s * (sx * gs);
}

// The coupling's response G (response()) with its shape for add_block.
Response response_shape(const Coupling& c, CouplingMode mode, const Vec3& slide, double h) {
  Response r;
  const double reach = h + c.lead;   // s
  const double g_n = reach * c.k_n + c.c_n;
  if (mode == CouplingMode::kSlip) {
    r.shape = Response::Shape::kRankOne;
    r.a = g_n * (c.normal + c.mu * slide);
    r.b = c.normal;
  } else if (g_n == reach * c.k_t + c.c_t) {
    r.shape = Response::Shape::kIsotropic;
    r.g = g_n;
  } else {
    r.shape = Response::Shape::kGeneral;
    r.full = response(c, mode, slide, h);
  }
  return r;
}

}  // namespace

ImplicitStep::ImplicitStep(const Model& model) {
  const std::size_t n = model.bodies.size();
  parent_.resize(n);
  island_of_.resize(n);
  local_.resize(n);
  current_.reserve(n);
  matrix_.resize(49 * n * n);
  rhs_.resize(7 * n);
  v1_.resize(n);
  w1_.resize(n);
  vq_.resize(n);
  wq_.resize(n);
  v_mean_.resize(n);
  w_mean_.resize(n);
  second_order_.resize(n);
  iso_.resize(n);
  signature_.resize(n);
}

void ImplicitStep::reserve(std::size_t couplings) {
  mode_.reserve(couplings);
  slide_.reserve(couplings);
  solved_.reserve(couplings);
  u0_.reserve(couplings);
  start_force_.reserve(couplings);
  constant_.reserve(couplings);
  response_.reserve(couplings);
  current_couplings_.reserve(couplings);
}

int ImplicitStep::find(int body) {
  while (parent_[body] != body) body = parent_[body] = parent_[parent_[body]];
  return body;
}

inline Vec3 ImplicitStep::relative_velocity(const State& state, const Coupling& c, const std::vector<Vec3>& v,
                                     const std::vector<Vec3>& w) const {
  const auto point_velocity = [&](int body) -> Vec3 {
    if (body < 0 || island_of_[body] < 0) return Vec3::Zero();
    return v[body] + w[body].cross(c.point - state.bodies[body].position);
  };
  return point_velocity(c.b) - (c.a < 0 ? c.world_velocity : point_velocity(c.a));
}

void ImplicitStep::solve(const Model& model, const State& state, const std::vector<Coupling>& couplings,
                         const std::vector<std::uint8_t>& awake, const std::vector<Vec3>& v0,
                         const std::vector<Vec3>& w0, const std::vector<Vec3>& force,
                         const std::vector<Vec3>& torque, const std::vector<std::uint8_t>& axis_active,
                         const std::vector<Vec3>& axis, const std::vector<Vec3>& axis_point,
                         const std::vector<double>& axis_rate, const StepHistory& history, double h) {
  const Inputs in{model, state, couplings, force, torque, axis_active, axis, axis_point, axis_rate};
  const int nb = static_cast<int>(model.bodies.size());
  mode_.assign(couplings.size(), CouplingMode::kHold);
  slide_.assign(couplings.size(), Vec3::Zero());
  solved_.assign(couplings.size(), Vec3::Zero());
  for (int b = 0; b < nb; ++b) {
    parent_[b] = b;
    island_of_[b] = awake[b] ? 0 : -1;
    v1_[b] = v0[b];
    w1_[b] = w0[b];
    second_order_[b] = 0;
    signature_[b] = 0;
  }
  u0_.resize(couplings.size());
  start_force_.resize(couplings.size());
  constant_.resize(couplings.size());
  response_.resize(couplings.size());
  for (std::size_t i = 0; i < couplings.size(); ++i) u0_[i] = relative_velocity(state, couplings[i], v0, w0);
  // Islands: awake bodies joined by a body point (a sleeping body stays put, as the world does).
  for (const Coupling& c : couplings) {
    if (c.a >= 0 && c.b >= 0 && awake[c.a] && awake[c.b]) {
      const int ra = find(c.a), rb = find(c.b);
      if (ra != rb) parent_[std::max(ra, rb)] = std::min(ra, rb);
    }
  }
  for (int root = 0; root < nb; ++root) {
    if (!awake[root] || find(root) != root) continue;
    current_.clear();
    for (int b = root; b < nb; ++b) {
      if (awake[b] && find(b) == root) {
        local_[b] = static_cast<int>(current_.size());
        current_.push_back(b);
      }
    }
    current_couplings_.clear();
    for (std::size_t i = 0; i < couplings.size(); ++i) {
      const Coupling& c = couplings[i];
      const int body = (c.b >= 0 && awake[c.b]) ? c.b : c.a;
      if (body >= 0 && awake[body] && find(body) == root) current_couplings_.push_back(static_cast<int>(i));
    }
    // BDF2 where every body of the island stepped in this same island for kSettledSteps, with no
    // axis rule (a rule sets the rate about its axis outright, a jump the history cannot carry),
    // no finger (its force is the fast loops' mean over the window, measured while its god-object
    // slid on the surface: its stretch over a step is not the bodies' displacement, which is what
    // BDF2's history term takes it to be) and the gyroscopic term neglected (its step is backward
    // Euler's one Newton step; BDF2 on the world angular velocity would drift |L| by 21 % in
    // spin_flip).
    const std::uint64_t last = history.order == 2 && model.gyroscopic == Gyroscopic::kNeglect ? history.signature[root] : 0;
    bool bdf2 = last != 0;
    // Nor a point between two bodies: those are found only once they overlap (the floor's are
    // taken in as the step reaches them), and BDF2's lighter damping of an arrival's bounce lets a
    // body overshoot such a point by a micrometre, lose it and fall a whole step back in.
    for (int i : current_couplings_) bdf2 = bdf2 && couplings[i].source == Coupling::Source::kFloor;
    for (int b : current_) {
      bdf2 = bdf2 && history.valid[b] && !axis_active[b] && history.signature[b] == last &&
             history.steps[b] >= kSettledSteps;
    }
    if (bdf2) {
      const double third = 1.0 / 3.0;
      for (int b : current_) {
        const BodyState& bs = state.bodies[b];
        v_mean_[b] = (bs.position - bs.position_before_step) / h;
        const Eigen::AngleAxisd turn(bs.rotation * bs.rotation_before_step.transpose());
        w_mean_[b] = (turn.angle() / h) * turn.axis();
        vq_[b] = third * (4.0 * v0[b] - state.bodies[b].velocity_before_step);
        wq_[b] = third * (4.0 * w0[b] - state.bodies[b].angular_velocity_before_step);
      }
      // The springs' displacement over the step is h (u_mean + 2 u1) / 3: the part already known
      // joins the force at the start (in a sliding point only its normal part counts).
      for (int i : current_couplings_) {
        const Coupling& c = couplings[i];
        const Vec3 u = relative_velocity(state, c, v_mean_, w_mean_);
        const double u_n = c.normal.dot(u);
        start_force_[i] = c.force - (third * h) * (c.k_n * u_n * c.normal + c.k_t * (u - u_n * c.normal));
      }
      solve_island(in, 2.0 * third * h);
      bdf2 = island_signature(couplings) == last;
    }
    if (!bdf2) {
      for (int b : current_) {
        vq_[b] = v0[b];
        wq_[b] = w0[b];
      }
      for (int i : current_couplings_) start_force_[i] = couplings[i].force;
      solve_island(in, h);
    }
    const std::uint64_t signature = bdf2 ? last : island_signature(couplings);
    for (int b : current_) {
      second_order_[b] = bdf2 ? 1 : 0;
      signature_[b] = signature;
    }
  }
}

// Rounds: solve, then change modes where the solution breaks a limit. A point leaving the cone is
// decided before any point letting go: a held point stops the body dead, and the torque that takes
// can lift other points that a sliding body keeps on the floor. `h` is the step's implicit
// coefficient: the step for backward Euler, 2/3 of it for BDF2.
void ImplicitStep::solve_island(const Inputs& in, double h) {
  const State& state = in.state;
  const std::vector<Coupling>& couplings = in.couplings;
  for (int i : current_couplings_) {
    mode_[i] = CouplingMode::kHold;
    slide_[i].setZero();
    solved_[i].setZero();
  }
  for (int round = 0; round < kMaxRounds; ++round) {
    assemble_and_solve(in, h);
    bool slipped = false, released = false;
    for (int i : current_couplings_) {
      const Coupling& c = couplings[i];
      if (mode_[i] == CouplingMode::kOff) continue;
      const Vec3 u1 = relative_velocity(state, c, v1_, w1_);
      solved_[i] = constant_[i] - response_[i].times(u1);
      if (c.mu < 0.0 || mode_[i] != CouplingMode::kHold) continue;
      const double f_n = c.normal.dot(solved_[i]);
      const Vec3 f_t = solved_[i] - f_n * c.normal;
      const double f_t_norm = f_t.norm();
      // Out of the cone (or pulling, which no cone holds): it slides the way it pulled. A
      // pulling point slides before it may let go, so that a held point's drag, which pitches
      // the body, is gone before the solve decides which points lift off.
      if (f_t_norm > c.mu * std::max(0.0, f_n) + c.viscous) {
        mode_[i] = CouplingMode::kSlip;
        slide_[i] = f_t / f_t_norm;
        slipped = true;
      }
    }
    if (!slipped) {
      for (int i : current_couplings_) {
        const Coupling& c = couplings[i];
        if (c.mu < 0.0 || mode_[i] == CouplingMode::kOff || c.normal.dot(solved_[i]) >= 0.0) continue;
        mode_[i] = CouplingMode::kOff;   // it would pull: the point lets go
        released = true;
      }
    }
    if (!slipped && !released) break;
  }
  for (int i : current_couplings_) {
    if (mode_[i] == CouplingMode::kOff) solved_[i].setZero();
  }
}

// A hash of the island's bodies and its couplings' identities, whether each pushed at the start
// of the step, and their modes: equal from one step to the next only while the same points act on
// the same bodies in the same way. (A floor point the step reaches is a coupling before the body
// arrives; its arrival is the step its force starts to push.) Word by word, FNV-1a's multiply
// with an xor-shift after it, so that every bit of a word reaches the high and the low bits.
std::uint64_t ImplicitStep::island_signature(const std::vector<Coupling>& couplings) const {
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

void ImplicitStep::assemble_and_solve(const Inputs& in, double h) {
  int constraints = 0;
  for (int b : current_) constraints += in.axis_active[b] ? 1 : 0;
  const int n = 6 * static_cast<int>(current_.size()) + constraints;
  switch (n) {
    case 6: return assemble_and_solve_n<6>(in, n, h);   // one body, no axis rule
    default: return assemble_and_solve_n<0>(in, n, h);
  }
}

// The island's system from q^ = (vq_, wq_), the couplings in their modes, and the axis
// constraints; solved into (v1_, w1_).
template <int N>
void ImplicitStep::assemble_and_solve_n(const Inputs& in, int size, double h) {
  const int n = N > 0 ? N : size;
  const Model& model = in.model;
  const State& state = in.state;
  const std::vector<Vec3>& v0 = vq_;
  const std::vector<Vec3>& w0 = wq_;
  double* m = matrix_.data();
  double* r = rhs_.data();
  std::fill(m, m + n * n, 0.0);
  // M q0 + h Q: each body's mass and world inertia R Jp R^T, its momentum and the external wrench.
  for (int b : current_) {
    const int o = 6 * local_[b];
    const BodyParams& bp = model.bodies[b];
    const Mat3& R = state.bodies[b].rotation;
    const Mat3 inertia = R * bp.inertia.asDiagonal() * R.transpose();   // kg m^2, world
    const Vec3 p = bp.mass * v0[b] + h * in.force[b];
    const Vec3 l = inertia * w0[b] + h * in.torque[b];
    for (int i = 0; i < 3; ++i) {
      m[(o + i) * n + o + i] = bp.mass;
      for (int j = 0; j < 3; ++j) m[(o + 3 + i) * n + o + 3 + j] = inertia(i, j);
      r[o + i] = p[i];
      r[o + 3 + i] = l[i];
    }
  }
  // Each coupling: h J^T G J into the matrix, h J^T (force + C u0) into the right side. An
  // isotropic point's block on its own body, g [[I, -S(r)], [S(r), -S(r)^2]], is linear in g, g r
  // and g S(r)^2 = g (r r^T - (r . r) I): summed over the body's points first, and added once.
  for (int b : current_) iso_[local_[b]] = IsotropicSum{};
  const auto own_block = [&](int body, const Response& g, const Vec3& arm) {
    const int o = 6 * local_[body];
    if (g.shape != Response::Shape::kIsotropic) return add_block<N>(m, n, o, o, g, arm, arm, h);
    IsotropicSum& sum = iso_[local_[body]];
    sum.g += g.g;
    sum.g_arm += g.g * arm;
    Mat3 arm2 = arm * arm.transpose();
    arm2.diagonal().array() -= arm.dot(arm);
    sum.g_arm2 += g.g * arm2;
  };
  for (int i : current_couplings_) {
    const Coupling& c = in.couplings[i];
    if (mode_[i] == CouplingMode::kOff) continue;
    response_[i] = response_shape(c, mode_[i], slide_[i], h);
    const Response& g = response_[i];
    constant_[i] = constant_force(c, start_force_[i], mode_[i], u0_[i], slide_[i]);
    Vec3 fc = constant_[i];
    if (c.a < 0) fc += g.times(c.world_velocity);   // the world side moves on: u1 = J q1 - v_world
    const bool in_b = c.b >= 0 && island_of_[c.b] >= 0;
    const bool in_a = c.a >= 0 && island_of_[c.a] >= 0;
    const Vec3 r_b = in_b ? Vec3(c.point - state.bodies[c.b].position) : Vec3::Zero();
    const Vec3 r_a = in_a ? Vec3(c.point - state.bodies[c.a].position) : Vec3::Zero();
    if (in_b) {
      const int o = 6 * local_[c.b];
      own_block(c.b, g, r_b);
      const Vec3 t = r_b.cross(fc);
      for (int k = 0; k < 3; ++k) {
        r[o + k] += h * fc[k];
        r[o + 3 + k] += h * t[k];
      }
    }
    if (in_a) {
      const int o = 6 * local_[c.a];
      own_block(c.a, g, r_a);
      const Vec3 t = r_a.cross(fc);
      for (int k = 0; k < 3; ++k) {
        r[o + k] -= h * fc[k];
        r[o + 3 + k] -= h * t[k];
      }
    }
    if (in_a && in_b) {
      add_block<N>(m, n, 6 * local_[c.b], 6 * local_[c.a], g, r_b, r_a, -h);
      add_block<N>(m, n, 6 * local_[c.a], 6 * local_[c.b], g, r_a, r_b, -h);
    }
  }
  for (int b : current_) {
    const IsotropicSum& sum = iso_[local_[b]];
    if (sum.g == 0.0) continue;
    const int o = 6 * local_[b];
    constexpr int kSize = N > 0 ? N : Eigen::Dynamic;
    Eigen::Map<Eigen::Matrix<double, kSize, kSize, Eigen::RowMajor>> a(m, n, n);
    const Mat3 s = h * skew(sum.g_arm);
    a.template block<3, 3>(o, o).diagonal().array() += h * sum.g;
    a.template block<3, 3>(o, o + 3) -= s;
    a.template block<3, 3>(o + 3, o) += s;
    a.template block<3, 3>(o + 3, o + 3) -= h * sum.g_arm2;
  }
  // Axis constraints: w1 . u = rate. The multiplier turns the body about the axis line through
  // `axis_point`, as a hinge (momentum M d, d = (u x (c - p), u) the twist of a unit turn about
  // that line), so that setting the rate does not move the axis itself: the fingers on it are
  // not asked for the pivot's force (grasp_rules.hpp). Unsymmetric, so the elimination pivots.
  int row = 6 * static_cast<int>(current_.size());
  for (int b : current_) {
    if (!in.axis_active[b]) continue;
    const int o = 6 * local_[b];
    const BodyParams& bp = model.bodies[b];
    const Mat3& R = state.bodies[b].rotation;
    const Vec3& u = in.axis[b];
    const Vec3 dv = u.cross(state.bodies[b].position - in.axis_point[b]);              // m/s per rad/s
    const Vec3 dl = R * bp.inertia.cwiseProduct(R.transpose() * u);                  // kg m^2
    for (int i = 0; i < 3; ++i) {
      m[row * n + o + 3 + i] = u[i];
      m[(o + i) * n + row] = bp.mass * dv[i];
      m[(o + 3 + i) * n + row] = dl[i];
    }
    r[row] = in.axis_rate[b];
    ++row;
  }
  if constexpr (N == 6) dense::solve_one_body(m, r);
  else dense::lu_solve(m, r, n);
  for (int b : current_) {
    const int o = 6 * local_[b];
    v1_[b] = Vec3(r[o], r[o + 1], r[o + 2]);
    w1_[b] = Vec3(r[o + 3], r[o + 4], r[o + 5]);
  }
}

}  // namespace graspsim
