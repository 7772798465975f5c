#include "rigcal/calib/base_lidar/ground_plane.hpp"

#include <Eigen/Eigenvalues>

#include <cmath>
#include <sstream>

namespace rigcal::calib {

namespace {

// splitmix64: tiny, fast and identical on every platform (std distributions are not).
struct SplitMix64 {
  std::uint64_t state;
  std::uint64_t next() {
    std::uint64_t z = (state += 0x9e3779b97f4a7c15ULL);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    return z ^ (z >> 31);
  }
  std::size_t below(std::size_t n) { return std::size_t(next() % n); }
};

// Least-squares plane through the given points (smallest-eigenvalue direction of their covariance).
bool fitPlane(const std::vector<Eigen::Vector3d>& pts, const std::vector<std::size_t>& idx,
              Eigen::Vector3d& normal, double& d) {
  if (idx.size() < 3) return false;
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (std::size_t i : idx) mean += pts[i];
  mean /= double(idx.size());
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  for (std::size_t i : idx) cov += (pts[i] - mean) * (pts[i] - mean).transpose();
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(cov);
  normal = solver.eigenvectors().col(0);
  d = -normal.dot(mean);
  return normal.allFinite();
}

}  // namespace

GroundPlaneResult findGroundPlane(const std::vector<Eigen::Vector3d>& points, const Eigen::Vector3d& up,
                                  const GroundPlaneSettings& s) {
  GroundPlaneResult result;
  std::vector<std::size_t> remaining;
  remaining.reserve(points.size());
  for (std::size_t i = 0; i < points.size(); ++i)
    if (points[i].allFinite()) remaining.push_back(i);
  const std::size_t total = remaining.size();
  SplitMix64 rng{s.seed};
  std::ostringstream why;

  for (int attempt = 1; attempt <= s.max_attempts; ++attempt) {
    if (remaining.size() < 3 || remaining.size() < std::size_t(s.min_plane_points)) {
      why << "attempt " << attempt << ": only " << remaining.size() << " points left (need "
          << s.min_plane_points << ")";
      break;
    }
    // RANSAC: best three-point plane by inlier count.
    Eigen::Vector3d best_n = up;
    double best_d = 0;
    std::size_t best_count = 0;
    for (int it = 0; it < s.max_iterations; ++it) {
      const Eigen::Vector3d& a = points[remaining[rng.below(remaining.size())]];
      const Eigen::Vector3d& b = points[remaining[rng.below(remaining.size())]];
      const Eigen::Vector3d& c = points[remaining[rng.below(remaining.size())]];
      Eigen::Vector3d n = (b - a).cross(c - a);
      if (n.norm() < 1e-9) continue;
      n.normalize();
      const double d = -n.dot(a);
      std::size_t count = 0;
      for (std::size_t i : remaining) count += std::abs(n.dot(points[i]) + d) <= s.max_inlier_distance;
      if (count > best_count) {
        best_count = count;
        best_n = n;
        best_d = d;
      }
    }
    std::vector<std::size_t> inliers;
    for (std::size_t i : remaining)
      if (std::abs(best_n.dot(points[i]) + best_d) <= s.max_inlier_distance) inliers.push_back(i);
    // Refine on the inliers, then re-collect them against the refined plane.
    Eigen::Vector3d n = best_n;
    double d = best_d;
    if (fitPlane(points, inliers, n, d)) {
      inliers.clear();
      for (std::size_t i : remaining)
        if (std::abs(n.dot(points[i]) + d) <= s.max_inlier_distance) inliers.push_back(i);
    }
    if (n.dot(up) < 0) {  // orient upward: upstream leaves the sign to chance
      n = -n;
      d = -d;
    }
    const double percentage = 100.0 * double(inliers.size()) / double(total);
    const double cos_distance = 1.0 - std::abs(n.dot(up));
    if (int(inliers.size()) > s.min_plane_points && percentage > s.min_plane_points_percentage &&
        cos_distance < s.max_cos_distance) {
      result.plane = GroundPlane{n, d, inliers.size(), percentage, attempt};
      return result;
    }
    why << "attempt " << attempt << ": plane with " << inliers.size() << " inliers (" << percentage
        << "%), 1−|n·up| = " << cos_distance << " rejected; ";
    // Not the ground: remove its points and look again.
    std::vector<std::size_t> rest;
    std::size_t k = 0;
    for (std::size_t i : remaining) {
      if (k < inliers.size() && inliers[k] == i)
        ++k;
      else
        rest.push_back(i);
    }
    if (rest.size() == remaining.size()) break;
    remaining.swap(rest);
  }
  result.failure = "no ground plane: " + why.str();
  return result;
}

}  // namespace rigcal::calib
