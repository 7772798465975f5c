#include "rigcal/calib/lidar_lidar/cloud_pair_global_search.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <unordered_map>

#include <Eigen/Geometry>

#include "rigcal/calib/base_lidar/ground_plane.hpp"
#include "rigcal/registration/voxel_grid.hpp"

namespace rigcal::calib {
namespace {

std::vector<Eigen::Vector3d> voxelised(const std::vector<Eigen::Vector3d>& points, double leaf) {
  const auto cloud = registration::voxelDownsample(registration::fromPoints(points), leaf);
  std::vector<Eigen::Vector3d> out;
  out.reserve(cloud.size());
  for (const auto& p : cloud.points) out.push_back(p.head<3>());
  return out;
}

// The target's distance to its nearest point, truncated at d_max, sampled at the centres of cubic cells:
// one hash lookup scores a point. Cells farther than d_max from every point are absent (= d_max).
class DistanceGrid {
 public:
  DistanceGrid(const std::vector<Eigen::Vector3d>& points, double cell, double max_distance)
      : cell_(cell), max_sq_(max_distance * max_distance) {
    const int r = int(std::ceil(max_distance / cell));
    cells_.reserve(points.size() * std::size_t(2 * r + 1) * std::size_t(2 * r + 1) * 2);
    for (const auto& p : points) {
      const Eigen::Vector3i c = cellOf(p);
      for (int dx = -r; dx <= r; ++dx)
        for (int dy = -r; dy <= r; ++dy)
          for (int dz = -r; dz <= r; ++dz) {
            const Eigen::Vector3i k = c + Eigen::Vector3i(dx, dy, dz);
            const double d2 = (centre(k) - p).squaredNorm();
            if (d2 >= max_sq_) continue;
            auto [it, fresh] = cells_.try_emplace(key(k), float(d2));
            if (!fresh && float(d2) < it->second) it->second = float(d2);
          }
    }
  }
  /// min(d², d_max²) of q.
  [[nodiscard]] double sqDistance(const Eigen::Vector3d& q) const {
    const auto it = cells_.find(key(cellOf(q)));
    return it == cells_.end() ? max_sq_ : double(it->second);
  }
  [[nodiscard]] double maxSq() const { return max_sq_; }

 private:
  [[nodiscard]] Eigen::Vector3i cellOf(const Eigen::Vector3d& p) const {
    return (p / cell_).array().floor().cast<int>();
  }
  [[nodiscard]] Eigen::Vector3d centre(const Eigen::Vector3i& k) const {
    return (k.cast<double>().array() + 0.5).matrix() * cell_;
  }
  static std::uint64_t key(const Eigen::Vector3i& k) {
    // 21 bits per axis: ±1 million cells (±250 km at 0.25 m) is far beyond any lidar cloud.
    const auto u = [](int v) { return std::uint64_t(std::uint32_t(v + (1 << 20)) & 0x1FFFFFU); };
    return u(k.x()) | u(k.y()) << 21 | u(k.z()) << 42;
  }
  double cell_, max_sq_;
  std::unordered_map<std::uint64_t, float> cells_;
};

struct Candidate {
  double yaw = 0, a = 0, b = 0;  // rad about the ground normal; m along e1, e2
  double score = 0, inliers = 0;
};

// The search's frame: yaw turns the levelled source about the normal n through its origin t0, (a, b) moves
// it along the ground. T(yaw, a, b) = [Rn(yaw) R0 | t0 + a e1 + b e2].
struct SearchFrame {
  Eigen::Matrix3d R0 = Eigen::Matrix3d::Identity();
  Eigen::Vector3d t0 = Eigen::Vector3d::Zero();
  Eigen::Vector3d n = Eigen::Vector3d::UnitZ(), e1 = Eigen::Vector3d::UnitX(), e2 = Eigen::Vector3d::UnitY();

