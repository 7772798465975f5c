#include "rigcal/calib/lidar_pose/lidar_pose_points.hpp"

#include <algorithm>
#include <cinttypes>
#include <cmath>
#include <cstdio>
#include <limits>
#include <stdexcept>
#include <string>

namespace rigcal::calib {
namespace {

// splitmix64 finaliser: a bijective mix whose outputs are uniform enough for sampling.
std::uint64_t mix(std::uint64_t v) {
  v += 0x9e3779b97f4a7c15ULL;
  v = (v ^ (v >> 30)) * 0xbf58476d1ce4e5b9ULL;
  v = (v ^ (v >> 27)) * 0x94d049bb133111ebULL;
  return v ^ (v >> 31);
}

// "[a, b] s (length s)" with nanosecond digits; built with snprintf only (GCC 12 warns falsely about
// operator+ on short literals under -O3).
std::string range(TimeNs a, TimeNs b) {
  const auto split = [](TimeNs t, const char** sign, TimeNs* sec, TimeNs* ns) {
    *sign = t < 0 ? "-" : "";
    const TimeNs m = t < 0 ? -t : t;
    *sec = m / kNsPerSec;
    *ns = m % kNsPerSec;
  };
  const char *sa, *sb;
  TimeNs a_s, a_ns, b_s, b_ns;
  split(a, &sa, &a_s, &a_ns);
  split(b, &sb, &b_s, &b_ns);
  char buf[128];
  std::snprintf(buf, sizeof buf, "[%s%" PRId64 ".%09" PRId64 ", %s%" PRId64 ".%09" PRId64 "] s (%.3f s)", sa,
                a_s, a_ns, sb, b_s, b_ns, toSeconds(b - a));
  return buf;
}

}  // namespace

bool keepPoint(std::uint64_t seed, std::uint64_t sequence, std::size_t index, double ratio) {
  if (ratio >= 1.0) return true;
  if (!(ratio > 0.0)) return false;
  const std::uint64_t h = mix(mix(seed ^ mix(sequence)) ^ static_cast<std::uint64_t>(index));
  // Compare in [0, 1): 53 bits are all a double can hold exactly.
  return static_cast<double>(h >> 11) * 0x1.0p-53 < ratio;
}

void appendLidarPoints(const Scan& scan, const LidarPointSelection& sel, LidarPoints& out) {
  auto& c = out.counts;
  ++c.scans;
  const double min_sq = sel.min_point_distance * sel.min_point_distance;
  const double max_sq = sel.max_point_distance * sel.max_point_distance;
  c.input += scan.size();
  for (std::size_t i = 0; i < scan.size(); ++i) {
    if (!keepPoint(sel.seed, scan.sequence, i, sel.keep_points_ratio)) {
      ++c.not_sampled;
      continue;
    }
    if (!(scan.intensity[i] > sel.min_return_intensity)) {
      ++c.low_intensity;
      continue;
    }
    const double px = scan.x[i], py = scan.y[i], pz = scan.z[i];
    const double sq = px * px + py * py + pz * pz;
    if (!std::isfinite(sq) || !(sq > min_sq) || !(sq < max_sq)) {
      ++c.out_of_range;
      continue;
    }
    out.x.push_back(scan.x[i]);
    out.y.push_back(scan.y[i]);
    out.z.push_back(scan.z[i]);
    out.intensity.push_back(scan.intensity[i]);
    out.time_ns.push_back(scan.pointTime(i));
  }
  c.kept = out.size();
}

LidarPoints selectLidarPoints(const std::vector<Scan>& scans, const LidarPointSelection& sel) {
  LidarPoints out;
  for (const Scan& scan : scans) appendLidarPoints(scan, sel, out);
  return out;
}

void restrictToTrajectory(LidarPoints& points, const PoseTrajectory& trajectory, double margin_s,
                          std::size_t min_points) {
  const TimeNs margin = fromSeconds(std::abs(margin_s));
  TimeNs first = std::numeric_limits<TimeNs>::max(), last = std::numeric_limits<TimeNs>::min();
  std::size_t out = 0;
  for (std::size_t i = 0; i < points.size(); ++i) {
    const TimeNs t = points.time_ns[i];
    first = std::min(first, t);
    last = std::max(last, t);
    if (t - margin < trajectory.begin() || t + margin > trajectory.end()) continue;
    points.x[out] = points.x[i];
    points.y[out] = points.y[i];
    points.z[out] = points.z[i];
    points.intensity[out] = points.intensity[i];
    points.time_ns[out] = t;
    ++out;
  }
  points.counts.outside_poses += points.size() - out;
  points.x.resize(out);
  points.y.resize(out);
  points.z.resize(out);
  points.intensity.resize(out);
  points.time_ns.resize(out);
  points.counts.kept = out;
  if (out >= min_points) return;
  const std::string lidar = first <= last ? range(first, last) : std::string("(no lidar point)");
  throw std::runtime_error(
      "the poses do not cover the lidar time range: poses span " +
      range(trajectory.begin(), trajectory.end()) + ", lidar points span " + lidar + "; " +
      std::to_string(out) + " points have a pose within ±" + std::to_string(margin_s) +
      " s (time offset search range), " + std::to_string(min_points) + " needed");
}

}  // namespace rigcal::calib
