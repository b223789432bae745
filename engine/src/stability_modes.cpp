// The stability check's analysis (stability.hpp): the groups of bodies that touch, each
// group's one-step map, its dominant mode in words, and the lowest rate that holds it.
#include "graspsim/engine/stability.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <sstream>
#include <utility>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>

#include "graspsim/engine/contact_law.hpp"

namespace graspsim {
namespace {

using Eigen::MatrixXd;
using Eigen::VectorXcd;
using Mat36 = Eigen::Matrix<double, 3, 6>;

// J = [I, -skew(r)]: the velocity of the point r (from the centre of mass) is v + w x r = J (v, w).
Mat36 point_jacobian(const Vec3& r) {
  Mat36 j;
  j.leftCols<3>() = Mat3::Identity();
  j.rightCols<3>() = -skew(r);
  return j;
}

int find_root(std::vector<int>& parent, int i) {
  while (parent[i] != i) i = parent[i] = parent[parent[i]];
  return i;
}

std::string quoted(const std::string& s) { return "'" + s + "'"; }

// "a", "a and b", "a, b and c".
std::string join_and(const std::vector<std::string>& items) {
  std::string out;
  for (std::size_t i = 0; i < items.size(); ++i) {
    if (i > 0) out += i + 1 == items.size() ? " and " : ", ";
    out += items[i];
  }
  return out;
}

std::string number(double v, int digits = 3) {
  std::ostringstream s;
  s.precision(digits);
  s << v;
  return s.str();
}

// The rotation a grasp hinge turns: rate w about `axis` through `point` moves the centre of mass
// at w axis x (c - point), so the generalised direction is d = (axis x (c - point), axis).
Eigen::Matrix<double, 6, 1> hinge_direction(const GraspHinge& g, const BodyState& bs) {
  Eigen::Matrix<double, 6, 1> d;
  d.head<3>() = g.axis.cross(bs.position - g.point);
  d.tail<3>() = g.axis;
  return d;
}

// One group's linear system in the map's coordinates (stability.hpp): the bodies' coordinates
// q = B L z, with B the free directions, W = B^T M^-1 B = L L^T, K' = L^T B^T K B L and C'
// likewise.
struct GroupSystem {
  std::vector<int> bodies;
  std::vector<int> local;   // per model body: its index in the group, or -1
  MatrixXd k6, c6;          // 6n x 6n, on (x, theta) per body: stiffness (N/m, N, N m/rad in
                            // its blocks) and damping (likewise, per second), assembled
  MatrixXd basis;           // 6n x D: each body's free directions (5 under a grasp hinge)
  MatrixXd l;               // D x D: Cholesky factor of the reduced inverse mass
  MatrixXd k, c;            // D x D: K' (1/s^2), C' (1/s)
  // The rotations about a grasp axis that the grasp rules drive with the floor and body
  // contacts' torque about it (not the fingers'): a separate mode of one coordinate.
  struct Hinge {
    int body;
    GraspHinge::Rate rate;
    double k, c, inertia;   // N m/rad, N m s/rad, kg m^2: about the axis
  };
  std::vector<Hinge> hinge_modes;
};

// The dominant eigenvalue of a hinge mode: the rate integrated like any body rate (inertial), or
// set by the pads' torsional friction c_t, w = T / c_t, so the angle follows
// theta1 = theta0 - h k theta0 / c_t (explicit; the implicit scheme's analogue divides by
// 1 + h k / c_t).
std::complex<double> hinge_eigenvalue(const GroupSystem::Hinge& m, Integrator integrator, double c_t, double h) {
  if (m.rate == GraspHinge::Rate::kQuasiStatic) {
    const double g = h * m.k / c_t;
    return integrator == Integrator::kPaper ? 1.0 - g : 1.0 / (1.0 + g);
  }
  const MatrixXd k = MatrixXd::Constant(1, 1, m.k / m.inertia);
  const MatrixXd c = MatrixXd::Constant(1, 1, m.c / m.inertia);
  const Eigen::EigenSolver<MatrixXd> solver(one_step_map(integrator, k, c, h, 1), false);
  std::complex<double> best = 0.0;
  for (Eigen::Index i = 0; i < solver.eigenvalues().size(); ++i) {
    if (std::abs(solver.eigenvalues()[i]) > std::abs(best)) best = solver.eigenvalues()[i];
  }
  return best;
}

// The order of the implicit step a group takes: BDF2 under implicit_order 2 but where a grasp
// rule's hinge acts, which takes backward Euler (island_solve.hpp).
int group_order(const GroupSystem& g, const Model& model) {
  return g.hinge_modes.empty() ? model.implicit_order : 1;
}

double group_radius(const GroupSystem& g, Integrator integrator, int order, double c_t, double h) {
  double r = spectral_radius(one_step_map(integrator, g.k, g.c, h, order));
  for (const auto& m : g.hinge_modes) r = std::max(r, std::abs(hinge_eigenvalue(m, integrator, c_t, h)));
  return r;
}

// How the dominant eigenvalue moves a disturbance from step to step.
std::string cadence(std::complex<double> l) {
  const double arg = std::abs(std::arg(l));
  if (arg > M_PI * (1.0 - 1e-6)) return "changing sign every step";
  if (arg < 1e-6) return "without oscillating";
  return "oscillating over " + number(2.0 * M_PI / arg, 2) + " steps";
}

const char* kComponentWords[6] = {"sideways translation x", "sideways translation y", "vertical translation z",
                                  "roll about x", "pitch about y", "yaw about z"};

// The motion of a mode q (6 per body, world: translation of the centre of mass, rotation), by the
// share of each component in its kinetic-energy norm (m |x_i|^2, I_ii |theta_i|^2 with I the
// world inertia): the largest, and the others that hold at least 15% of the total, at most three.
std::string describe_motion(const Model& model, const State& state, const std::vector<int>& bodies,
                            const VectorXcd& q) {
  struct Part {
    double share;
    int body, component;
  };
  std::vector<Part> parts;
  double total = 0.0;
  for (std::size_t i = 0; i < bodies.size(); ++i) {
    const BodyParams& bp = model.bodies[bodies[i]];
    const Mat3& R = state.bodies[bodies[i]].rotation;
    const Mat3 inertia = R * bp.inertia.asDiagonal() * R.transpose();
    for (int c = 0; c < 6; ++c) {
      const double weight = c < 3 ? bp.mass : inertia(c - 3, c - 3);
      const double share = weight * std::norm(q[static_cast<Eigen::Index>(6 * i + c)]);
      parts.push_back({share, bodies[i], c});
      total += share;
    }
  }
  std::stable_sort(parts.begin(), parts.end(), [](const Part& a, const Part& b) { return a.share > b.share; });
  std::vector<std::string> words;
  for (const Part& p : parts) {
    if (words.size() == 3 || (!words.empty() && p.share < 0.15 * total)) break;
    std::string w = kComponentWords[p.component];
    if (bodies.size() > 1) w = quoted(model.bodies[p.body].name) + " " + w;
    words.push_back(w);
  }
  if (words.empty()) return "no motion";
  std::string out = words[0];
  if (words.size() > 1) out += " with " + join_and(std::vector<std::string>(words.begin() + 1, words.end()));
  return out;
}

// A sleeping body is not stepped: to the bodies that touch it, it is part of the world.
bool moves(const State& state, int b) { return b >= 0 && !state.bodies[b].asleep; }

// Bodies joined by body-body points (union-find), each group listed by its lowest body; a body
// with no coupling is in none.
std::vector<std::vector<int>> touching_groups(const State& state, const std::vector<Coupling>& cs) {
  const int nb = static_cast<int>(state.bodies.size());
  std::vector<int> parent(nb);
  for (int b = 0; b < nb; ++b) parent[b] = b;
  std::vector<std::uint8_t> coupled(nb, 0);
  for (const Coupling& c : cs) {
    if (moves(state, c.a)) coupled[c.a] = 1;
    if (moves(state, c.b)) coupled[c.b] = 1;
    if (moves(state, c.a) && moves(state, c.b)) parent[find_root(parent, c.a)] = find_root(parent, c.b);
  }
  std::vector<std::vector<int>> groups;
  std::vector<int> group_of_root(nb, -1);
  for (int b = 0; b < nb; ++b) {
    if (!coupled[b]) continue;
    const int root = find_root(parent, b);
    if (group_of_root[root] < 0) {
      group_of_root[root] = static_cast<int>(groups.size());
      groups.emplace_back();
    }
    groups[group_of_root[root]].push_back(b);
  }
  return groups;
}

// The sides of coupling c within group g: a's and b's index in it, or -1 (world, asleep, other).
std::array<int, 2> sides(const GroupSystem& g, const State& state, const Coupling& c) {
  return {moves(state, c.a) ? g.local[c.a] : -1, moves(state, c.b) ? g.local[c.b] : -1};
}

// The group's linear system: K and C assembled as sum over couplings and their sides s, t
// (a: -1, b: +1) of s t J_s^T K J_t; the free directions (all six, or five under a grasp
// hinge); W = B^T M^-1 B = L L^T; K', C'; and the hinges' own modes.
GroupSystem assemble(const Model& model, const State& state, const std::vector<int>& bodies,
                     const std::vector<Coupling>& cs, const std::vector<GraspHinge>& hs) {
  GroupSystem g;
  g.bodies = bodies;
  g.local.assign(state.bodies.size(), -1);
  const int n = static_cast<int>(bodies.size());
  for (int i = 0; i < n; ++i) g.local[bodies[i]] = i;
  g.k6 = MatrixXd::Zero(6 * n, 6 * n);
  g.c6 = MatrixXd::Zero(6 * n, 6 * n);
  // Each body's own block of the floor and body points only: what the grasp rules turn it by.
  std::vector<Eigen::Matrix<double, 6, 6>> k_rule(n, Eigen::Matrix<double, 6, 6>::Zero());
  std::vector<Eigen::Matrix<double, 6, 6>> c_rule(n, Eigen::Matrix<double, 6, 6>::Zero());
  for (const Coupling& c : cs) {
    const std::array<int, 2> side = sides(g, state, c);
    if (side[0] < 0 && side[1] < 0) continue;
    const int body[2] = {c.a, c.b};
    const Mat3 stiffness = contact_matrix(c.k_n, c.normal, c.slipping);   // N/m, world
    const Mat3 damping = contact_matrix(c.c_n, c.normal, c.slipping);     // N s/m, world
    Mat36 j[2];
    for (int s = 0; s < 2; ++s) {
      if (side[s] >= 0) j[s] = point_jacobian(c.point - state.bodies[body[s]].position);
    }
    for (int s = 0; s < 2; ++s) {
      if (side[s] < 0) continue;
      for (int t = 0; t < 2; ++t) {
        if (side[t] < 0) continue;
        const double sign = (s == t) ? 1.0 : -1.0;
        g.k6.block<6, 6>(6 * side[s], 6 * side[t]) += sign * j[s].transpose() * stiffness * j[t];
        g.c6.block<6, 6>(6 * side[s], 6 * side[t]) += sign * j[s].transpose() * damping * j[t];
      }
      if (c.source != Coupling::Source::kFinger) {
        k_rule[side[s]] += j[s].transpose() * stiffness * j[s];
        c_rule[side[s]] += j[s].transpose() * damping * j[s];
      }
    }
  }
  // Free directions: all six, but under a grasp hinge the rules remove the springs' torque
  // about the axis u (and its angular acceleration, keep_axis_rate in grasp_rules.cpp), so the
  // springs move the body in translation and in the rotations perpendicular to u only; the
  // rotation about u is driven by the rule, a mode of its own (hinge_modes). Its effect on the
  // rest is one-way, so the map's eigenvalues are those of the two parts.
  std::vector<const GraspHinge*> hinge_of(n, nullptr);
  int d_total = 0;
  for (int i = 0; i < n; ++i) {
    for (const GraspHinge& h : hs) {
      if (h.body == bodies[i]) hinge_of[i] = &h;
    }
    d_total += hinge_of[i] ? 5 : 6;
  }
  g.basis = MatrixXd::Zero(6 * n, d_total);
  MatrixXd inverse_mass = MatrixXd::Zero(6 * n, 6 * n);
  int col = 0;
  for (int i = 0; i < n; ++i) {
    const BodyParams& bp = model.bodies[bodies[i]];
    const BodyState& bs = state.bodies[bodies[i]];
    const Mat3 inertia = bs.rotation * bp.inertia.asDiagonal() * bs.rotation.transpose();   // kg m^2, world
    inverse_mass.block<3, 3>(6 * i, 6 * i) = Mat3::Identity() / bp.mass;
    inverse_mass.block<3, 3>(6 * i + 3, 6 * i + 3) =
        bs.rotation * bp.inertia.cwiseInverse().asDiagonal() * bs.rotation.transpose();
    g.basis.block<3, 3>(6 * i, col) = Mat3::Identity();
    if (const GraspHinge* h = hinge_of[i]) {
      // Two unit vectors perpendicular to u (from the world axis least along u).
      Eigen::Index least = 0;
      h->axis.cwiseAbs().minCoeff(&least);
      const Vec3 e1 = h->axis.cross(Vec3::Unit(least)).normalized();
      g.basis.block<3, 1>(6 * i + 3, col + 3) = e1;
      g.basis.block<3, 1>(6 * i + 3, col + 4) = h->axis.cross(e1);
      if (h->rate != GraspHinge::Rate::kLocked) {
        const Eigen::Matrix<double, 6, 1> d = hinge_direction(*h, bs);
        const double j_axis = bp.mass * d.head<3>().squaredNorm() + h->axis.dot(inertia * h->axis);
        g.hinge_modes.push_back({bodies[i], h->rate, d.dot(k_rule[i] * d), d.dot(c_rule[i] * d), j_axis});
      }
      col += 5;
    } else {
      g.basis.block<3, 3>(6 * i + 3, col + 3) = Mat3::Identity();
      col += 6;
    }
  }
  const MatrixXd w = g.basis.transpose() * inverse_mass * g.basis;
  g.l = Eigen::LLT<MatrixXd>(w).matrixL();
  g.k = g.l.transpose() * (g.basis.transpose() * g.k6 * g.basis) * g.l;
  g.c = g.l.transpose() * (g.basis.transpose() * g.c6 * g.basis) * g.l;
  g.k = 0.5 * (g.k + g.k.transpose()).eval();   // symmetric to the last bit
  g.c = 0.5 * (g.c + g.c.transpose()).eval();
  return g;
}

// The names with the largest shares of `energy` (at least 10% of the total, at most four), largest
// first.
std::vector<std::string> largest_shares(std::vector<std::pair<std::string, double>> energy) {
  double total = 0.0;
  for (const auto& e : energy) total += e.second;
  std::stable_sort(energy.begin(), energy.end(), [](const auto& a, const auto& b) { return a.second > b.second; });
  std::vector<std::string> out;
  for (const auto& [who, e] : energy) {
    if (out.size() == 4 || (!out.empty() && e < 0.1 * total)) break;
    out.push_back(who);
  }
  return out;
}

void add_share(std::vector<std::pair<std::string, double>>& energy, const std::string& who, double e) {
  for (auto& [name, sum] : energy) {
    if (name == who) {
      sum += e;
      return;
    }
  }
  energy.emplace_back(who, e);
}

// The group's dominant mode at step h: the springs' map's largest eigenvalue, or a hinge's if
// larger; its motion in words and the springs that carry it (their share of q^H J^T K J q; for a
// hinge, the floor and body points on its body). `names` are the couplings' names.
void dominant_mode(const Model& model, const State& state, const GroupSystem& g,
                   const std::vector<Coupling>& cs, const std::vector<std::string>& names,
                   Integrator integrator, double h, StabilityMode& mode) {
  const Eigen::Index d = g.k.rows();
  const Eigen::EigenSolver<MatrixXd> solver(one_step_map(integrator, g.k, g.c, h, group_order(g, model)), true);
  Eigen::Index top = 0;
  for (Eigen::Index i = 1; i < solver.eigenvalues().size(); ++i) {
    if (std::abs(solver.eigenvalues()[i]) > std::abs(solver.eigenvalues()[top])) top = i;
  }
  mode.eigenvalue = d > 0 ? solver.eigenvalues()[top] : std::complex<double>(0.0);
  const GroupSystem::Hinge* hinge = nullptr;
  for (const auto& m : g.hinge_modes) {
    const std::complex<double> l = hinge_eigenvalue(m, integrator, model.grasp.torsional_damping, h);
    if (std::abs(l) > std::abs(mode.eigenvalue)) {
      mode.eigenvalue = l;
      hinge = &m;
    }
  }
  mode.radius = std::abs(mode.eigenvalue);
  std::vector<std::pair<std::string, double>> energy;
  if (hinge) {
    mode.motion = "rotation about the grasp axis of " + quoted(model.bodies[hinge->body].name) + " (the grasp rule's)";
    for (std::size_t i = 0; i < cs.size(); ++i) {
      if (cs[i].source != Coupling::Source::kFinger && (cs[i].a == hinge->body || cs[i].b == hinge->body))
        add_share(energy, names[i], 1.0);
    }
  } else if (d > 0) {
    const VectorXcd z = g.l.cast<std::complex<double>>() * solver.eigenvectors().col(top).head(d);
    const VectorXcd q = g.basis.cast<std::complex<double>>() * z;
    mode.motion = describe_motion(model, state, g.bodies, q);
    for (std::size_t i = 0; i < cs.size(); ++i) {
      const Coupling& c = cs[i];
      const std::array<int, 2> side = sides(g, state, c);
      if (side[0] < 0 && side[1] < 0) continue;
      const int body[2] = {c.a, c.b};
      Eigen::Vector3cd du = Eigen::Vector3cd::Zero();   // b's displacement at the point less a's
      for (int s = 0; s < 2; ++s) {
        if (side[s] < 0) continue;
        const Mat36 j = point_jacobian(c.point - state.bodies[body[s]].position);
        du += (s == 1 ? 1.0 : -1.0) * (j.cast<std::complex<double>>() * q.segment<6>(6 * side[s]));
      }
      add_share(energy, names[i], std::real(du.dot(contact_matrix(c.k_n, c.normal, c.slipping).cast<std::complex<double>>() * du)));
    }
  }
  mode.springs = largest_shares(std::move(energy));
}

// The lowest stable rate by bisection (the radius falls as the step shrinks: h^2 K and h C
// shrink with it) among the multiples of `physics` that divide the servo rate: a scenario whose
// duration is a whole number of physics periods keeps one at each of them. 0 when none is.
int lowest_stable_rate(const GroupSystem& g, const Model& model, Integrator integrator, int physics) {
  std::vector<int> rates;
  for (int r = physics; r <= model.rates.servo; r += physics) {
    if (model.rates.servo % r == 0) rates.push_back(r);
  }
  const double c_t = model.grasp.torsional_damping;
  const int order = group_order(g, model);
  const auto stable = [&](int rate) { return group_radius(g, integrator, order, c_t, 1.0 / rate) <= kUnstableRadius; };
  if (rates.empty() || !stable(rates.back())) return 0;
  if (stable(rates.front())) return rates.front();
  std::size_t lo = 0, hi = rates.size() - 1;   // rates[lo] unstable, rates[hi] stable
  while (hi - lo > 1) {
    const std::size_t mid = (lo + hi) / 2;
    (stable(rates[mid]) ? hi : lo) = mid;
  }
  return rates[hi];
}

}  // namespace

StabilityReport StabilityCheck::analyse(const State& state) {
  return analyse(state, model_.rates.physics, model_.integrator);
}

StabilityReport StabilityCheck::analyse(const State& state, int physics, Integrator integrator) {
  StabilityReport report;
  report.integrator = integrator;
  report.physics = physics;
  const std::vector<Coupling> cs = couplings(state);
  const std::vector<GraspHinge> hs = hinges(state);
  std::vector<std::string> names;
  for (const Coupling& c : cs) names.push_back(name(c));
  for (const std::vector<int>& bodies : touching_groups(state, cs)) {
    const GroupSystem g = assemble(model_, state, bodies, cs, hs);
    StabilityMode mode;
    mode.bodies = bodies;
    mode.physics = physics;
    dominant_mode(model_, state, g, cs, names, integrator, 1.0 / physics, mode);
    mode.stable_physics = mode.unstable() ? lowest_stable_rate(g, model_, integrator, physics) : physics;
    report.groups.push_back(std::move(mode));
  }
  for (std::size_t i = 0; i < report.groups.size(); ++i) {
    if (report.worst < 0 || report.groups[i].radius > report.groups[report.worst].radius) report.worst = static_cast<int>(i);
  }
  return report;
}

std::string StabilityReport::warning(const Model& model) const {
  if (!unstable()) return "";
  const StabilityMode& m = groups[worst];
  std::vector<std::string> bodies;
  for (int b : m.bodies) bodies.push_back(quoted(model.bodies[b].name));
  std::ostringstream s;
  s << "at " << m.physics << " Hz the " << (integrator == Integrator::kPaper ? "paper's explicit" : "implicit")
    << " step of " << join_and(bodies);
  if (!m.springs.empty()) s << " on " << join_and(m.springs);
  s << " has spectral radius " << number(m.radius) << " (" << m.motion << ", " << cadence(m.eigenvalue)
    << "): a disturbance grows " << number(m.radius) << " times a step; ";
  if (m.stable_physics > 0) {
    s << "raise rates.physics to >= " << m.stable_physics << " Hz";
  } else {
    s << "no physics rate up to the servo rate (" << model.rates.servo << " Hz) is stable: soften those springs";
  }
  if (integrator == Integrator::kPaper) s << " or use integrator = \"implicit\"";
  return s.str();
}

}  // namespace graspsim
