#include "lidar_pose_synthetic.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>

namespace rigcal::test {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kYard = 30.0;         // walls at x, y = ±30 m
constexpr double kWallHeight = 8.0;
constexpr double kSweepNs = 100e6;     // 10 Hz

struct Box {
  Eigen::Vector3d centre, half;
  double cos_yaw, sin_yaw;
  float intensity;
};

std::vector<Box> makeBoxes(std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::vector<Box> boxes;
  for (int i = 0; i < 28; ++i) {
    const double radius = 9.0 + 16.0 * u(rng), angle = 2.0 * M_PI * u(rng), yaw = M_PI * u(rng);
    Box b;
    b.half = {0.4 + 1.6 * u(rng), 0.4 + 1.6 * u(rng), 0.5 + 2.5 * u(rng)};
    b.centre = {radius * std::cos(angle), radius * std::sin(angle), b.half.z()};
    b.cos_yaw = std::cos(yaw);
    b.sin_yaw = std::sin(yaw);
    b.intensity = static_cast<float>(60 + i);
    boxes.push_back(b);
  }
  return boxes;
}

// Nearest hit along o + s·d (d unit), or kInf; `intensity` is set on a hit.
double castRay(const std::vector<Box>& boxes, const Eigen::Vector3d& o, const Eigen::Vector3d& d,
               float* intensity) {
  double best = kInf;
  if (d.z() < 0.0) {  // ground z = 0
    best = -o.z() / d.z();
    *intensity = 10.0f;
  }
  double exit = kInf;  // walls: the ray leaves the yard through the nearest of them
  for (int a = 0; a < 2; ++a)
    if (d[a] != 0.0) exit = std::min(exit, ((d[a] > 0 ? kYard : -kYard) - o[a]) / d[a]);
  const double z_exit = o.z() + exit * d.z();
  if (exit < best && z_exit >= 0.0 && z_exit <= kWallHeight) {
    best = exit;
    *intensity = 40.0f;
  }
  for (const Box& b : boxes) {
    // Ray into the box frame (rotated by −yaw about z), then the slab test.
    const Eigen::Vector3d r = o - b.centre;
    const double lo[3] = {b.cos_yaw * r.x() + b.sin_yaw * r.y(), -b.sin_yaw * r.x() + b.cos_yaw * r.y(), r.z()};
    const double dir[3] = {b.cos_yaw * d.x() + b.sin_yaw * d.y(), -b.sin_yaw * d.x() + b.cos_yaw * d.y(), d.z()};
    double t_in = 0.0, t_out = best;
    for (int a = 0; a < 3 && t_in <= t_out; ++a) {
      if (std::abs(dir[a]) < 1e-12) {
        if (std::abs(lo[a]) > b.half[a]) t_in = kInf;
        continue;
      }
      double t1 = (-b.half[a] - lo[a]) / dir[a], t2 = (b.half[a] - lo[a]) / dir[a];
      if (t1 > t2) std::swap(t1, t2);
      t_in = std::max(t_in, t1);
      t_out = std::min(t_out, t2);
    }
    if (t_in <= t_out && t_in > 0.0 && t_in < best) {
      best = t_in;
      *intensity = b.intensity;
    }
  }
  return best;
}

}  // namespace

Pose syntheticPose(const SyntheticOptions& o, double t) {
  const double w = 2.0 * M_PI / 10.0;  // one figure of eight every 10 s, up to ~3.8 m/s
  const double A = 6.0, B = 3.0;
  XyzRpy v;
  v.x = A * std::sin(w * t);
  v.y = B * std::sin(2.0 * w * t);
  v.yaw = std::atan2(2.0 * B * w * std::cos(2.0 * w * t), A * w * std::cos(w * t));
  v.z = 1.0;
  if (!o.planar) {
    v.roll = deg2rad(o.roll_amplitude_deg) * std::sin(2.0 * M_PI * 0.37 * t);
    v.pitch = deg2rad(o.pitch_amplitude_deg) * std::sin(2.0 * M_PI * 0.23 * t + 0.5);
    v.z += 0.15 * std::sin(2.0 * M_PI * 0.31 * t);
  }
  return fromXyzRpy(v);
}

SyntheticRecording makeSyntheticRecording(const SyntheticOptions& o) {
  SyntheticRecording rec;
  const double pose_dt = 1.0 / o.pose_rate_hz;
  for (double t = -o.pose_margin_s; t <= o.duration_s + o.pose_margin_s + 1e-9; t += pose_dt) {
    rec.pose_stamps.push_back(o.start_ns + fromSeconds(t));
    rec.poses.push_back(syntheticPose(o, t));
  }

  const std::vector<Box> boxes = makeBoxes(o.seed);
  std::mt19937_64 rng(o.seed ^ 0x5eedULL);
  std::normal_distribution<double> noise(0.0, o.range_noise_m);
  const int sweeps = static_cast<int>(std::floor(o.duration_s * 1e9 / kSweepNs));
  std::vector<Eigen::Vector3d> ray_dirs;  // lidar frame, per (column, ring)
  for (int c = 0; c < o.columns; ++c) {
    const double az = 2.0 * M_PI * c / o.columns;
    for (int r = 0; r < o.rings; ++r) {
      const double el = deg2rad(-15.0 + 30.0 * r / std::max(1, o.rings - 1));
      ray_dirs.emplace_back(std::cos(el) * std::cos(az), std::cos(el) * std::sin(az), std::sin(el));
    }
  }
  for (int k = 0; k < sweeps; ++k) {
    Scan scan;
    scan.sensor_id = "synthetic";
    scan.sequence = static_cast<std::uint64_t>(k);
    scan.stamp_ns = o.start_ns + static_cast<TimeNs>(k * kSweepNs);
    scan.reserve(ray_dirs.size());
    for (int c = 0; c < o.columns; ++c) {
      const TimeNs offset = static_cast<TimeNs>(c * kSweepNs / o.columns);
      const double t_pose = toSeconds(scan.stamp_ns + offset - o.start_ns) + o.time_offset_s;
      bool pose_ready = false;
      Pose T_world_lidar;
      for (int r = 0; r < o.rings; ++r) {
        const std::size_t idx = scan.size();
        Point p;
        p.ring = static_cast<std::uint16_t>(r);
        p.time_ns = scan.stamp_ns + offset;
        if (calib::keepPoint(o.selection.seed, scan.sequence, idx, o.selection.keep_points_ratio)) {
          if (!pose_ready) {
            T_world_lidar = syntheticPose(o, t_pose) * o.T_pose_lidar;
            pose_ready = true;
          }
          const Eigen::Vector3d& dir = ray_dirs[static_cast<std::size_t>(c * o.rings + r)];
          float intensity = 0.0f;
          const double range = castRay(boxes, T_world_lidar.translation(), T_world_lidar.linear() * dir,
                                       &intensity);
          if (range < 100.0) {
            const Eigen::Vector3d q = dir * (range + noise(rng));
            p.x = static_cast<float>(q.x());
            p.y = static_cast<float>(q.y());
            p.z = static_cast<float>(q.z());
            p.intensity = intensity;
          } else {  // no return
            p.x = p.y = p.z = std::numeric_limits<float>::quiet_NaN();
          }
        }
        scan.push_back(p);
      }
    }
    rec.scans.push_back(std::move(scan));
  }
  return rec;
}

}  // namespace rigcal::test
