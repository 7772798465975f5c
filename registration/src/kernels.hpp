#pragma once
// Private: per-match contributions to the Gauss–Newton system, written out by hand because they run
// millions of times per second and Eigen's generic 3x3/6x6 products leave much of the work on the table.
//
// All methods perturb the pose on the left, in the target frame: T ← exp(δ)·T with δ = (ρ, ω). For a
// transformed source point q = T·p that gives dq/dδ = J = [I, −[q]×]. Only the upper triangle of H is
// accumulated; mirrorUpper() completes it once per chunk.
#include <algorithm>
#include <cmath>

#include <Eigen/Core>

#include "rigcal/core/pose.hpp"

namespace rigcal::registration::detail {

using Matrix6d = Eigen::Matrix<double, 6, 6>;

/// H += Jᵀ·W·J (W symmetric), upper triangle.
inline void addWeightedHessian(const Eigen::Matrix3d& W, const Eigen::Vector3d& q, Matrix6d& H) {
  const double x = q.x(), y = q.y(), z = q.z();
  // V = W·[q]×, column by column.
  const Eigen::Vector3d v0 = W.col(1) * z - W.col(2) * y;
  const Eigen::Vector3d v1 = W.col(2) * x - W.col(0) * z;
  const Eigen::Vector3d v2 = W.col(0) * y - W.col(1) * x;
  H(0, 0) += W(0, 0);
  H(0, 1) += W(0, 1);
  H(0, 2) += W(0, 2);
  H(1, 1) += W(1, 1);
  H(1, 2) += W(1, 2);
  H(2, 2) += W(2, 2);
  H.block<3, 1>(0, 3) -= v0;
  H.block<3, 1>(0, 4) -= v1;
  H.block<3, 1>(0, 5) -= v2;
  // [q]×ᵀ·V, upper triangle: row i of [q]×ᵀ is (0, z, −y), (−z, 0, x), (y, −x, 0).
  H(3, 3) += z * v0.y() - y * v0.z();
  H(3, 4) += z * v1.y() - y * v1.z();
  H(3, 5) += z * v2.y() - y * v2.z();
  H(4, 4) += x * v1.z() - z * v1.x();
  H(4, 5) += x * v2.z() - z * v2.x();
  H(5, 5) += y * v2.x() - x * v2.y();
}

/// b += Jᵀ·u.
inline void addGradient(const Eigen::Vector3d& q, const Eigen::Vector3d& u, Vector6d& b) {
  b.head<3>() += u;
  b.tail<3>() += q.cross(u);
}

/// One scalar residual e with gradient row j = [n, q × n]: H += jᵀj, b += jᵀe (point-to-plane).
inline void addRow(const Vector6d& j, double e, Matrix6d& H, Vector6d& b) {
  for (int c = 0; c < 6; ++c) {
    for (int r = 0; r <= c; ++r) H(r, c) += j[r] * j[c];
  }
  b += j * e;
}

/// Point-to-point sums: J = [I, −[q]×] has JᵀJ = [[I, −[q]×], [[q]×, |q|²I − qqᵀ]], so a chunk only
/// needs the count, Σq, Σ|q|² and Σqqᵀ; turned into H by finish().
struct PointToPointSums {
  double n = 0.0;
  Eigen::Vector3d sum_q = Eigen::Vector3d::Zero();
  double sum_qq = 0.0;
  Eigen::Matrix3d outer = Eigen::Matrix3d::Zero();

  void add(const Eigen::Vector3d& q) {
    n += 1.0;
    sum_q += q;
    sum_qq += q.squaredNorm();
    outer.noalias() += q * q.transpose();
  }
  void finish(Matrix6d& H) const {
    H.topLeftCorner<3, 3>() += n * Eigen::Matrix3d::Identity();
    H.topRightCorner<3, 3>() -= skew(sum_q);
    H.bottomRightCorner<3, 3>() += sum_qq * Eigen::Matrix3d::Identity() - outer;
  }
};

inline void mirrorUpper(Matrix6d& H) { H.triangularView<Eigen::StrictlyLower>() = H.transpose(); }

/// A symmetric 3x3 by its upper triangle: half the memory of a Matrix3d (GICP's weights, covariances).
struct Sym3 {
  double xx = 0, xy = 0, xz = 0, yy = 0, yz = 0, zz = 0;

