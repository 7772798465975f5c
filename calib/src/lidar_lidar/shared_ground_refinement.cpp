#include "rigcal/calib/lidar_lidar/shared_ground_refinement.hpp"

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <iomanip>
#include <optional>
#include <sstream>
#include <vector>

#include "rigcal/calib/base_lidar/ground_plane.hpp"
#include "rigcal/registration/target.hpp"
#include "rigcal/registration/voxel_grid.hpp"
#include "rigcal/core/text_format.hpp"
#include "scan_points.hpp"

namespace rigcal::calib {
namespace {

using detail::finitePoints;

// m: a plane with this many points further below it is not the floor (noise and a 2.5 cm fit band stay
// well inside)
constexpr double kUnderFloor = 0.10;

struct Floor {
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();  // unit, along the expected up
  double d = 0.0;                                     // normal·p + d = 0
  std::size_t points = 0;
};

// Total least squares through the points within `band` of the plane (its smallest-variance direction).
bool refitPlane(const std::vector<Eigen::Vector3d>& pts, double band, Floor& f) {
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  std::size_t n = 0;
  for (const auto& p : pts)
    if (std::abs(f.normal.dot(p) + f.d) <= band) mean += p, ++n;
  if (n < 3) return false;
  mean /= double(n);
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  for (const auto& p : pts)
    if (std::abs(f.normal.dot(p) + f.d) <= band) cov += (p - mean) * (p - mean).transpose();
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(cov);
  Eigen::Vector3d normal = solver.eigenvectors().col(0);
  if (!normal.allFinite()) return false;
  if (normal.dot(f.normal) < 0) normal = -normal;
  f.normal = normal;
  f.d = -normal.dot(mean);
  f.points = n;
  return true;
}

// RANSAC (on at most 20000 of the points, evenly strided) then least-squares refits on all of them.
std::optional<Floor> largestPlane(const std::vector<Eigen::Vector3d>& below, const Eigen::Vector3d& up,
                                  const SharedGroundSettings& s, std::string* why) {
  std::vector<Eigen::Vector3d> sample;
  const std::size_t stride = std::max<std::size_t>(1, below.size() / 20000);
  for (std::size_t k = 0; k < below.size(); k += stride) sample.push_back(below[k]);
  GroundPlaneSettings gs;
  gs.max_inlier_distance = s.ransac_inlier_distance;
  gs.max_iterations = 1000;
  gs.min_plane_points = int(s.min_floor_points / stride);
  gs.min_plane_points_percentage = 10.0;
  gs.max_cos_distance = 1.0 - std::cos(deg2rad(s.max_up_deviation_deg));
  const auto ground = findGroundPlane(sample, up, gs);
  if (!ground.plane) {
    *why = ground.failure.substr(0, ground.failure.find(';'));
    return std::nullopt;
  }
  Floor f{ground.plane->normal, ground.plane->d, 0};
  if (!refitPlane(below, s.ransac_inlier_distance, f)) return std::nullopt;
  for (int k = 0; k < 3; ++k)
    if (!refitPlane(below, s.refit_inlier_distance, f)) return std::nullopt;
  if (f.points < s.min_floor_points) {
    *why = "only " + std::to_string(f.points) + " floor points";
    return std::nullopt;
  }
  return f;
}

// The floor under a sensor, in its own frame: the lowest large near-horizontal plane well below it.
std::optional<Floor> fitFloor(const std::vector<Eigen::Vector3d>& points, const Eigen::Vector3d& up,
                              const SharedGroundSettings& s, std::string* why) {
  std::vector<Eigen::Vector3d> below;  // candidates, then what lies under the last plane found
  for (const auto& p : points)
    if (up.dot(p) < -s.min_below_sensor && p.norm() < s.max_floor_range) below.push_back(p);
  if (below.size() < s.min_floor_points) {
    *why = std::to_string(below.size()) + " points below the sensor (need " + std::to_string(s.min_floor_points) + ")";
    return std::nullopt;
  }
  // The largest near-horizontal plane may be crate tops or a shelf: while enough points lie well below
  // the plane found, it is not the floor, and the search goes on among those points.
  for (int round = 0; round < 4; ++round) {
    auto f = largestPlane(below, up, s, why);
    if (!f) return std::nullopt;
    std::vector<Eigen::Vector3d> under;
    for (const auto& p : below)
      if (f->normal.dot(p) + f->d < -kUnderFloor) under.push_back(p);
    if (under.size() < std::max<std::size_t>(s.min_floor_points, f->points / 10)) return f;
    below = std::move(under);
  }
  *why = "every plane found had another one under it";
  return std::nullopt;
}


}  // namespace

struct SharedGroundReference::Impl {
  std::optional<Floor> floor;
  std::string note;  // why there is no reference
  std::optional<registration::Target> structure;
};

SharedGroundReference::SharedGroundReference(const Scan& target_scan, const Eigen::Vector3d& up_target,
                                             const SharedGroundSettings& s)
    : impl_(std::make_unique<Impl>()), settings_(s) {
  const auto t0 = std::chrono::steady_clock::now();
  const auto target = finitePoints(target_scan);
  std::string why;
  impl_->floor = fitFloor(target, up_target.normalized(), s, &why);
  if (!impl_->floor) {
    impl_->note = "no floor in the target cloud (" + why + ")";
  } else {
    const Floor& f = *impl_->floor;
    registration::PointCloud structure;
    for (const auto& p : target)
      if (f.normal.dot(p) + f.d > s.refit_inlier_distance * 2) structure.add(p.x(), p.y(), p.z());
    structure = registration::voxelDownsample(structure, s.structure_voxel);
    if (structure.size() < 100) {
      impl_->note = "too little structure above the target's floor (" + std::to_string(structure.size()) + " voxels)";
      impl_->floor.reset();
    } else {
      registration::TargetOptions to;
      to.normals_and_covariances = true;
      to.num_threads = 2;
      impl_->structure.emplace(std::move(structure), to);
    }
  }
  build_seconds_ = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

SharedGroundReference::~SharedGroundReference() = default;

bool SharedGroundReference::ok() const { return impl_->floor.has_value(); }

SharedGroundRefinement SharedGroundReference::refine(const Scan& source_scan, const Pose& T_in) const {
  const SharedGroundSettings& s = settings_;
  const auto t0 = std::chrono::steady_clock::now();
  SharedGroundRefinement out;
  out.T_target_source = T_in;
  const auto finish = [&](std::string note) {
    out.note = std::move(note);
    out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    return out;
  };
  if (!impl_->floor) return finish(impl_->note);
  const Floor& ft = *impl_->floor;
  const auto source = finitePoints(source_scan);
  const Eigen::Matrix3d R_in = T_in.linear();
  std::string why;
  const auto fs = fitFloor(source, R_in.transpose() * ft.normal, s, &why);
  if (!fs) return finish("no floor in the source cloud (" + why + ")");
  out.target_floor_points = ft.points;
  out.source_floor_points = fs->points;
  // 1. Tilt and height: the source's floor onto the target's (rotating about the source's origin).
  const Eigen::Vector3d n = ft.normal;
  out.floor_normal = n;
  Eigen::Matrix3d R = Eigen::Quaterniond::FromTwoVectors(R_in * fs->normal, n).toRotationMatrix() * R_in;
  Eigen::Vector3d t = T_in.translation() + (fs->d - ft.d - n.dot(T_in.translation())) * n;

  // 2. Yaw about the floor normal and translation along the floor: ICP over what stands on the floor.
  Eigen::Vector3d e1 = Eigen::Vector3d::UnitX() - n.x() * n;
  if (e1.norm() < 1e-3) e1 = Eigen::Vector3d::UnitY() - n.y() * n;
  e1.normalize();
  const Eigen::Vector3d e2 = n.cross(e1);
  registration::PointCloud source_structure;
  for (const auto& p : source)
    if (fs->normal.dot(p) + fs->d > s.off_floor_height) source_structure.add(p.x(), p.y(), p.z());
  source_structure = registration::voxelDownsample(source_structure, s.structure_voxel);
  if (source_structure.size() < 100)
    return finish("too little structure above the source's floor (" + std::to_string(source_structure.size()) +
                  " voxels)");
  const registration::Target& tgt = *impl_->structure;
  const auto& tp = tgt.cloud().points;
  constexpr double kHuber = 0.02;  // m: residuals beyond this weigh less (edges, what one lidar sees only)
  std::size_t matches = 0;
  for (double dist = s.max_correspondence; dist >= s.min_correspondence * 0.999; dist /= 2) {
    for (int it = 0; it < s.max_iterations / 3; ++it) {
      Eigen::Matrix3d H = Eigen::Matrix3d::Zero();
      Eigen::Vector3d g = Eigen::Vector3d::Zero();
      matches = 0;
      for (const auto& ps : source_structure.points) {
        const Eigen::Vector3d q = R * ps.head<3>() + t;
        registration::Neighbor nb;
        if (!tgt.tree().nearest(q.homogeneous(), dist * dist, &nb)) continue;
        const Eigen::Vector3d m = tgt.normal(nb.index);
        if (m.squaredNorm() < 0.5) continue;  // no normal there
        const double r = m.dot(q - tp[nb.index].head<3>());
        const Eigen::Vector3d J(m.dot(n.cross(q - t)), m.dot(e1), m.dot(e2));
        const double w = std::abs(r) <= kHuber ? 1.0 : kHuber / std::abs(r);
        H += w * J * J.transpose();
        g += w * J * r;
        ++matches;
      }
      if (matches < 50) return finish("too few structure matches (" + std::to_string(matches) + ")");
      // Gauss-Newton step in the directions the structure constrains; the others stay where they are.
      const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(H);
      const double largest = eig.eigenvalues().maxCoeff();
      Eigen::Vector3d delta = Eigen::Vector3d::Zero();
      for (int k = 0; k < 3; ++k) {
        const double l = eig.eigenvalues()(k);
        if (l > s.min_information_share * largest && l > 0)
          delta -= eig.eigenvectors().col(k) * (eig.eigenvectors().col(k).dot(g) / l);
      }
      R = Eigen::AngleAxisd(delta(0), n).toRotationMatrix() * R;
      t += delta(1) * e1 + delta(2) * e2;
      if (std::abs(delta(0)) < 1e-7 && std::hypot(delta(1), delta(2)) < 1e-6) break;
    }
  }
  out.matches = matches;

  Pose T = Pose::Identity();
  T.linear() = R;
  T.translation() = t;
  const Eigen::Vector3d dt = t - T_in.translation();
  out.height_correction_m = n.dot(dt);
  out.planar_correction_m = (dt - n.dot(dt) * n).norm();
  const Eigen::Matrix3d dR = R * R_in.transpose();
  out.tilt_correction_deg = rad2deg(std::acos(std::clamp((dR * n).dot(n), -1.0, 1.0)));
  const Eigen::AngleAxisd total(dR);
  out.yaw_correction_deg = rad2deg(total.angle() * total.axis().dot(n));
  const double correction_deg = rad2deg(total.angle());
  if (dt.norm() > s.max_correction_m || correction_deg > s.max_correction_deg)
    return finish("the floor-based correction (" + fixed(100 * dt.norm(), 1) + " cm, " + fixed(correction_deg, 2) +
                  " deg) is larger than a refinement should be: a floor was likely mistaken; kept the ensemble's");
  out.T_target_source = T;
  out.applied = true;
  return finish("");
}

}  // namespace rigcal::calib
