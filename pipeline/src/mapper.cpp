#include "rigcal/pipeline/mapper.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <deque>
#include <chrono>
#include <future>
#include <optional>
#include <sstream>
#include <stdexcept>

#include <sys/resource.h>
#include <unistd.h>

#include "rigcal/pipeline/deskew.hpp"
#include "rigcal/registration/covariance.hpp"
#include "rigcal/registration/gicp.hpp"
#include "rigcal/registration/ndt.hpp"
#include "rigcal/registration/target.hpp"
#include "rigcal/registration/voxel_grid.hpp"

namespace rigcal::pipeline {

namespace reg = registration;

void cropRange(Scan& scan, double min_range, double max_range) {
  const double min2 = min_range * min_range, max2 = max_range * max_range;
  scan.filter([&](std::size_t i) {
    const double r2 = double(scan.x[i]) * scan.x[i] + double(scan.y[i]) * scan.y[i] + double(scan.z[i]) * scan.z[i];
    return std::isfinite(r2) && r2 >= min2 && r2 < max2;
  });
}

namespace {

Scan toScan(const reg::PointCloud& cloud, const Scan& like) {
  Scan s;
  s.sensor_id = like.sensor_id;
  s.sequence = like.sequence;
  s.stamp_ns = like.stamp_ns;
  s.reserve(cloud.size());
  for (const auto& p : cloud.points) {
    s.x.push_back(float(p.x()));
    s.y.push_back(float(p.y()));
    s.z.push_back(float(p.z()));
  }
  s.intensity.assign(s.size(), 0.0f);
  s.ring.assign(s.size(), 0);
  s.offset_ns.assign(s.size(), 0);
  s.return_index.assign(s.size(), 0);
  return s;
}

using KeyframeCloud = std::shared_ptr<const reg::PointCloud>;  // in the map frame, voxel leaf_size_local_map

}  // namespace

struct Mapper::Impl {
  config::Parameters params;
  FrameTracker tracker;
  bool use_ndt = false;
  std::deque<KeyframeCloud> local;     // the local map's keyframes, oldest first
  std::vector<KeyframeCloud> all_keyframes;  // every keyframe's cloud (for the map)
  std::shared_ptr<const reg::Target> target;
  // The local map after a new keyframe is built on another thread while registration goes on against
  // the previous one; it is swapped in at the second scan after that keyframe (a fixed point in the
  // scan sequence: offline runs stay deterministic), waiting for it only if it is not ready by then.
  std::future<std::shared_ptr<const reg::Target>> pending_target;
  int scans_since_launch = 0;
  bool rebuild_wanted = false;          // real time: a keyframe came while a build was still running
  static constexpr int kBuildNiceness = 5;  // weight ~1/3 of the mapper's: slowed, never starved
  static constexpr int kSwapAfterScans = 2;
  // The last two good registrations (mid-sweep poses and times): the motion model.
  bool have_last = false, have_prev = false, last_failed = false;
  FrameKind last_kind = FrameKind::kKeyframe;
  int failures_in_a_row = 0;
  static constexpr int kRestartAfterFailures = 2;

  static TimeNs midSweep(const Scan& scan) {
    std::uint32_t sweep = 0;
    for (std::uint32_t o : scan.offset_ns) sweep = std::max(sweep, o);
    return scan.stamp_ns + TimeNs(sweep / 2);
  }
  TimeNs last_stamp = 0, prev_stamp = 0;
  Pose last_pose = Pose::Identity(), prev_pose = Pose::Identity();

  bool deterministic = true;
  bool defer_post_pose = false;
  struct PendingKeyframe {
    std::shared_ptr<const Scan> deskewed;
    Pose pose;
    bool restart = false;
  };
  std::optional<PendingKeyframe> pending_keyframe;  // deferred post-pose work

  void finishFrame(MapperOutput& out) {
    if (out.deskewed) {
      out.cloud = denseCloud(*out.deskewed);
      out.deskewed.reset();
    }
    if (pending_keyframe) {
      const PendingKeyframe k = std::move(*pending_keyframe);
      pending_keyframe.reset();
      addKeyframe(*k.deskewed, k.pose, k.restart);
    }
  }

  std::shared_ptr<const Scan> denseCloud(const Scan& deskewed) const {
    return std::make_shared<const Scan>(
        toScan(reg::voxelDownsample(reg::fromScan(deskewed), params.leaf_size_dense_map), deskewed));
  }

  Impl(const config::Parameters& p, bool det) : params(p), tracker(p), deterministic(det) {
    if (p.mapping_registrator == "ndt") use_ndt = true;
    else if (p.mapping_registrator != "gicp")
      throw std::invalid_argument("mapping_registrator must be gicp or ndt, got '" + p.mapping_registrator + "'");
  }

