// The implicit step's dense linear solves: an island's system, and one body's by its blocks.
#pragma once

#include <cmath>
#include <utility>

#include <Eigen/LU>

#include "graspsim/engine/math.hpp"

namespace graspsim::dense {

// Solves A x = b in place by Gaussian elimination with partial pivoting (`a` row-major n x n,
// overwritten; `b` becomes x). The island's matrix M + h (h K + C) is positive definite but for
// sliding points, whose friction force follows their normal force, mu t n^T, which makes it
// unsymmetric; pivoting keeps the elimination backward stable either way. A zero or non-finite
// pivot leaves `b` non-finite, which the step's divergence check sees.
inline void lu_solve(double* a, double* b, int n) {
  for (int j = 0; j < n; ++j) {
    int p = j;
    for (int i = j + 1; i < n; ++i) {
      if (std::abs(a[i * n + j]) > std::abs(a[p * n + j])) p = i;
    }
    if (p != j) {
      for (int k = j; k < n; ++k) std::swap(a[j * n + k], a[p * n + k]);
      std::swap(b[j], b[p]);
    }
    const double pivot = a[j * n + j];
    for (int i = j + 1; i < n; ++i) {
      const double l = a[i * n + j] / pivot;
      if (l == 0.0) continue;
      for (int k = j + 1; k < n; ++k) a[i * n + k] -= l * a[j * n + k];
      b[i] -= l * b[j];
    }
  }
  for (int i = n - 1; i >= 0; --i) {
    double s = b[i];
    for (int k = i + 1; k < n; ++k) s -= a[i * n + k] * b[k];
    b[i] = s / a[i * n + i];
  }
}

// Solves one body's 6x6 system (`a` row-major, read only; `b` becomes x) by its 3x3 blocks
// [[A, B], [C, D]], translation first: y = S^-1 (q - C A^-1 p) with S = D - C A^-1 B, then
// x = A^-1 (p - B y): 2.3 times fewer instructions than lu_solve on 6 unknowns. A is m I plus
// h G for each point on the body, whose eigenvalues are m + h g_n (a sliding point's
// G = g_n (n + mu t) n^T has n . (n + mu t) = 1), so it is never near singular; S is the rotation's
// matrix with the translation eliminated, positive definite where the whole is (every point
// held). A singular or non-finite S leaves `b` non-finite, as lu_solve does.
inline void solve_one_body(const double* a, double* b) {
  const Eigen::Map<const Eigen::Matrix<double, 6, 6, Eigen::RowMajor>> m(a);
  const Mat3 A = m.block<3, 3>(0, 0), B = m.block<3, 3>(0, 3), C = m.block<3, 3>(3, 0), D = m.block<3, 3>(3, 3);
  const Vec3 p(b[0], b[1], b[2]), q(b[3], b[4], b[5]);
  const Mat3 a_inverse = A.inverse();
  const Mat3 c_a_inverse = C * a_inverse;
  const Vec3 y = (D - c_a_inverse * B).inverse() * (q - c_a_inverse * p);
  const Vec3 x = a_inverse * (p - B * y);
  for (int i = 0; i < 3; ++i) {
    b[i] = x[i];
    b[3 + i] = y[i];
  }
}

}  // namespace graspsim::dense
