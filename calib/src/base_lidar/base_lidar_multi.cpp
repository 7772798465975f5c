#include "rigcal/calib/base_lidar/base_lidar_multi.hpp"

#include <algorithm>
#include <cmath>

namespace rigcal::calib {

namespace {
double median(std::vector<double> v) {
  const std::size_t mid = v.size() / 2;
  std::nth_element(v.begin(), v.begin() + std::ptrdiff_t(mid), v.end());
  if (v.size() % 2 == 1) return v[mid];
  const double upper = v[mid];
  return 0.5 * (upper + *std::max_element(v.begin(), v.begin() + std::ptrdiff_t(mid)));
}

// Angles as offsets from a reference, wrapped to (−π, π]: a median near ±π stays meaningful.
double wrapAngle(double a) { return std::atan2(std::sin(a), std::cos(a)); }

double medianAbsDeviation(const std::vector<double>& v, double centre) {
  std::vector<double> dev;
  dev.reserve(v.size());
  for (double x : v) dev.push_back(std::abs(x - centre));
  return median(std::move(dev));
}
}  // namespace

BaseLidarResult calibrateBaseLidarMulti(const std::vector<Eigen::Vector3d>& map_points,
                                        const std::vector<Pose>& T_map_lidar_keyframes,
                                        const Pose& initial_T_base_lidar, const config::Parameters& p,
                                        const BaseLidarMultiSettings& settings) {
  BaseLidarResult combined;
  if (T_map_lidar_keyframes.empty()) {
    combined.failure = "no keyframe to fit the ground at";
    return combined;
  }
  // Keyframes spread evenly over the list (the whole path when there are few).
  std::vector<std::size_t> chosen;
  const std::size_t n = T_map_lidar_keyframes.size();
  const std::size_t want = std::max<std::size_t>(1, std::min(settings.max_keyframes, n));
  for (std::size_t k = 0; k < want; ++k) {
    const std::size_t i = want == 1 ? n / 2 : k * (n - 1) / (want - 1);
    if (chosen.empty() || chosen.back() != i) chosen.push_back(i);
  }

  const Eigen::Vector3d lo(p.base_lidar_crop_box_min_x, p.base_lidar_crop_box_min_y, p.base_lidar_crop_box_min_z);
  const Eigen::Vector3d hi(p.base_lidar_crop_box_max_x, p.base_lidar_crop_box_max_y, p.base_lidar_crop_box_max_z);
  std::vector<BaseLidarResult> accepted;
  std::vector<XyzRpy> estimates;
  std::string last_failure;
  std::vector<Eigen::Vector3d> cropped;
  for (std::size_t i : chosen) {
    // The map in this keyframe's lidar frame, cropped to the box (in base_link under the initial guess).
    const Pose T_base_map = initial_T_base_lidar * T_map_lidar_keyframes[i].inverse();
    const Pose T_lidar_map = T_map_lidar_keyframes[i].inverse();
    cropped.clear();
    for (const auto& q : map_points) {
      const Eigen::Vector3d b = T_base_map * q;
      if ((b.array() >= lo.array()).all() && (b.array() <= hi.array()).all()) cropped.push_back(T_lidar_map * q);
    }
    // RANSAC scores every point per hypothesis: thin a large crop evenly to bound the cost.
    if (settings.max_points_per_fit > 0 && cropped.size() > settings.max_points_per_fit) {
      const double stride = double(cropped.size()) / double(settings.max_points_per_fit);
      std::vector<Eigen::Vector3d> thin;
      thin.reserve(settings.max_points_per_fit);
      for (std::size_t k = 0; k < settings.max_points_per_fit; ++k) thin.push_back(cropped[std::size_t(double(k) * stride)]);
      cropped.swap(thin);
    }
    BaseLidarResult r = calibrateBaseLidar(cropped, initial_T_base_lidar, p);
    if (!r.ok) {
      last_failure = r.failure;
      continue;
    }
    estimates.push_back(toXyzRpy(r.T_base_lidar));
    accepted.push_back(std::move(r));
  }
  combined.keyframes_tried = chosen.size();
  combined.keyframes_used = accepted.size();
  if (accepted.empty()) {
    combined.failure = "no ground plane at any of " + std::to_string(chosen.size()) + " keyframes; last: " + last_failure;
    return combined;
  }

  // Per-component median: robust to a keyframe whose plane caught a ramp or a kerb.
  auto component = [&](double XyzRpy::*field) {
    std::vector<double> v;
    v.reserve(estimates.size());
    const bool angle = field == &XyzRpy::roll || field == &XyzRpy::pitch || field == &XyzRpy::yaw;
    for (const auto& e : estimates)
      v.push_back(angle ? wrapAngle(e.*field - estimates.front().*field) : e.*field - estimates.front().*field);
    return v;
  };
  XyzRpy m;
  for (double XyzRpy::*f : {&XyzRpy::x, &XyzRpy::y, &XyzRpy::z, &XyzRpy::roll, &XyzRpy::pitch, &XyzRpy::yaw})
    m.*f = median(component(f));  // offset from the first estimate
  combined.spread_z = medianAbsDeviation(component(&XyzRpy::z), m.z);
  combined.spread_roll_deg = rad2deg(medianAbsDeviation(component(&XyzRpy::roll), m.roll));
  combined.spread_pitch_deg = rad2deg(medianAbsDeviation(component(&XyzRpy::pitch), m.pitch));
  for (double XyzRpy::*f : {&XyzRpy::x, &XyzRpy::y, &XyzRpy::z}) m.*f += estimates.front().*f;
  for (double XyzRpy::*f : {&XyzRpy::roll, &XyzRpy::pitch, &XyzRpy::yaw}) m.*f = wrapAngle(m.*f + estimates.front().*f);
  combined.T_base_lidar = fromXyzRpy(m);

  // The combined ground plane in the lidar frame (base z = 0); support figures from the fit closest to it.
  const Eigen::Matrix3d R = combined.T_base_lidar.linear();
  combined.plane.normal = R.transpose() * Eigen::Vector3d::UnitZ();
  combined.plane.d = combined.T_base_lidar.translation().z();
  std::size_t closest = 0;
  for (std::size_t k = 1; k < estimates.size(); ++k)
    if (std::abs(estimates[k].z - m.z) < std::abs(estimates[closest].z - m.z)) closest = k;
  combined.plane.inliers = accepted[closest].plane.inliers;
  combined.plane.inlier_percentage = accepted[closest].plane.inlier_percentage;
  combined.plane.attempts = accepted[closest].plane.attempts;
  combined.cropped_points = accepted[closest].cropped_points;
  combined.ok = true;
  return combined;
}

}  // namespace rigcal::calib
