// The stability check: for the contact set a State holds, the linearised one-step map of each
// body, and of each group of bodies that touch, on all of its springs and dampers at once
// (fingers, floor points, other bodies, the grasp rules), under the integrator the model uses.
// Its spectral radius says whether a small disturbance grows from one physics step to the next;
// its dominant eigenvector says which motion and which springs carry the growth
// (engine/README.md, "Stability check"). Not part of the step: called before a run and when the
// contact set changes (contact_signature), so it may allocate.
#pragma once

#include <complex>
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "graspsim/engine/math.hpp"
#include "graspsim/engine/model.hpp"
#include "graspsim/engine/contact_gather.hpp"
#include "graspsim/engine/coupling.hpp"
#include "graspsim/engine/state.hpp"

namespace graspsim {

// A map whose spectral radius exceeds this makes a disturbance grow. Not exactly 1: a free
// direction (a body held by one finger turns freely about it) gives the eigenvalue 1 twice in a
// Jordan block, which rounding splits by about sqrt(1e-16) = 1e-8; an undamped spring under
// symplectic Euler has |lambda| = 1 exactly. A real growth of 1e-6 a step would need 10^6 steps
// (5.6 h at 50 Hz) to grow e-fold: no run sees it.
inline constexpr double kUnstableRadius = 1.0 + 1e-6;

// ---- the map of a linear system ----
//
// Generalised coordinates q (n of them) with inverse mass W (n x n, symmetric positive
// definite), stiffness K and damping C (n x n, symmetric positive semi-definite): the force is
// -K q - C q'. With W = L L^T, the coordinates z = L^-1 q make the system M' = I, K' = L^T K L,
// C' = L^T C L (same eigenvalues, better conditioned), and the state is (z, y = h z'), both in
// the same units. One step of length h:
//   kPaper (symplectic Euler, integrate.cpp):   y1 = (I - h C') y0 - h^2 K' z0,   z1 = z0 + y1
//   kImplicit (linearised backward Euler, island_solve.hpp: the pose moves by h v1):
//     S y1 = y0 - h^2 K' z0,  S = I + h C' + h^2 K',   z1 = z0 + y1
// The map is the 2n x 2n matrix A with (z1, y1) = A (z0, y0).
//   kImplicit with implicit_order 2 (BDF2, its restarts aside):
//     S2 y1 = (4 y0 - y_-1) / 3 - (2/3) h^2 K' (4 z0 - z_-1) / 3,  S2 = I + (2/3) h C' + (4/9) h^2 K'
//     z1 = (4 z0 - z_-1) / 3 + (2/3) y1
//   a 4n x 4n map of (z0, y0, z_-1, y_-1); its first n components are still z0.
Eigen::MatrixXd one_step_map(Integrator integrator, const Eigen::MatrixXd& stiffness_over_mass,
                             const Eigen::MatrixXd& damping_over_mass, double h, int implicit_order);

// The largest |lambda| over the eigenvalues of `map` (Eigen's EigenSolver: the same input gives
// the same output).
double spectral_radius(const Eigen::MatrixXd& map);

// Symplectic Euler on one spring k, damper c and mass m at step h, in closed form: the radius
// of [[1 - a, 1 - b], [-a, 1 - b]] with a = h^2 k / m, b = h c / m (trace 2 - a - b, det 1 - b).
// Stable (radius <= 1) iff b < 2 and a < 4 - 2 b; for c = 0 the eigenvalues lie on the unit
// circle while a <= 4 and the radius is (a - 2) / 2 + sqrt(((a - 2) / 2)^2 - 1) beyond.
double paper_radius_1d(double k_over_m, double c_over_m, double h);

// ---- couplings of a state ----

// The couplings are the contact points as every stage sees them (coupling.hpp): a spring-damper
// between two bodies (or a body and the world) at a point, whose force on b is -K du - C du' where
// du is b's material displacement at the point relative to a's; the velocity of a body's point is
// v + w x r, r from its centre of mass (J = [I, -skew(r)]). K and C from contact_matrix(): k I while
// the point holds, k n n^T while it slips.

// The rotation about a two-finger grasp axis that the grasp rules drive instead of the springs
// (grasp_rules.hpp): through `point` along unit `axis`, world.
struct GraspHinge {
  int body = -1;
  Vec3 point{0.0, 0.0, 0.0};   // m, world: the first god-object
  Vec3 axis{0.0, 0.0, 1.0};    // 1, world, unit
  enum class Rate { kLocked, kInertial, kQuasiStatic } rate = Rate::kLocked;
};

// ---- what the analysis finds ----

struct StabilityMode {
  std::vector<int> bodies;             // the group, ascending
  int physics = 0;                     // Hz: the rate the map was evaluated at
  double radius = 0.0;                 // 1: spectral radius of the one-step map
  std::complex<double> eigenvalue;     // the dominant one
  std::string motion;                  // e.g. "sideways translation y with yaw about z"
  std::vector<std::string> springs;    // the couplings carrying most of the mode's spring energy,
                                       // e.g. "finger 'thumb'", "the floor under 'box'"
  int stable_physics = 0;              // Hz: the lowest multiple of `physics` dividing the servo
                                       // rate at which the map is stable (0: none is)
  bool unstable() const { return radius > kUnstableRadius; }
};

struct StabilityReport {
  Integrator integrator = Integrator::kPaper;
  int physics = 0;                   // Hz
  std::vector<StabilityMode> groups;  // every group with a coupling, by its lowest body
  int worst = -1;                    // index into groups of the largest radius (-1: none)
  bool unstable() const { return worst >= 0 && groups[worst].unstable(); }
  // One sentence a person can act on about the worst group when it is unstable, else "".
  std::string warning(const Model& model) const;
};

// ---- when to look again ----

// The contact set in a few integers: which fingers touch which body and stick or slip, how many
// floor points each body has, which pairs touch and at how many points, and which bodies sleep.
// Cheap (no geometry); the analysis depends on the state only through this and the poses, so a
// caller re-runs it when this changes.
struct ContactSignature {
  std::vector<int> finger_body;     // per finger: FingerState::body
  std::vector<int> finger_phase;    // per finger: ContactPhase as an int
  std::vector<int> floor_points;    // per body: active floor points
  std::vector<int> asleep;          // per body: 1 when sleeping
  std::vector<int> pair_points;     // per pair of State::pairs: its bodies and points at the last step
  bool operator==(const ContactSignature&) const = default;
};
ContactSignature contact_signature(const State& state);

class StabilityCheck {
 public:
  // With `contacts`, the points of touching pairs come from that gather (a Simulation's: one FCL
  // world a run); without, from one of its own.
  explicit StabilityCheck(const Model& model, ContactGather* contacts = nullptr);
  const Model& model() const { return model_; }
  // The points of touching pairs from `contacts` from now on (its own gather is dropped).
  void use_contacts(ContactGather& contacts) {
    contacts_ = &contacts;
    own_.reset();
  }