  static std::shared_ptr<const reg::Target> buildTarget(const std::vector<KeyframeCloud>& clouds,
                                                        const config::Parameters& params, bool use_ndt,
                                                        int threads) {
    reg::PointCloud merged;
    for (const auto& k : clouds) merged.points.insert(merged.points.end(), k->points.begin(), k->points.end());
    merged = reg::voxelDownsample(merged, params.leaf_size_local_map);
    reg::TargetOptions o;
    o.num_threads = threads;
    if (use_ndt) o.ndt_resolutions = {params.mapper_resolution};
    else o.normals_and_covariances = true;
    return std::make_shared<const reg::Target>(std::move(merged), o);
  }

  void swapInPendingTarget(bool now) {
    if (!pending_target.valid()) return;
    if (!target) {  // a first or restarted map: nothing else to register against, wait for it
      target = pending_target.get();
      return;
    }
    ++scans_since_launch;
    const bool ready = pending_target.wait_for(std::chrono::seconds(0)) == std::future_status::ready;
    if (!now && (deterministic ? scans_since_launch < kSwapAfterScans : !ready)) return;
    target = pending_target.get();
  }

  void addKeyframe(const Scan& deskewed, const Pose& T_map_lidar, bool restart) {
    reg::PointCloud c = reg::voxelDownsample(reg::fromScan(deskewed), params.leaf_size_local_map);
    auto k = std::make_shared<reg::PointCloud>(reg::transformed(c, T_map_lidar));
    k->clearAttributes();
    if (restart) local.clear();
    all_keyframes.push_back(k);
    local.push_back(std::move(k));
    while (int(local.size()) > std::max(1, params.local_map_num_keyframes)) local.pop_front();
    // A first or restarted map is built in the background too: the scan that seeds it returns at once and
    // the next one (a sweep period later) finds it ready, or waits for the rest. Either way every scan
    // registers against the same map, whatever the timing: offline runs stay deterministic.
    if (restart || !target) {
      target.reset();
      launchBuild();
      return;
    }
    if (!deterministic && pending_target.valid() &&
        pending_target.wait_for(std::chrono::seconds(0)) != std::future_status::ready) {
      // Real time: never wait for the last build. It is swapped in when ready; this keyframe's map follows.
      rebuild_wanted = true;
      return;
    }
    swapInPendingTarget(true);
    launchBuild();
  }

  void launchBuild() {
    std::vector<KeyframeCloud> clouds(local.begin(), local.end());
    scans_since_launch = 0;
    rebuild_wanted = false;
    // Real time: one build thread, so the registering threads keep one core to themselves (a build on
    // both cores slows both halves of every registration's parallel loop). Offline: as fast as possible.
    // The Target is the same whatever the thread count.
    const int threads = deterministic ? std::max(1, params.mapper_num_threads) : 1;
    pending_target = std::async(std::launch::async, [clouds = std::move(clouds), p = params, ndt = use_ndt, threads] {
      // Below the registering thread: a build (~5x one registration's CPU) must not stretch the scans
      // that register meanwhile, on two cores. Its helper threads inherit the niceness.
      ::setpriority(PRIO_PROCESS, id_t(::gettid()), kBuildNiceness);
      return buildTarget(clouds, p, ndt, threads);
    });
  }

  // A capture (or a driver started mid-rotation) begins with part of a sweep. Seeding the map with it
  // leaves the next full sweeps half outside the map: they fail the fitness check and are lost until the
  // map restarts. So the first seed must cover kCompleteSweep of the rotation: of the whole circle for the
  // very first sweep, of the fullest sweep seen so far after that (a sensor with a limited field of view
  // loses one sweep, never more).
  static constexpr double kCompleteSweep = 0.9;
  bool seed_checked = false;
  double best_coverage = 0.0;

  /// Fraction of the 360 one-degree azimuth sectors around the sensor that hold a point.
  static double azimuthCoverage(const Scan& scan) {
    std::array<bool, 360> hit{};
    for (std::size_t i = 0; i < scan.size(); ++i) {
      const double deg = std::atan2(double(scan.y[i]), double(scan.x[i])) * 180.0 / M_PI + 180.0;
      hit[std::min<std::size_t>(359, std::size_t(deg))] = true;
    }
    return double(std::count(hit.begin(), hit.end(), true)) / 360.0;
  }

  static constexpr double kCoarseCorrespondence = 1.0;  // m
  // A scan-to-map registration needs a few thousand well-spread points, not every voxel: beyond this the
  // voxelised scan is thinned with a fixed stride (deterministic), which keeps the mapper within a 10 Hz
  // budget on two shared cores at the same accuracy (see the trajectory test).
  static constexpr std::size_t kMaxRegistrationPoints = 6000;

