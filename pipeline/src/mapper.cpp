#include "rigcal/pipeline/mapper.hpp"

#include <algorithm>
#include <cmath>
#include <optional>
#include <stdexcept>

#include "local_map.hpp"
#include "motion_model.hpp"
#include "seed_sweep_check.hpp"
#include "rigcal/pipeline/deskew.hpp"
#include "rigcal/registration/covariance.hpp"
#include "rigcal/registration/gicp.hpp"
#include "rigcal/registration/ndt.hpp"
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

bool usesNdt(const config::Parameters& p) {
  if (p.mapping_registrator == "ndt") return true;
  if (p.mapping_registrator != "gicp")
    throw std::invalid_argument("mapping_registrator must be gicp or ndt, got '" + p.mapping_registrator + "'");
  return false;
}

/// A stored frame's cloud: x, y, z only, the other arrays empty (nobody reads them: the voxel centroids
/// have no intensity, ring or time). Half the bytes of a full Scan: a drive keeps hundreds of these.
Scan positionsOnly(const reg::PointCloud& cloud, const Scan& like) {
  Scan s;
  s.sensor_id = like.sensor_id;
  s.sequence = like.sequence;
  s.stamp_ns = like.stamp_ns;
  s.x.reserve(cloud.size());
  s.y.reserve(cloud.size());
  s.z.reserve(cloud.size());
  for (const auto& p : cloud.points) {
    s.x.push_back(float(p.x()));
    s.y.push_back(float(p.y()));
    s.z.push_back(float(p.z()));
  }
  return s;
}

MapperOutput skipped(std::string why) {
  MapperOutput out;
  out.skipped_reason = std::move(why);
  return out;
}

}  // namespace

struct Mapper::Impl {
  static constexpr int kRestartAfterFailures = 2;
  static constexpr double kCoarseCorrespondence = 1.0;  // m
  // A scan-to-map registration needs a few thousand well-spread points, not every voxel: beyond this the
  // voxelised scan is thinned with a fixed stride (deterministic), which keeps the mapper within a 10 Hz
  // budget on two shared cores at the same accuracy (see the trajectory test).
  static constexpr std::size_t kMaxRegistrationPoints = 6000;

  config::Parameters params;
  bool use_ndt;
  FrameTracker tracker;
  MotionModel motion;
  LocalMap local_map;
  SeedSweepCheck seed_check;
  int failures_in_a_row = 0;

  bool defer_post_pose = false;
  struct PendingKeyframe {
    std::shared_ptr<const Scan> deskewed;
    Pose pose;
    bool restart = false;
  };
  std::optional<PendingKeyframe> pending_keyframe;  // deferred post-pose work

  /// Where a scan landed: its pose at its stamp and the scan deskewed to that stamp.
  struct Placement {
    RegistrationSummary summary;
    Pose T_map_lidar = Pose::Identity();
    Scan deskewed;
  };

  Impl(const config::Parameters& p, bool deterministic)
      : params(p), use_ndt(usesNdt(p)), tracker(p), local_map(p, use_ndt, deterministic) {}

  // Preprocess → seed check → guess → align → update, the steps of every scan.
  MapperOutput process(Scan scan) {
    if (pending_keyframe) {  // the caller did not finish the last frame: the map must not miss it
      MapperOutput last;
      finishFrame(last);
    }
    if (tracker.full()) return skipped("mapper full (mapping_max_frames)");
    cropRange(scan, params.mapping_min_range, params.mapping_max_range);
    if (int(scan.size()) < params.min_mapping_pointcloud_size)
      return skipped(std::to_string(scan.size()) + " points < min_mapping_pointcloud_size " +
                     std::to_string(params.min_mapping_pointcloud_size));
    if (!motion.started())  // this sweep would seed the map: it must be a whole rotation
      if (auto why = seed_check.reject(scan)) return skipped(std::move(*why));

    local_map.beforeRegistration();
    Placement placed = local_map.target() ? registerScan(scan) : firstFrame(scan);
    MapperOutput out;
    out.registered = true;
    out.registration = std::move(placed.summary);
    out.frame = tracker.add(scan.sequence, scan.stamp_ns, placed.T_map_lidar, out.registration.ok);
    motion.classified(scan, placed.T_map_lidar, out.frame.kind, out.registration.ok);
    keep(out, std::move(placed));
    if (!defer_post_pose) finishFrame(out);
    return out;
  }

