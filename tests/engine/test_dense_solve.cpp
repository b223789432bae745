// The implicit step's linear solves (engine/dense_solve.hpp) on the systems the step builds:
// one body, M + h sum J^T G J, J = [I, -S(r)], with points held (G isotropic, or with k_t != k_n)
// and sliding (G = g_n (n + mu t) n^T, unsymmetric).
#include <catch2/catch.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <random>

#include "graspsim/engine/dense_solve.hpp"

using namespace graspsim;

namespace {

using Mat6 = Eigen::Matrix<double, 6, 6, Eigen::RowMajor>;
using Vec6 = Eigen::Matrix<double, 6, 1>;

enum class PointMode { kHeld, kHeldAnisotropic, kSliding };

// A body of mass `mass` (kg), a unit cube's inertia scaled with it, turned at random, with four
// points at random on its surface (0.05 m half size), each with normal response g_n = h k + c
// (k = `stiffness` N/m, c = 2 sqrt(k m)) and the mode given; the step's matrix for step h.
Mat6 one_body_matrix(std::mt19937_64& rng, double mass, double stiffness, double h, PointMode mode) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const Vec3 axis = Vec3(u(rng), u(rng), u(rng)).normalized();
  const Mat3 R = Eigen::AngleAxisd(3.0 * u(rng), axis).toRotationMatrix();
  const Vec3 inertia = mass * Vec3(0.0017, 0.0021, 0.0013);   // kg m^2, principal
  Mat6 a = Mat6::Zero();
  a.block<3, 3>(0, 0) = mass * Mat3::Identity();
  a.block<3, 3>(3, 3) = R * inertia.asDiagonal() * R.transpose();
  const double damping = 2.0 * std::sqrt(stiffness * mass);
  const double g_n = h * stiffness + damping;
  for (int i = 0; i < 4; ++i) {
    const Vec3 r = 0.05 * Vec3(u(rng), u(rng), u(rng));
    const Vec3 n = Vec3(u(rng), u(rng), 1.0).normalized();
    Mat3 g;
    if (mode == PointMode::kSliding) {
      const Vec3 t = n.unitOrthogonal();
      g = g_n * (n + 0.8 * t) * n.transpose();
    } else {
      const double g_t = mode == PointMode::kHeld ? g_n : 0.3 * g_n;
      g = g_n * n * n.transpose() + g_t * (Mat3::Identity() - n * n.transpose());
    }
    Eigen::Matrix<double, 3, 6> j;
    j << Mat3::Identity(), -skew(r);
    a += h * j.transpose() * g * j;
  }
  return a;
}

// Backward error of x for A x = b: |A x - b| / (|A| |x| + |b|), max norms.
double backward_error(const Mat6& a, const Vec6& x, const Vec6& b) {
  const double scale = a.cwiseAbs().rowwise().sum().maxCoeff() * x.cwiseAbs().maxCoeff() + b.cwiseAbs().maxCoeff();
  return (a * x - b).cwiseAbs().maxCoeff() / scale;
}

}  // namespace

TEST_CASE("one body's block solve and the pivoted elimination both solve the step's system to round-off",
          "[implicit]") {
  // Law: both are direct solves of the same 6x6 system, so each solution's backward error,
  // |A x - b| / (|A| |x| + |b|), is a few ulps (1.1e-16) whatever the conditioning: the
  // tolerance 1e-13 is 900 ulps, for the 6x6 products. A wrong sign or a block in the wrong
  // place in the Schur complement leaves an error of order 1. Swept over stiffness 10 to 1e9
  // N/m (the step's matrix from mass-dominated to contact-dominated, condition numbers to 1e9),
  // mass 0.01 to 10 kg, the paper's three rates, and every mode of point.
  std::mt19937_64 rng(20261126);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  int systems = 0;
  for (double h : {1.0 / 50.0, 1.0 / 500.0, 1.0 / 3000.0}) {
    for (double stiffness : {1e1, 1e3, 1e5, 1e7, 1e9}) {
      for (double mass : {0.01, 0.5, 10.0}) {
        for (PointMode mode : {PointMode::kHeld, PointMode::kHeldAnisotropic, PointMode::kSliding}) {
          const Mat6 a = one_body_matrix(rng, mass, stiffness, h, mode);
          Vec6 b;
          for (int i = 0; i < 6; ++i) b[i] = mass * u(rng);
          Mat6 lu_matrix = a;
          Vec6 x_lu = b, x_block = b;
          dense::lu_solve(lu_matrix.data(), x_lu.data(), 6);
          dense::solve_one_body(a.data(), x_block.data());
          INFO("h " << h << " s, k " << stiffness << " N/m, m " << mass << " kg, mode " << static_cast<int>(mode));
          CHECK(backward_error(a, x_lu, b) < 1e-13);
          CHECK(backward_error(a, x_block, b) < 1e-13);
          ++systems;
        }
      }
    }
  }
  CHECK(systems == 135);
}

TEST_CASE("a singular system leaves the solution non-finite, for the step's divergence check", "[implicit]") {
  // A zero matrix (a body of no mass with no point on it) has no solution: both solves must say
  // so by a non-finite result, never by a finite wrong one.
  const Mat6 zero = Mat6::Zero();
  Mat6 lu_matrix = zero;
  Vec6 x_lu = Vec6::Ones(), x_block = Vec6::Ones();
  dense::lu_solve(lu_matrix.data(), x_lu.data(), 6);
  dense::solve_one_body(zero.data(), x_block.data());
  CHECK_FALSE(x_lu.allFinite());
  CHECK_FALSE(x_block.allFinite());
}
