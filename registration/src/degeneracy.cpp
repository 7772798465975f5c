// How well the matched geometry pins down all six degrees of freedom. Independent of the method's own
// Hessian (point-to-point ICP's is always full rank, even on a plane), it uses surface normals:
// a direction the point-to-plane information matrix cannot see is one the scene lets slide.
#include <algorithm>
#include <cmath>
#include <vector>

#include <Eigen/Eigenvalues>

#include "solver.hpp"

namespace rigcal::registration::detail {

namespace {
constexpr std::size_t kSamples = 1024;  // enough for a stable 6x6 estimate, cheap next to one iteration
constexpr std::size_t kNormalNeighbors = 10;
}  // namespace

double conditioning(std::span<const SourceTarget> pairs, const Pose& T, double max_distance) {
  std::size_t total = 0;
  for (const auto& p : pairs) total += p.source->size();
  if (total == 0) return 0.0;
  const std::size_t stride = std::max<std::size_t>(1, total / kSamples);
  const Eigen::Matrix4d M = T.matrix();
  const double max_sq = max_distance * max_distance;

  std::vector<Eigen::Vector3d> at, normal;
  std::size_t global = 0;
  Neighbor nb[kNormalNeighbors];
  for (const auto& [source, target] : pairs) {
    for (std::size_t i = (stride - global % stride) % stride; i < source->size(); i += stride) {
      const Eigen::Vector4d q = M * source->points[i];
      Neighbor hit;
      if (!target->tree().nearest(q, max_sq, &hit)) continue;
      const Eigen::Vector3d x = target->cloud().points[hit.index].head<3>();
      Eigen::Vector3d n;
      if (target->hasNormals()) {
        n = target->normal(hit.index);
      } else {
        const std::size_t found = target->tree().knn(target->cloud().points[hit.index], kNormalNeighbors, nb);
        if (found < 5) continue;
        Eigen::Vector3d mean = Eigen::Vector3d::Zero();
        for (std::size_t j = 0; j < found; ++j) mean += target->cloud().points[nb[j].index].head<3>();
        mean /= static_cast<double>(found);
        Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
        for (std::size_t j = 0; j < found; ++j) {
          const Eigen::Vector3d d = target->cloud().points[nb[j].index].head<3>() - mean;
          cov.noalias() += d * d.transpose();
        }
        Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig;
        eig.computeDirect(cov);
        n = eig.eigenvectors().col(0);
      }
      if (!(n.squaredNorm() > 0.5)) continue;  // unknown normal
      at.push_back(x);
      normal.push_back(n.normalized());
    }
    global += source->size();
  }
  if (at.size() < 6) return 0.0;

  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  for (const auto& x : at) centre += x;
  centre /= static_cast<double>(at.size());
  double radius_sq = 0.0;
  for (const auto& x : at) radius_sq += (x - centre).squaredNorm();
  const double radius = std::max(std::sqrt(radius_sq / static_cast<double>(at.size())), 1e-3);

  // Rows [n, (x − c) × n / radius]: translation in metres, rotation as the displacement it causes at the
  // cloud's typical radius, so the two halves are comparable.
  Eigen::Matrix<double, 6, 6> info = Eigen::Matrix<double, 6, 6>::Zero();
  for (std::size_t i = 0; i < at.size(); ++i) {
    Eigen::Matrix<double, 6, 1> j;
    j << normal[i], (at[i] - centre).cross(normal[i]) / radius;
    info.noalias() += j * j.transpose();
  }
  info /= static_cast<double>(at.size());
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, 6, 6>> eig(info, Eigen::EigenvaluesOnly);
  const double largest = eig.eigenvalues()(5);
  if (!(largest > 0.0)) return 0.0;
  return std::max(eig.eigenvalues()(0), 0.0) / largest;
}

}  // namespace rigcal::registration::detail