  [[nodiscard]] Pose pose(const Candidate& c) const {
    Pose T = Pose::Identity();
    T.linear() = Eigen::AngleAxisd(c.yaw, n).toRotationMatrix() * R0;
    T.translation() = t0 + c.a * e1 + c.b * e2;
    return T;
  }
};

class Scorer {
 public:
  Scorer(const DistanceGrid& grid, const std::vector<Eigen::Vector3d>& source, const SearchFrame& frame)
      : grid_(grid), source_(source), frame_(frame) {}

  /// Scores every (a, b) on the grid at one yaw, appending to `out`.
  void scanYaw(double yaw, const std::vector<double>& as, const std::vector<double>& bs, std::vector<Candidate>& out) {
    const Eigen::Matrix3d R = Eigen::AngleAxisd(yaw, frame_.n).toRotationMatrix() * frame_.R0;
    placed_.resize(source_.size());
    for (std::size_t i = 0; i < source_.size(); ++i) placed_[i] = R * source_[i] + frame_.t0;
    for (const double a : as)
      for (const double b : bs) {
        const Eigen::Vector3d shift = a * frame_.e1 + b * frame_.e2;
        double sum = 0;
        std::size_t in = 0;
        for (const auto& q : placed_) {
          const double d2 = grid_.sqDistance(q + shift);
          sum += d2;
          in += d2 < grid_.maxSq() ? 1 : 0;
        }
        const double n = double(std::max<std::size_t>(placed_.size(), 1));
        out.push_back({yaw, a, b, sum / n, double(in) / n});
        ++scored;
      }
  }
  std::size_t scored = 0;