  reg::PointCloud registrationSource(const Scan& deskewed) const {
    reg::PointCloud v = reg::voxelDownsample(reg::fromScan(deskewed), params.leaf_size_input);
    if (v.size() <= kMaxRegistrationPoints) return v;
    const double stride = double(v.size()) / double(kMaxRegistrationPoints);
    reg::PointCloud thin;
    thin.points.reserve(kMaxRegistrationPoints);
    for (std::size_t i = 0; i < kMaxRegistrationPoints; ++i) thin.points.push_back(v.points[std::size_t(double(i) * stride)]);
    return thin;
  }

  static bool accepted(const reg::RegistrationResult& r) {
    return (r.status == reg::Status::kConverged || r.status == reg::Status::kMaxIterations) &&
           r.inlier_ratio >= kMinInlierRatio;
  }

  static bool allFinite(const Pose& T) { return T.matrix().allFinite(); }

  reg::RegistrationResult align(const reg::PointCloud& source, const Pose& guess, double max_corr) {
    const int threads = std::max(1, params.mapper_num_threads);
    if (use_ndt) {
      reg::NdtParams np;
      np.resolution = params.mapper_resolution;
      np.step_size = params.mapper_step_size;
      np.max_iterations = params.mapper_max_iterations;
      np.num_threads = threads;
      np.max_correspondence_distance = std::max(max_corr, 1.0);
      return reg::alignNdt(*target, source, guess, np);
    }
    reg::GicpParams gp;
    gp.max_correspondence_distance = max_corr;
    gp.max_iterations = params.mapper_max_iterations;
    gp.num_threads = threads;
    return reg::alignGicp(*target, source, guess, gp);
  }

  Pose extrapolate(TimeNs stamp) const {
    if (!have_prev || last_stamp <= prev_stamp) return last_pose;
    const double steps = double(stamp - last_stamp) / double(last_stamp - prev_stamp);
    return last_pose * expSE3(steps * logSE3(prev_pose.inverse() * last_pose));
  }

  SensorMotion motion(TimeNs stamp) const {
    if (!have_prev || last_stamp <= prev_stamp) return [](TimeNs) { return Pose::Identity(); };
    return constantVelocity(prev_pose.inverse() * last_pose, last_stamp - prev_stamp, stamp);
  }