  // Every coupling at `state`, in a fixed order: fingers, then floor points body by body, then
  // body pairs (the gather's last_contacts); and the hinges the grasp rules impose.
  std::vector<Coupling> couplings(const State& state);
  std::vector<GraspHinge> hinges(const State& state) const;

  // The map of every group at `state` under the model's integrator and physics rate, or the
  // ones given.
  StabilityReport analyse(const State& state);
  StabilityReport analyse(const State& state, int physics, Integrator integrator);

  // A short name of a coupling for a sentence: "finger 'thumb'", "the floor under 'box'",
  // "the contact of 'a' and 'b'".
  std::string name(const Coupling& c) const;

 private:
  Model model_;
  std::unique_ptr<ContactGather> own_;   // when no gather was given
  ContactGather* contacts_;
};

// The check over a run: after each physics tick, the state is analysed again when its contact
// signature has changed (and at the first call), and a warning is given once per mode: a mode
// met again (the same bodies on the same springs, at another radius or pose) gives none.
class StabilityMonitor {
 public:
  explicit StabilityMonitor(const Model& model, ContactGather* contacts = nullptr);
  void use_contacts(ContactGather& contacts) { check_.use_contacts(contacts); }

  // Returns the warning for `state` if its analysis is unstable and that mode was not warned
  // of before, else "". Cheap when the signature is unchanged (a comparison, no allocation).
  std::string update(const State& state);

  const StabilityReport& report() const { return report_; }   // of the last analysis
  int analyses() const { return analyses_; }                   // how many were run

 private:
  StabilityCheck check_;
  ContactSignature last_;
  bool has_last_ = false;
  StabilityReport report_;
  std::vector<std::string> warned_;   // the modes warned of (bodies and springs)
  int analyses_ = 0;
};

}  // namespace graspsim