  static Placement firstFrame(const Scan& scan) {  // the first frame defines the map
    return Placement{{"first", 0, 1.0, 0.0, true}, Pose::Identity(), scan};
  }

  Placement registerScan(const Scan& scan) {
    // Deskew to the middle of the sweep and register there (the motion model's time).
    const TimeNs mid = MotionModel::midSweep(scan);
    const SensorMotion T_mid_sensor = motion.motion(mid);
    const Pose guess = motion.guess(mid);
    Placement placed;
    placed.deskewed = scan;
    deskew(placed.deskewed, T_mid_sensor);
    const reg::RegistrationResult r = alignToMap(registrationSource(placed.deskewed), guess);
    placed.summary = summarize(r);
    const Pose mid_pose = placed.summary.ok ? r.T_target_source : guess;
    SensorMotion registered_mid, registered_sweep;
    if (placed.summary.ok && motion.registeredMotion(mid, mid_pose, mid, registered_mid) &&
        motion.registeredMotion(mid, mid_pose, scan.stamp_ns, registered_sweep)) {
      // Refine once: the motion from the last registration to this one replaces the prediction; the
      // frame's pose and stored cloud are at its stamp (first point).
      placed.T_map_lidar = mid_pose * registered_mid(scan.stamp_ns);
      placed.deskewed = scan;
      deskew(placed.deskewed, registered_sweep);
    } else {
      placed.T_map_lidar = mid_pose * T_mid_sensor(scan.stamp_ns);
    }
    if (placed.summary.ok) motion.registered(mid, mid_pose);
    return placed;
  }

  /// The voxelised scan, thinned to kMaxRegistrationPoints, with covariances for GICP.
  reg::PointCloud registrationSource(const Scan& deskewed) const {
    reg::PointCloud v = reg::voxelDownsample(reg::fromScan(deskewed), params.leaf_size_input);
    if (v.size() > kMaxRegistrationPoints) {
      const double stride = double(v.size()) / double(kMaxRegistrationPoints);
      reg::PointCloud thin;
      thin.points.reserve(kMaxRegistrationPoints);
      for (std::size_t i = 0; i < kMaxRegistrationPoints; ++i)
        thin.points.push_back(v.points[std::size_t(double(i) * stride)]);
      v = std::move(thin);
    }
    if (!use_ndt) {  // once, shared by the retries
      reg::CovarianceOptions co;
      co.num_threads = std::max(1, params.mapper_num_threads);
      reg::estimateCovariances(v, co);
    }
    return v;
  }

  static bool accepted(const reg::RegistrationResult& r) {
    return (r.status == reg::Status::kConverged || r.status == reg::Status::kMaxIterations) &&
           r.inlier_ratio >= kMinInlierRatio;
  }

  reg::RegistrationResult alignToMap(const reg::PointCloud& source, const Pose& guess) const {
    reg::RegistrationResult r = align(source, guess, params.mapper_max_correspondence_distance);
    if (!accepted(r)) {
      // Coarse then fine from the same guess: a jerk or a longer gap moves the scan beyond the fine
      // correspondence distance; the frame's lost/kept status is still the tracker's call.
      const reg::RegistrationResult coarse = align(source, guess, kCoarseCorrespondence);
      if (accepted(coarse)) r = align(source, coarse.T_target_source, params.mapper_max_correspondence_distance);
    }
    return r;
  }