  MapperOutput process(const Scan& input) {
    if (pending_keyframe) {  // the caller did not finish the last frame: the map must not miss it
      MapperOutput last;
      finishFrame(last);
    }
    MapperOutput out;
    if (tracker.full()) {
      out.skipped_reason = "mapper full (mapping_max_frames)";
      return out;
    }
    Scan scan = input;
    cropRange(scan, params.mapping_min_range, params.mapping_max_range);
    if (int(scan.size()) < params.min_mapping_pointcloud_size) {
      out.skipped_reason = std::to_string(scan.size()) + " points < min_mapping_pointcloud_size " +
                           std::to_string(params.min_mapping_pointcloud_size);
      return out;
    }
    if (!have_last) {  // this sweep would seed the map: it must be a whole rotation
      const double coverage = azimuthCoverage(scan);
      const double required = kCompleteSweep * (seed_checked ? best_coverage : 1.0);
      best_coverage = std::max(best_coverage, coverage);
      const bool first_look = !seed_checked;
      seed_checked = true;
      if (coverage < required) {
        std::ostringstream why;
        why << "incomplete sweep cannot seed the map: it covers " << std::lround(100 * coverage) << "% of the rotation"
            << (first_look ? "" : " (the fullest so far " + std::to_string(std::lround(100 * best_coverage)) + "%)");
        out.skipped_reason = why.str();
        return out;
      }
    }
    out.registered = true;

    swapInPendingTarget(false);
    if (rebuild_wanted && !pending_target.valid()) launchBuild();
    Pose pose = Pose::Identity();
    Scan deskewed = scan;
    if (!target) {  // the first frame defines the map
      out.registration = {"first", 0, 1.0, 0.0, true};
    } else {
      // Deskew to the middle of the sweep and register there. The motion model follows these mid-sweep
      // poses only (pure registration results): were it fed the poses at the first point, which are
      // extrapolated with the model's own velocity, a velocity error would come back amplified (the loop
      // oscillates and grows while standing still).
      const TimeNs mid = midSweep(scan);
      const SensorMotion T_mid_sensor = motion(mid);
      // Upstream: constant velocity, or the last pose after a stopped or lost frame. After a failed
      // registration the motion of the last two good ones is still the best guess.
      const bool hold = (last_kind == FrameKind::kStopped || last_kind == FrameKind::kStoppedKeyframe) && !last_failed;
      const Pose guess = hold ? last_pose : extrapolate(mid);
      deskew(deskewed, T_mid_sensor);
      reg::PointCloud source = registrationSource(deskewed);
      if (!use_ndt) {  // once, shared by the retries
        reg::CovarianceOptions co;
        co.num_threads = std::max(1, params.mapper_num_threads);
        reg::estimateCovariances(source, co);
      }
      reg::RegistrationResult r = align(source, guess, params.mapper_max_correspondence_distance);
      if (!accepted(r)) {
        // Coarse then fine from the same guess: a jerk or a longer gap moves the scan beyond the fine
        // correspondence distance; the frame's lost/kept status is still the tracker's call.
        const reg::RegistrationResult coarse = align(source, guess, kCoarseCorrespondence);
        if (accepted(coarse)) r = align(source, coarse.T_target_source, params.mapper_max_correspondence_distance);
      }
      const bool converged = r.status == reg::Status::kConverged || r.status == reg::Status::kMaxIterations;
      const bool fit = r.inlier_ratio >= kMinInlierRatio && allFinite(r.T_target_source);
      out.registration = {std::string(reg::toString(r.status)), r.iterations, r.inlier_ratio, r.rmse,
                          converged && fit};
      if (converged && !fit) out.registration.status += ", inlier ratio below " + std::to_string(kMinInlierRatio);
      const Pose mid_pose = out.registration.ok ? r.T_target_source : guess;
      if (out.registration.ok && have_last && mid > last_stamp) {
        // Refine once: the motion from the last registration to this one replaces the prediction; the
        // frame's pose and stored cloud are at its stamp (first point).
        const Pose step = last_pose.inverse() * mid_pose;
        pose = mid_pose * constantVelocity(step, mid - last_stamp, mid)(scan.stamp_ns);
        deskewed = scan;
        deskew(deskewed, constantVelocity(step, mid - last_stamp, scan.stamp_ns));
      } else {
        pose = mid_pose * T_mid_sensor(scan.stamp_ns);
      }
      if (out.registration.ok) {
        prev_pose = last_pose;
        prev_stamp = last_stamp;
        have_prev = have_last;
        last_pose = mid_pose;
        last_stamp = mid;
        have_last = true;
      }
    }

    out.frame = tracker.add(scan.sequence, scan.stamp_ns, pose, out.registration.ok);
    last_failed = !out.registration.ok;
    last_kind = out.frame.kind;
    if (!have_last) {  // the first frame: at rest as far as anyone knows
      last_pose = pose;
      last_stamp = midSweep(scan);
      have_last = true;
    }

    // A lost keyframe restarts the local map (upstream); a failed registration does not feed it, unless
    // registrations keep failing (the map was restarted from a partial sweep, or the vehicle got far off
    // the prediction): then the map restarts from this frame at its predicted pose.
    failures_in_a_row = out.registration.ok ? 0 : failures_in_a_row + 1;
    bool feed = false, restart = false;
    if (out.frame.isKeyframe() && out.registration.ok) {
      feed = true;
      restart = out.frame.lost || !target;
    } else if (failures_in_a_row >= kRestartAfterFailures) {
      feed = restart = true;
      failures_in_a_row = 0;
    }
    std::shared_ptr<const Scan> shared_deskewed;
    if (out.frame.stored() || feed) shared_deskewed = std::make_shared<const Scan>(std::move(deskewed));
    if (out.frame.stored()) out.deskewed = shared_deskewed;
    if (feed) pending_keyframe = PendingKeyframe{shared_deskewed, pose, restart};
    if (!defer_post_pose) finishFrame(out);
    return out;
  }
};

Mapper::Mapper(const config::Parameters& params, bool deterministic)
    : impl_(std::make_unique<Impl>(params, deterministic)) {}
Mapper::~Mapper() = default;
MapperOutput Mapper::process(const Scan& scan) { return impl_->process(scan); }
void Mapper::deferPostPoseWork(bool defer) { impl_->defer_post_pose = defer; }
void Mapper::finishFrame(MapperOutput& out) { impl_->finishFrame(out); }
const FrameTracker& Mapper::tracker() const { return impl_->tracker; }
bool Mapper::done() const { return impl_->tracker.full(); }
std::size_t Mapper::localMapPoints() const { return impl_->target ? impl_->target->size() : 0; }

std::shared_ptr<const Scan> Mapper::mapCloud() const {
  reg::PointCloud merged;
  for (const auto& k : impl_->all_keyframes) merged.points.insert(merged.points.end(), k->points.begin(), k->points.end());
  Scan like;
  like.sensor_id = "map";
  if (merged.empty()) return std::make_shared<const Scan>(like);
  return std::make_shared<const Scan>(toScan(reg::voxelDownsample(merged, impl_->params.leaf_size_local_map), like));
}

}  // namespace rigcal::pipeline
