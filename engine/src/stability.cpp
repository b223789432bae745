// The stability check (stability.hpp): the couplings of a state, the groups of bodies that
// touch, each group's one-step map, and its dominant mode in words.
#include "graspsim/engine/stability.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <utility>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>

#include "graspsim/engine/finger_contact.hpp"
#include "graspsim/engine/grasp_rules.hpp"

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

// A contact's spring (or damper) of coefficient k: isotropic while it holds, along the normal
// only while it slips (the tangential force then sits on the friction cone, mu f_n, and no
// longer follows the displacement).
Mat3 law(double k, const Vec3& n, bool slipping) {
  return slipping ? Mat3(k * n * n.transpose()) : Mat3(k * Mat3::Identity());
}

bool finite_law(const ContactPair& p) { return std::isfinite(p.stiffness) && std::isfinite(p.damping); }

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

// One group's linear system in the map's coordinates (stability.hpp): q = B z' with
// z' = L z, W = B^T M^-1 B = L L^T, K' = L^T B^T K B L, C' likewise.
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
  const Eigen::EigenSolver<MatrixXd> solver(one_step_map(integrator, k, c, h), false);
  std::complex<double> best = 0.0;
  for (Eigen::Index i = 0; i < solver.eigenvalues().size(); ++i) {
    if (std::abs(solver.eigenvalues()[i]) > std::abs(best)) best = solver.eigenvalues()[i];
  }
  return best;
}

double group_radius(const GroupSystem& g, Integrator integrator, double c_t, double h) {
  double r = spectral_radius(one_step_map(integrator, g.k, g.c, h));
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

}  // namespace

ContactSignature contact_signature(const State& state) {
  ContactSignature s;
  for (const FingerState& fs : state.fingers) {
    s.finger_body.push_back(fs.body);
    s.finger_phase.push_back(static_cast<int>(fs.phase));
  }
  for (const BodyState& bs : state.bodies) {
    int active = 0;
    for (const VertexContact& vc : bs.floor_contacts) active += vc.active ? 1 : 0;
    s.floor_points.push_back(active);
    s.asleep.push_back(bs.asleep ? 1 : 0);
  }
  for (const PairContact& pc : state.pairs) s.pair_points.push_back(pc.count);
  return s;
}

StabilityCheck::StabilityCheck(const Model& model) : model_(model), contacts_(model_) {}

std::string StabilityCheck::name(const StabilityCoupling& c) const {
  switch (c.kind) {
    case StabilityCoupling::Kind::kFinger: return "finger " + quoted(model_.fingers[c.finger].name);
    case StabilityCoupling::Kind::kFloor: return "the floor under " + quoted(model_.bodies[c.b].name);
    case StabilityCoupling::Kind::kBody:
      return "the contact of " + quoted(model_.bodies[c.a].name) + " and " + quoted(model_.bodies[c.b].name);
  }
  return "?";
}

