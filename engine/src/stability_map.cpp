// The one-step map of a linear spring-damper system under each integrator, and its spectral
// radius (stability.hpp).
#include <algorithm>
#include <cmath>
#include <limits>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>

#include "graspsim/engine/stability.hpp"

namespace graspsim {

Eigen::MatrixXd one_step_map(Integrator integrator, const Eigen::MatrixXd& k, const Eigen::MatrixXd& c,
                             double h, int implicit_order) {
  const Eigen::Index n = k.rows();
  const Eigen::MatrixXd id = Eigen::MatrixXd::Identity(n, n);
  if (integrator == Integrator::kImplicit && implicit_order == 2) {
    // BDF2 on (z, y), with y = h z' (state: z0, y0, z_-1, y_-1):
    //   S2 y1 = (4 y0 - y_-1) / 3 - (2/3) h^2 K' (4 z0 - z_-1) / 3,  S2 = I + (2/3) h C' + (4/9) h^2 K'
    //   z1 = (4 z0 - z_-1) / 3 + (2/3) y1
    const Eigen::LLT<Eigen::MatrixXd> s(id + (2.0 / 3.0) * h * c + (4.0 / 9.0) * h * h * k);
    const Eigen::MatrixXd s_inv = s.solve(id);
    const Eigen::MatrixXd s_inv_z = s.solve((2.0 / 3.0) * h * h * k);
    Eigen::MatrixXd a = Eigen::MatrixXd::Zero(4 * n, 4 * n);
    const Eigen::MatrixXd y_z0 = -(4.0 / 3.0) * s_inv_z, y_zm = (1.0 / 3.0) * s_inv_z;   // y1's rows
    const Eigen::MatrixXd y_y0 = (4.0 / 3.0) * s_inv, y_ym = -(1.0 / 3.0) * s_inv;
    a.block(0, 0, n, n) = (4.0 / 3.0) * id + (2.0 / 3.0) * y_z0;
    a.block(0, n, n, n) = (2.0 / 3.0) * y_y0;
    a.block(0, 2 * n, n, n) = -(1.0 / 3.0) * id + (2.0 / 3.0) * y_zm;
    a.block(0, 3 * n, n, n) = (2.0 / 3.0) * y_ym;
    a.block(n, 0, n, n) = y_z0;
    a.block(n, n, n, n) = y_y0;
    a.block(n, 2 * n, n, n) = y_zm;
    a.block(n, 3 * n, n, n) = y_ym;
    a.block(2 * n, 0, n, n) = id;   // z0 and y0 become the history
    a.block(3 * n, n, n, n) = id;
    return a;
  }
  const Eigen::MatrixXd z = h * h * k;   // h^2 K' (1)
  Eigen::MatrixXd a(2 * n, 2 * n);
  if (integrator == Integrator::kPaper) {
    // y1 = (I - h C') y0 - h^2 K' z0; z1 = z0 + y1.
    const Eigen::MatrixXd y = id - h * c;
    a.topLeftCorner(n, n) = id - z;
    a.topRightCorner(n, n) = y;
    a.bottomLeftCorner(n, n) = -z;
    a.bottomRightCorner(n, n) = y;
  } else {
    // S y1 = y0 - h^2 K' z0; z1 = z0 + y1. S = I + h C' + h^2 K' is symmetric positive definite
    // (I plus two positive semi-definite terms): Cholesky.
    const Eigen::LLT<Eigen::MatrixXd> s(id + h * c + z);
    const Eigen::MatrixXd s_inv = s.solve(id);
    const Eigen::MatrixXd s_inv_z = s.solve(z);
    a.topLeftCorner(n, n) = id - s_inv_z;
    a.topRightCorner(n, n) = s_inv;
    a.bottomLeftCorner(n, n) = -s_inv_z;
    a.bottomRightCorner(n, n) = s_inv;
  }
  return a;
}

double spectral_radius(const Eigen::MatrixXd& map) {
  if (map.size() == 0) return 0.0;
  if (!map.allFinite()) return std::numeric_limits<double>::infinity();
  const Eigen::EigenSolver<Eigen::MatrixXd> solver(map, /*computeEigenvectors=*/false);
  double radius = 0.0;
  for (Eigen::Index i = 0; i < solver.eigenvalues().size(); ++i) radius = std::max(radius, std::abs(solver.eigenvalues()[i]));
  return radius;
}

double paper_radius_1d(double k_over_m, double c_over_m, double h) {
  const double a = h * h * k_over_m, b = h * c_over_m;
  const double trace = 2.0 - a - b, det = 1.0 - b;
  const double disc = 0.25 * trace * trace - det;
  if (disc < 0.0) return std::sqrt(det);   // a complex pair: |lambda|^2 = det
  const double root = std::sqrt(disc);
  return std::max(std::abs(0.5 * trace + root), std::abs(0.5 * trace - root));
}

}  // namespace graspsim