  static Sym3 upperOf(const Eigen::Matrix4d& C) {
    return {C(0, 0), C(0, 1), C(0, 2), C(1, 1), C(1, 2), C(2, 2)};
  }
  /// From 6 consecutive doubles or floats (Target::covarianceUpperFloat()).
  static Sym3 load(const double* u) { return {u[0], u[1], u[2], u[3], u[4], u[5]}; }
  static Sym3 load(const float* u) { return {u[0], u[1], u[2], u[3], u[4], u[5]}; }
  [[nodiscard]] Eigen::Vector3d times(const Eigen::Vector3d& v) const {
    return {xx * v.x() + xy * v.y() + xz * v.z(), xy * v.x() + yy * v.y() + yz * v.z(),
            xz * v.x() + yz * v.y() + zz * v.z()};
  }
};

/// C_t + R·C_s·Rᵀ, written out: R·C_s (27 products), its upper triangle times Rᵀ (18). About half the
/// instructions of the same with generic Eigen 3x3 products. (A rank-one source needs none of it: see
/// GicpBatch.)
inline Sym3 fusedCovariance(const Eigen::Matrix3d& R, const Sym3& s, const Sym3& t) {
  double a[3][3];
  for (int i = 0; i < 3; ++i) {
    const double r0 = R(i, 0), r1 = R(i, 1), r2 = R(i, 2);
    a[i][0] = r0 * s.xx + r1 * s.xy + r2 * s.xz;
    a[i][1] = r0 * s.xy + r1 * s.yy + r2 * s.yz;
    a[i][2] = r0 * s.xz + r1 * s.yz + r2 * s.zz;
  }
  auto f = [&](int i, int j) { return a[i][0] * R(j, 0) + a[i][1] * R(j, 1) + a[i][2] * R(j, 2); };
  return {f(0, 0) + t.xx, f(0, 1) + t.xy, f(0, 2) + t.xz, f(1, 1) + t.yy, f(1, 2) + t.yz, f(2, 2) + t.zz};
}

/// v with C = I − v·vᵀ (v = 0 for C = I), if C has that form to rounding; false otherwise.
inline bool rankOneFromIdentity(const Sym3& c, Eigen::Vector3d* v) {
  const Sym3 m{1.0 - c.xx, -c.xy, -c.xz, 1.0 - c.yy, -c.yz, 1.0 - c.zz};
  const double d[3] = {m.xx, m.yy, m.zz};
  const int a = d[0] >= d[1] ? (d[0] >= d[2] ? 0 : 2) : (d[1] >= d[2] ? 1 : 2);
  Eigen::Vector3d out = Eigen::Vector3d::Zero();
  if (d[a] > 0.0) {
    const double s = 1.0 / std::sqrt(d[a]);
    const Eigen::Vector3d col = a == 0 ? Eigen::Vector3d(m.xx, m.xy, m.xz)
                                       : (a == 1 ? Eigen::Vector3d(m.xy, m.yy, m.yz) : Eigen::Vector3d(m.xz, m.yz, m.zz));
    out = col * s;
  }
  constexpr double kTolerance = 1e-12;
  const double err = std::max({std::abs(m.xx - out.x() * out.x()), std::abs(m.xy - out.x() * out.y()),
                               std::abs(m.xz - out.x() * out.z()), std::abs(m.yy - out.y() * out.y()),
                               std::abs(m.yz - out.y() * out.z()), std::abs(m.zz - out.z() * out.z())});
  if (!(err <= kTolerance)) return false;
  *v = out;
  return true;
}

}  // namespace rigcal::registration::detail