std::vector<StabilityCoupling> StabilityCheck::couplings(const State& state) {
  std::vector<StabilityCoupling> out;
  // Fingers: the servo force k (GO - HIP) + c (v_GO - v_HIP), with the GO riding on the body, is
  // a spring from a point fixed in the world (the HIP) to the body's material point under the GO.
  // The paper's scheme applies the mean of the window's servo forces, each computed at the pose
  // (and velocity) the body has had since the last physics step, since a body only moves at
  // physics steps: over the map the finger acts as an explicit spring at the physics rate; the
  // window changes nothing but which HIP it pulls towards (an input, not a state).
  for (std::size_t f = 0; f < state.fingers.size(); ++f) {
    const FingerState& fs = state.fingers[f];
    if (fs.phase == ContactPhase::kFree || fs.body < 0) continue;
    const BodyState& bs = state.bodies[fs.body];
    const ContactPair pair = finger_contact_pair(model_, static_cast<int>(f), fs.body);
    const Vec3 n = bs.rotation * fs.normal;
    const bool slipping = fs.phase == ContactPhase::kSlip;
    StabilityCoupling c;
    c.kind = StabilityCoupling::Kind::kFinger;
    c.b = fs.body;
    c.finger = static_cast<int>(f);
    c.point = bs.rotation * fs.god_object + bs.position - model_.fingers[f].radius * n;
    c.stiffness = law(pair.stiffness, n, slipping);
    c.damping = law(model_.fingers[f].damping, n, slipping);
    out.push_back(c);
  }
  // Floor points that touched at the last step, at the pose now. A contact law left infinite
  // (only possible when the integrator chooses it) has no spring to analyse here.
  if (model_.floor.enabled) {
    for (std::size_t b = 0; b < state.bodies.size(); ++b) {
      const BodyState& bs = state.bodies[b];
      const BodyParams& bp = model_.bodies[b];
      const ContactPair pair = contact_pair(bp.material, model_.floor.material);
      if (!finite_law(pair)) continue;
      for (std::size_t k = 0; k < bs.floor_contacts.size(); ++k) {
        const VertexContact& vc = bs.floor_contacts[k];
        if (!vc.active) continue;
        bool rolling = false;
        StabilityCoupling c;
        c.kind = StabilityCoupling::Kind::kFloor;
        c.b = static_cast<int>(b);
        c.point = bs.position + floor_point(bp.shape, bs.rotation, static_cast<int>(k), rolling);
        c.stiffness = law(pair.stiffness, Vec3::UnitZ(), vc.slipping);
        c.damping = law(pair.damping, Vec3::UnitZ(), vc.slipping);
        out.push_back(c);
      }
    }
  }
  // Body pairs that touched at the last step: their manifold at the pose now, each point's
  // slipping flag from the anchor with its key.
  const int nb = static_cast<int>(state.bodies.size());
  ManifoldPoint points[kMaxPairPoints];
  for (int a = 0; a < nb; ++a) {
    for (int b = a + 1; b < nb; ++b) {
      const PairContact& pc = state.pairs[pair_index(a, b, nb)];
      if (pc.count == 0) continue;
      const ContactPair pair = contact_pair(model_.bodies[a].material, model_.bodies[b].material);
      if (!finite_law(pair)) continue;
      const int n = contacts_.points(model_, state, a, b, points);
      for (int i = 0; i < n; ++i) {
        bool slipping = false;
        for (int j = 0; j < pc.count; ++j) {
          if (pc.points[j].key == points[i].key) slipping = pc.points[j].slipping;
        }
        StabilityCoupling c;
        c.kind = StabilityCoupling::Kind::kBody;
        c.a = a;
        c.b = b;
        c.point = points[i].point;
        c.stiffness = law(pair.stiffness, points[i].normal, slipping);
        c.damping = law(pair.damping, points[i].normal, slipping);
        out.push_back(c);
      }
    }
  }
  return out;
}

std::vector<GraspHinge> StabilityCheck::hinges(const State& state) const {
  std::vector<GraspHinge> out;
  const GraspParams& gp = model_.grasp;
  if (gp.torsion == Torsion::kNone) return out;
  for (std::size_t b = 0; b < state.bodies.size(); ++b) {
    const TwoPointGrasp grasp = two_point_grasp(model_, state, static_cast<int>(b));
    if (!grasp.held) continue;
    GraspHinge h;
    h.body = static_cast<int>(b);
    h.point = grasp.go_first;
    h.axis = grasp.axis;
    if (gp.torsion == Torsion::kGravityDrop) {
      // Below A_crit the rules turn the body about the axis by the gravity-drop torque and the
      // floor's (and other bodies') torque about it; above, they hold the rate at zero.
      if (grasp.area < gp.critical_area) {
        h.rate = gp.torsional_damping > 0.0 ? GraspHinge::Rate::kQuasiStatic : GraspHinge::Rate::kInertial;
      }
    } else if (!(grasp.area > gp.critical_area) ||
               (grasp.first != gp.gimbal_finger && grasp.second != gp.gimbal_finger)) {
      continue;   // the gimbal rule acts only above A_crit, with the gimbal finger in the grasp
    }
    out.push_back(h);
  }
  return out;
}

StabilityReport StabilityCheck::analyse(const State& state) {
  return analyse(state, model_.rates.physics, model_.integrator);
}

