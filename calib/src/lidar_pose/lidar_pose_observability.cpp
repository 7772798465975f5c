#include "rigcal/calib/lidar_pose/lidar_pose_observability.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <sstream>

namespace rigcal::calib {
namespace {

std::string fmt(double v, int decimals = 2) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*f", decimals, v);
  return buf;
}

constexpr const char* kAxis[3] = {"x", "y", "z"};

}  // namespace

const char* lidarPoseParamName(LidarPoseParam p) {
  switch (p) {
    case LidarPoseParam::kX: return "x";
    case LidarPoseParam::kY: return "y";
    case LidarPoseParam::kZ: return "z";
    case LidarPoseParam::kRoll: return "roll";
    case LidarPoseParam::kPitch: return "pitch";
    case LidarPoseParam::kYaw: return "yaw";
    case LidarPoseParam::kTimeOffset: return "time_offset";
  }
  return "?";
}

ObservabilityReport assessObservability(const PoseTrajectory& trajectory, TimeNs begin, TimeNs end,
                                        const ObservabilitySettings& s) {
  ObservabilityReport r;
  // Poses inside [begin, end] plus the ones bracketing it: the motion the lidar points actually see.
  std::size_t first = 0, last = trajectory.size() - 1;
  while (first + 1 < trajectory.size() && trajectory.stamp(first + 1) <= begin) ++first;
  while (last > first && trajectory.stamp(last - 1) >= end) --last;
  r.poses = last - first + 1;
  r.duration_s = toSeconds(trajectory.stamp(last) - trajectory.stamp(first));

  Eigen::Vector3d angle = Eigen::Vector3d::Zero(), lo = angle, hi = angle, rate_sq = angle;
  double weight = 0.0;
  r.speed_min_mps = std::numeric_limits<double>::max();
  r.speed_max_mps = 0.0;
  for (std::size_t i = first; i < last; ++i) {
    const Pose& a = trajectory.pose(i);
    const Pose& b = trajectory.pose(i + 1);
    const double dt = toSeconds(trajectory.stamp(i + 1) - trajectory.stamp(i));
    const Eigen::Vector3d w = logSO3(a.linear().transpose() * b.linear());  // body frame increment
    angle += w;
    lo = lo.cwiseMin(angle);
    hi = hi.cwiseMax(angle);
    rate_sq += (w / dt).cwiseAbs2() * dt;
    weight += dt;
    const double step = (b.translation() - a.translation()).norm();
    r.path_length_m += step;
    r.speed_min_mps = std::min(r.speed_min_mps, step / dt);
    r.speed_max_mps = std::max(r.speed_max_mps, step / dt);
  }
  if (r.speed_min_mps > r.speed_max_mps) r.speed_min_mps = 0.0;
  for (int a = 0; a < 3; ++a) {
    r.rotation_range_deg[a] = rad2deg(hi[a] - lo[a]);
    r.angular_rate_rms_dps[a] = weight > 0 ? rad2deg(std::sqrt(rate_sq[a] / weight)) : 0.0;
  }

  const double R = s.min_rotation_range_deg;
  const auto& rr = r.rotation_range_deg;
  const auto flag = [&](LidarPoseParam p, std::string why) {
    r.poorly_constrained[static_cast<std::size_t>(p)] = true;
    r.reason[static_cast<std::size_t>(p)] = std::move(why);
  };
  const auto ranges = [&](int a, int b) {
    return "rotation about " + std::string(kAxis[a]) + " " + fmt(rr[a]) + "°, about " + kAxis[b] + " " +
           fmt(rr[b]) + "° < " + fmt(R) + "°";
  };
  for (int a = 0; a < 3; ++a) {
    const int b = (a + 1) % 3, c = (a + 2) % 3;
    if (rr[b] < R && rr[c] < R)
      flag(static_cast<LidarPoseParam>(a),
           "translation along " + std::string(kAxis[a]) + " needs rotation about another axis: " +
               ranges(std::min(b, c), std::max(b, c)));
  }
  const double tilt = std::max(rr[0], rr[1]);
  if (!r.flagged(LidarPoseParam::kZ) && tilt < s.min_tilt_range_for_z_deg) {
    std::ostringstream why;
    why << "translation along z is seen only through tilt (an error dz moves points sideways by "
           "dz*sin(tilt)): rotation about x "
        << fmt(rr[0]) << "°, about y " << fmt(rr[1]) << "° < " << fmt(s.min_tilt_range_for_z_deg) << "°";
    flag(LidarPoseParam::kZ, why.str());
  }
  if (rr[0] < R && rr[1] < R) {
    const std::string why = "roll and pitch need non-planar motion: " + ranges(0, 1);
    flag(LidarPoseParam::kRoll, why);
    flag(LidarPoseParam::kPitch, why);
  }
  const double max_range = std::max({rr[0], rr[1], rr[2]});
  if (max_range < R && r.path_length_m < s.min_path_length_m)
    flag(LidarPoseParam::kYaw, "yaw needs rotation or travel: largest rotation range " + fmt(max_range) +
                                   "° < " + fmt(R) + "°, path " + fmt(r.path_length_m) + " m < " +
                                   fmt(s.min_path_length_m) + " m");
  const double speed_range = r.speed_max_mps - r.speed_min_mps;
  if (max_range < R && speed_range < s.min_speed_range_mps)
    flag(LidarPoseParam::kTimeOffset,
         "the time offset needs rotation or a change of speed: largest rotation range " + fmt(max_range) +
             "° < " + fmt(R) + "°, speed range " + fmt(speed_range) + " m/s < " +
             fmt(s.min_speed_range_mps) + " m/s");
  return r;
}

std::string ObservabilityReport::text() const {
  std::ostringstream o;
  o << "Motion over " << fmt(duration_s) << " s (" << poses << " poses): rotation range about x, y, z "
    << fmt(rotation_range_deg[0]) << "°, " << fmt(rotation_range_deg[1]) << "°, "
    << fmt(rotation_range_deg[2]) << "°; angular rate RMS " << fmt(angular_rate_rms_dps[0]) << ", "
    << fmt(angular_rate_rms_dps[1]) << ", " << fmt(angular_rate_rms_dps[2]) << " °/s; path "
    << fmt(path_length_m) << " m; speed " << fmt(speed_min_mps) << " to " << fmt(speed_max_mps)
    << " m/s\n";
  bool any = false;
  for (std::size_t i = 0; i < kLidarPoseParams; ++i) {
    if (!poorly_constrained[i]) continue;
    any = true;
    o << "poorly constrained: " << lidarPoseParamName(static_cast<LidarPoseParam>(i)) << " (" << reason[i]
      << ")\n";
  }
  if (!any) o << "all parameters excited\n";
  return o.str();
}

}  // namespace rigcal::calib