  reg::RegistrationResult align(const reg::PointCloud& source, const Pose& guess, double max_corr) const {
    const int threads = std::max(1, params.mapper_num_threads);
    if (use_ndt) {
      reg::NdtParams np;
      np.resolution = params.mapper_resolution;
      np.step_size = params.mapper_step_size;
      np.max_iterations = params.mapper_max_iterations;
      np.num_threads = threads;
      np.max_correspondence_distance = std::max(max_corr, 1.0);
      return reg::alignNdt(*local_map.target(), source, guess, np);
    }
    reg::GicpParams gp;
    gp.max_correspondence_distance = max_corr;
    gp.max_iterations = params.mapper_max_iterations;
    gp.num_threads = threads;
    return reg::alignGicp(*local_map.target(), source, guess, gp);
  }

  static RegistrationSummary summarize(const reg::RegistrationResult& r) {
    const bool converged = r.status == reg::Status::kConverged || r.status == reg::Status::kMaxIterations;
    const bool fit = r.inlier_ratio >= kMinInlierRatio && r.T_target_source.matrix().allFinite();
    RegistrationSummary s{std::string(reg::toString(r.status)), r.iterations, r.inlier_ratio, r.rmse,
                          converged && fit};
    if (converged && !fit) s.status += ", inlier ratio below " + std::to_string(kMinInlierRatio);
    return s;
  }

  /// Update: a keyframe keeps its deskewed scan (for its dense cloud) and feeds the local map. A lost
  /// keyframe restarts the local map (upstream); a failed registration does not feed it, unless
  /// registrations keep failing (the map was restarted from a partial sweep, or the vehicle got far off the
  /// prediction): then the map restarts from this frame at its predicted pose.
  void keep(MapperOutput& out, Placement&& placed) {
    failures_in_a_row = out.registration.ok ? 0 : failures_in_a_row + 1;
    bool feed = false, restart = false;
    if (out.frame.isKeyframe() && out.registration.ok) {
      feed = true;
      restart = out.frame.lost || !local_map.target();
    } else if (failures_in_a_row >= kRestartAfterFailures) {
      feed = restart = true;
      failures_in_a_row = 0;
    }
    std::shared_ptr<const Scan> shared_deskewed;
    // Only keyframes get a dense cloud: targets and the live view read no other (target_window_picks.hpp).
    if (out.frame.isKeyframe() || feed) shared_deskewed = std::make_shared<const Scan>(std::move(placed.deskewed));
    if (out.frame.isKeyframe()) out.deskewed = shared_deskewed;
    if (feed) pending_keyframe = PendingKeyframe{shared_deskewed, placed.T_map_lidar, restart};
  }

  void finishFrame(MapperOutput& out) {
    if (out.deskewed) {
      out.cloud = std::make_shared<const Scan>(
          positionsOnly(reg::voxelDownsample(reg::fromScan(*out.deskewed), params.leaf_size_dense_map), *out.deskewed));
      out.deskewed.reset();
    }
    if (pending_keyframe) {
      const PendingKeyframe k = std::move(*pending_keyframe);
      pending_keyframe.reset();
      local_map.addKeyframe(*k.deskewed, k.pose, k.restart);
    }
  }
};

Mapper::Mapper(const config::Parameters& params, bool deterministic)
    : impl_(std::make_unique<Impl>(params, deterministic)) {}
Mapper::~Mapper() = default;
MapperOutput Mapper::process(Scan scan) { return impl_->process(std::move(scan)); }
void Mapper::deferPostPoseWork(bool defer) { impl_->defer_post_pose = defer; }
void Mapper::finishFrame(MapperOutput& out) { impl_->finishFrame(out); }
const FrameTracker& Mapper::tracker() const { return impl_->tracker; }
bool Mapper::done() const { return impl_->tracker.full(); }
std::size_t Mapper::localMapPoints() const {
  const reg::Target* target = impl_->local_map.target();
  return target ? target->size() : 0;
}

std::shared_ptr<const Scan> Mapper::mapCloud() const {
  const reg::PointCloud merged = impl_->local_map.allKeyframes();
  Scan like;
  like.sensor_id = "map";
  if (merged.empty()) return std::make_shared<const Scan>(like);
  return std::make_shared<const Scan>(reg::toScan(merged, like));
}

}  // namespace rigcal::pipeline