StabilityReport StabilityCheck::analyse(const State& state, int physics, Integrator integrator) {
  StabilityReport report;
  report.integrator = integrator;
  report.physics = physics;
  const std::vector<StabilityCoupling> cs = couplings(state);
  const std::vector<GraspHinge> hs = hinges(state);
  const int nb = static_cast<int>(state.bodies.size());
  // A sleeping body is not stepped: to the bodies that touch it, it is part of the world.
  const auto moves = [&](int b) { return b >= 0 && !state.bodies[b].asleep; };

  // Groups: bodies joined by body-body points (union-find), each listed by its lowest body.
  std::vector<int> parent(nb);
  for (int b = 0; b < nb; ++b) parent[b] = b;
  std::vector<std::uint8_t> coupled(nb, 0);
  for (const StabilityCoupling& c : cs) {
    if (moves(c.a)) coupled[c.a] = 1;
    if (moves(c.b)) coupled[c.b] = 1;
    if (moves(c.a) && moves(c.b)) parent[find_root(parent, c.a)] = find_root(parent, c.b);
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

  const double c_t = model_.grasp.torsional_damping;
  for (const std::vector<int>& bodies : groups) {
    GroupSystem g;
    g.bodies = bodies;
    g.local.assign(nb, -1);
    const int n = static_cast<int>(bodies.size());
    for (int i = 0; i < n; ++i) g.local[bodies[i]] = i;
    const int n6 = 6 * n;
    g.k6 = MatrixXd::Zero(n6, n6);
    g.c6 = MatrixXd::Zero(n6, n6);
    // Each body's own block of the floor and body points only: what the grasp rules turn it by.
    std::vector<Eigen::Matrix<double, 6, 6>> k_rule(n, Eigen::Matrix<double, 6, 6>::Zero());
    std::vector<Eigen::Matrix<double, 6, 6>> c_rule(n, Eigen::Matrix<double, 6, 6>::Zero());
    // Assemble sum over couplings of s_i s_j J_i^T K J_j over the sides (a: -1, b: +1) in the group.
    for (const StabilityCoupling& c : cs) {
      const int side[2] = {moves(c.a) ? g.local[c.a] : -1, moves(c.b) ? g.local[c.b] : -1};
      if (side[0] < 0 && side[1] < 0) continue;
      Mat36 j[2];
      const int body[2] = {c.a, c.b};
      for (int s = 0; s < 2; ++s) {
        if (side[s] >= 0) j[s] = point_jacobian(c.point - state.bodies[body[s]].position);
      }
      for (int s = 0; s < 2; ++s) {
        for (int t = 0; t < 2; ++t) {
          if (side[s] < 0 || side[t] < 0) continue;
          const double sign = (s == t) ? 1.0 : -1.0;
          g.k6.block<6, 6>(6 * side[s], 6 * side[t]) += sign * j[s].transpose() * c.stiffness * j[t];
          g.c6.block<6, 6>(6 * side[s], 6 * side[t]) += sign * j[s].transpose() * c.damping * j[t];
        }
        if (side[s] >= 0 && c.kind != StabilityCoupling::Kind::kFinger) {
          k_rule[side[s]] += j[s].transpose() * c.stiffness * j[s];
          c_rule[side[s]] += j[s].transpose() * c.damping * j[s];
        }
      }
    }
    // Free directions: all six, but under a grasp hinge the rules remove the springs' torque
    // about the axis u (and its angular acceleration, keep_axis_rate in grasp_rules.cpp), so the
    // springs move the body in translation and in the rotations perpendicular to u only; the
    // rotation about u is driven by the rule, a mode of its own (hinge_modes). Its effect on the
    // rest is one-way, so the map's eigenvalues are those of the two parts.
    std::vector<int> dims(n, 6);
    std::vector<const GraspHinge*> hinge_of(n, nullptr);
    for (const GraspHinge& h : hs) {
      if (g.local[h.body] >= 0) {
        hinge_of[g.local[h.body]] = &h;
        dims[g.local[h.body]] = 5;
      }
    }
    int d_total = 0;
    for (int d : dims) d_total += d;
    g.basis = MatrixXd::Zero(n6, d_total);
    MatrixXd inverse_mass = MatrixXd::Zero(n6, n6);
    int col = 0;
    for (int i = 0; i < n; ++i) {
      const BodyParams& bp = model_.bodies[bodies[i]];
      const BodyState& bs = state.bodies[bodies[i]];
      inverse_mass.block<3, 3>(6 * i, 6 * i) = Mat3::Identity() / bp.mass;
      inverse_mass.block<3, 3>(6 * i + 3, 6 * i + 3) =
          bs.rotation * bp.inertia.cwiseInverse().asDiagonal() * bs.rotation.transpose();
      g.basis.block<3, 3>(6 * i, col) = Mat3::Identity();
      if (const GraspHinge* h = hinge_of[i]) {
        // Two unit vectors perpendicular to u (from the world axis least along u).
        Eigen::Index least = 0;
        h->axis.cwiseAbs().minCoeff(&least);
        const Vec3 e1 = h->axis.cross(Vec3::Unit(least)).normalized();
        const Vec3 e2 = h->axis.cross(e1);
        g.basis.block<3, 1>(6 * i + 3, col + 3) = e1;
        g.basis.block<3, 1>(6 * i + 3, col + 4) = e2;
        if (h->rate != GraspHinge::Rate::kLocked) {
          const Eigen::Matrix<double, 6, 1> d = hinge_direction(*h, bs);
          const Mat3 inertia = bs.rotation * bp.inertia.asDiagonal() * bs.rotation.transpose();
          const double j_axis = bp.mass * d.head<3>().squaredNorm() + h->axis.dot(inertia * h->axis);
          g.hinge_modes.push_back({bodies[i], h->rate, d.dot(k_rule[i] * d), d.dot(c_rule[i] * d), j_axis});
        }
      } else {
        g.basis.block<3, 3>(6 * i + 3, col + 3) = Mat3::Identity();
      }
      col += dims[i];
    }
    const MatrixXd w = g.basis.transpose() * inverse_mass * g.basis;
    g.l = Eigen::LLT<MatrixXd>(w).matrixL();
    g.k = g.l.transpose() * (g.basis.transpose() * g.k6 * g.basis) * g.l;
    g.c = g.l.transpose() * (g.basis.transpose() * g.c6 * g.basis) * g.l;
    g.k = 0.5 * (g.k + g.k.transpose()).eval();   // symmetric to the last bit
    g.c = 0.5 * (g.c + g.c.transpose()).eval();

    StabilityMode mode;
    mode.bodies = bodies;
    mode.physics = physics;
    const double h = 1.0 / physics;
    // The dominant eigenpair of the springs' map.
    const Eigen::EigenSolver<MatrixXd> solver(one_step_map(integrator, g.k, g.c, h), true);
    Eigen::Index top = 0;
    for (Eigen::Index i = 1; i < solver.eigenvalues().size(); ++i) {
      if (std::abs(solver.eigenvalues()[i]) > std::abs(solver.eigenvalues()[top])) top = i;
    }
    mode.eigenvalue = d_total > 0 ? solver.eigenvalues()[top] : std::complex<double>(0.0);
    mode.radius = std::abs(mode.eigenvalue);
    const GroupSystem::Hinge* hinge_wins = nullptr;
    for (const auto& m : g.hinge_modes) {
      const std::complex<double> l = hinge_eigenvalue(m, integrator, c_t, h);
      if (std::abs(l) > mode.radius) {
        mode.radius = std::abs(l);
        mode.eigenvalue = l;
        hinge_wins = &m;
      }
    }
    // Its motion and the springs that carry it (their share of q^H J^T K J q).
    std::vector<std::pair<std::string, double>> energy;
    const auto add_energy = [&](const std::string& who, double e) {
      for (auto& [name, sum] : energy) {
        if (name == who) {
          sum += e;
          return;
        }
      }
      energy.emplace_back(who, e);
    };
    if (hinge_wins) {
      mode.motion = "rotation about the grasp axis of " + quoted(model_.bodies[hinge_wins->body].name) +
                    " (the grasp rule's)";
      for (const StabilityCoupling& c : cs) {
        if (c.kind != StabilityCoupling::Kind::kFinger && (c.a == hinge_wins->body || c.b == hinge_wins->body))
          add_energy(name(c), 1.0);
      }
    } else if (d_total > 0) {
      const VectorXcd z = g.l.cast<std::complex<double>>() * solver.eigenvectors().col(top).head(d_total);
      const VectorXcd q = g.basis.cast<std::complex<double>>() * z;
      mode.motion = describe_motion(model_, state, bodies, q);
      for (const StabilityCoupling& c : cs) {
        Eigen::Vector3cd du = Eigen::Vector3cd::Zero();
        const int side[2] = {moves(c.a) ? g.local[c.a] : -1, moves(c.b) ? g.local[c.b] : -1};
        if (side[0] < 0 && side[1] < 0) continue;
        const int body[2] = {c.a, c.b};
        for (int s = 0; s < 2; ++s) {
          if (side[s] < 0) continue;
          const Mat36 j = point_jacobian(c.point - state.bodies[body[s]].position);
          du += (s == 1 ? 1.0 : -1.0) * (j.cast<std::complex<double>>() * q.segment<6>(6 * side[s]));
        }
        add_energy(name(c), std::real(du.dot(c.stiffness.cast<std::complex<double>>() * du)));
      }
    }
    double total = 0.0;
    for (const auto& e : energy) total += e.second;
    std::stable_sort(energy.begin(), energy.end(), [](const auto& a, const auto& b) { return a.second > b.second; });
    for (const auto& [who, e] : energy) {
      if (mode.springs.size() == 4 || (!mode.springs.empty() && e < 0.1 * total)) break;
      mode.springs.push_back(who);
    }
    // The lowest stable rate by bisection (the radius falls as the step shrinks: h^2 K and h C
    // shrink with it) among the multiples of this rate that divide the servo rate: a scenario
    // whose duration is a whole number of physics periods keeps one at each of them.
    std::vector<int> rates;
    for (int r = physics; r <= model_.rates.servo; r += physics) {
      if (model_.rates.servo % r == 0) rates.push_back(r);
    }
    if (!mode.unstable()) {
      mode.stable_physics = physics;
    } else if (!rates.empty() && group_radius(g, integrator, c_t, 1.0 / rates.back()) <= kUnstableRadius) {
      std::size_t lo = 0, hi = rates.size() - 1;   // rates[lo] unstable (or the given rate), rates[hi] stable
      while (hi - lo > 1) {
        const std::size_t mid = (lo + hi) / 2;
        if (group_radius(g, integrator, c_t, 1.0 / rates[mid]) <= kUnstableRadius) hi = mid;
        else lo = mid;
      }
      mode.stable_physics = rates[hi];
    }
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

namespace graspsim {
namespace {

// contact_signature(state) == s, without building one.
bool matches(const ContactSignature& s, const State& state) {
  if (s.finger_body.size() != state.fingers.size() || s.floor_points.size() != state.bodies.size() ||
      s.pair_points.size() != state.pairs.size())
    return false;
  for (std::size_t f = 0; f < state.fingers.size(); ++f) {
    const FingerState& fs = state.fingers[f];
    if (s.finger_body[f] != fs.body || s.finger_phase[f] != static_cast<int>(fs.phase)) return false;
  }
  for (std::size_t b = 0; b < state.bodies.size(); ++b) {
    const BodyState& bs = state.bodies[b];
    int active = 0;
    for (const VertexContact& vc : bs.floor_contacts) active += vc.active ? 1 : 0;
    if (s.floor_points[b] != active || s.asleep[b] != (bs.asleep ? 1 : 0)) return false;
  }
  for (std::size_t p = 0; p < state.pairs.size(); ++p) {
    if (s.pair_points[p] != state.pairs[p].count) return false;
  }
  return true;
}

}  // namespace

StabilityMonitor::StabilityMonitor(const Model& model) : check_(model) {}

std::string StabilityMonitor::update(const State& state) {
  if (has_last_ && matches(last_, state)) return "";
  last_ = contact_signature(state);
  has_last_ = true;
  report_ = check_.analyse(state);
  ++analyses_;
  if (!report_.unstable()) return "";
  // A mode is its bodies and the springs that carry it (in any order): its motion's words and
  // its radius move with the pose.
  const StabilityMode& m = report_.groups[report_.worst];
  std::vector<std::string> springs = m.springs;
  std::sort(springs.begin(), springs.end());
  std::string key;
  for (int b : m.bodies) key += std::to_string(b) + ",";
  for (const std::string& s : springs) key += s + ";";
  if (std::find(warned_.begin(), warned_.end(), key) != warned_.end()) return "";
  warned_.push_back(key);
  return report_.warning(check_.model());
}

}  // namespace graspsim