 private:
  const DistanceGrid& grid_;
  const std::vector<Eigen::Vector3d>& source_;
  const SearchFrame& frame_;
  std::vector<Eigen::Vector3d> placed_;
};

std::vector<double> steps(double centre, double range, double step) {
  std::vector<double> v;
  const int n = int(std::floor(range / step + 1e-9));
  for (int i = -n; i <= n; ++i) v.push_back(centre + i * step);
  return v;
}

bool sameBasin(const Candidate& x, const Candidate& y, const GlobalSearchSettings& s) {
  const double dyaw = std::abs(std::remainder(x.yaw - y.yaw, 2 * M_PI));
  return std::hypot(x.a - y.a, x.b - y.b) < s.basin_separation_m && dyaw < deg2rad(s.basin_separation_deg);
}

}  // namespace

GlobalSearchResult globalSearch(const std::vector<Eigen::Vector3d>& target, const std::vector<Eigen::Vector3d>& source,
                                const Pose& guess, const GlobalSearchSettings& s) {
  const auto t_start = std::chrono::steady_clock::now();
  GlobalSearchResult out;
  const auto tgt = voxelised(target, s.voxel);
  auto src = voxelised(source, s.voxel);

  // 1. Ground planes: the source ground normal onto the target's, the heights matched.
  SearchFrame f;
  f.R0 = guess.linear();
  f.t0 = guess.translation();
  f.n = Eigen::Vector3d::UnitZ();
  GroundPlaneSettings gs;
  gs.max_inlier_distance = s.ground_inlier_distance;
  gs.min_plane_points = 100;
  gs.min_plane_points_percentage = 5.0;  // on 0.25 m voxels the ground is a smaller share than in the scan (VLS-128: 9 %)
  gs.max_cos_distance = 0.5;  // within 60° of the target's z
  const auto tg = findGroundPlane(tgt, Eigen::Vector3d::UnitZ(), gs);
  gs.max_cos_distance = 1.0 - std::cos(deg2rad(75.0));  // the guess may be up to ~60° off
  const auto sg = findGroundPlane(src, guess.linear().transpose() * Eigen::Vector3d::UnitZ(), gs);
  if (tg.plane && sg.plane) {
    const Eigen::Vector3d nt = tg.plane->normal, ns = sg.plane->normal;
    f.n = nt;
    f.R0 = Eigen::Quaterniond::FromTwoVectors(guess.linear() * ns, nt).toRotationMatrix() * guess.linear();
    // Source origin's height above the target ground (n_t·t + d_t) must equal its own (d_s).
    f.t0 = guess.translation() + (sg.plane->d - tg.plane->d - nt.dot(guess.translation())) * nt;
    out.ground_used = true;
    // Ground points say nothing about yaw or the ground-plane translation: leave them out of the search.
    std::vector<Eigen::Vector3d> above;
    for (const auto& p : src)
      if (std::abs(ns.dot(p) + sg.plane->d) > 2 * s.ground_inlier_distance) above.push_back(p);
    if (above.size() >= 50) src = std::move(above);
  } else {
    // The first attempt's reason is enough for one line (the RANSAC failure lists every attempt).
    const std::string why = tg.plane ? sg.failure : tg.failure;
    out.ground_note = std::string(tg.plane ? "source" : "target") + " ground plane not found (" +
                      why.substr(0, why.find(';')) + "): roll, pitch and height kept from the guess";
  }
  Eigen::Vector3d x_axis = Eigen::Vector3d::UnitX() - f.n.x() * f.n;
  if (x_axis.norm() < 1e-3) x_axis = Eigen::Vector3d::UnitY() - f.n.y() * f.n;
  f.e1 = x_axis.normalized();
  f.e2 = f.n.cross(f.e1);
  std::erase_if(src, [&](const Eigen::Vector3d& p) { return p.norm() > s.max_source_range; });
  if (src.size() > s.max_source_points) {
    std::vector<Eigen::Vector3d> picked;
    const double stride = double(src.size()) / double(s.max_source_points);
    for (std::size_t k = 0; k < s.max_source_points; ++k) picked.push_back(src[std::size_t(double(k) * stride)]);
    src = std::move(picked);
  }

  // 2. Coarse grid over yaw and the ground-plane translation.
  const DistanceGrid grid(tgt, s.voxel, s.max_distance);
  Scorer scorer(grid, src, f);
  std::vector<Candidate> coarse;
  const auto as = steps(0.0, s.translation_range, s.translation_step);
  std::vector<double> yaws = steps(0.0, deg2rad(s.yaw_range_deg), deg2rad(s.yaw_step_deg));
  // A full turn would score ±180° twice: the same pose.
  if (yaws.size() > 1 && yaws.back() - yaws.front() >= 2 * M_PI - 1e-9) yaws.pop_back();
  for (const double yaw : yaws) scorer.scanYaw(yaw, as, as, coarse);
  std::sort(coarse.begin(), coarse.end(), [](const Candidate& x, const Candidate& y) { return x.score < y.score; });

  // 3. The best distinct basins, each refined on a finer grid around it.
  std::vector<Candidate> basins;
  for (const auto& c : coarse) {
    if (basins.size() >= s.basins_refined) break;
    if (std::none_of(basins.begin(), basins.end(), [&](const Candidate& b) { return sameBasin(b, c, s); }))
      basins.push_back(c);
  }
  std::vector<Candidate> refined;
  for (const auto& b : basins) {
    std::vector<Candidate> local;
    const double fine_t = s.translation_step / 3;
    for (const double yaw : steps(b.yaw, deg2rad(s.yaw_step_deg), deg2rad(s.yaw_step_deg) / 3))
      scorer.scanYaw(yaw, steps(b.a, s.translation_step, fine_t), steps(b.b, s.translation_step, fine_t), local);
    refined.push_back(*std::min_element(local.begin(), local.end(),
                                        [](const Candidate& x, const Candidate& y) { return x.score < y.score; }));
  }
  std::sort(refined.begin(), refined.end(), [](const Candidate& x, const Candidate& y) { return x.score < y.score; });
  out.poses_scored = scorer.scored;
  if (!refined.empty()) {
    out.T_target_source = f.pose(refined[0]);
    out.best_score = refined[0].score;
    out.best_inlier_ratio = refined[0].inliers;
    for (std::size_t k = 1; k < refined.size(); ++k)
      if (!sameBasin(refined[0], refined[k], s)) {
        out.second_score = refined[k].score;
        out.second_T_target_source = f.pose(refined[k]);
        break;
      }
  } else {
    out.T_target_source = guess;
  }
  out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t_start).count();
  return out;
}

}  // namespace rigcal::calib
