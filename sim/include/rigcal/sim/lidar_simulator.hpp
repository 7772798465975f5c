#pragma once
// The physics of one lidar: every beam of every firing sequence is cast into the scene at its own
// firing time, from where the sensor really is at that instant (the vehicle moves during a sweep, so
// sweeps come out skewed exactly like real ones). Returns get range noise, dropouts (random and by
// material), a reflectivity-dependent maximum range, the minimum range, and quantisation to the
// model's distance unit. Noise is a pure function of (seed, sensor, sequence, beam): the output does
// not depend on how the work is split between threads.
#include <cstdint>
#include <vector>

#include "rigcal/core/pose.hpp"
#include "rigcal/sim/firing.hpp"
#include "rigcal/sim/lidar_model.hpp"
#include "rigcal/sim/scenario.hpp"
#include "rigcal/sim/scene.hpp"
#include "rigcal/sim/trajectory.hpp"

namespace rigcal::sim {

struct CastStats {
  std::uint64_t rays = 0;
  std::uint64_t returns = 0;  // valid returns after every filter
};

class LidarSimulator {
 public:
  LidarSimulator(const LidarModel& model, const Scene& scene, const Trajectory& trajectory,
                 TimeNs trajectory_start_ns, const Pose& T_base_sensor, const NoiseSpec& noise,
                 std::uint64_t noise_key);

  /// Fills returns and points of firings [begin, end) of `batch` (already sized to the firing count).
  /// Safe to call concurrently on disjoint ranges.
  void cast(FiringBatch& batch, std::size_t begin, std::size_t end, CastStats& stats) const;

  /// T_world_sensor at a true time (exact trajectory pose).
  [[nodiscard]] Pose sensorPose(TimeNs true_time) const;
  [[nodiscard]] const LidarModel& model() const { return *model_; }

 private:
  struct BeamTerms {
    double cos_el, sin_el, cos_az, sin_az;  // elevation and total azimuth offset
    double time_fraction;                   // firing delay / sequence period
    double cos_origin, sin_origin;          // LidarBeam::origin_azimuth_deg
  };
  const LidarModel* model_;
  const Scene* scene_;
  const Trajectory* trajectory_;
  TimeNs start_ns_;
  Pose T_base_sensor_;
  NoiseSpec noise_;
  std::uint64_t key_;
  std::vector<BeamTerms> beams_;
  bool origin_per_beam_ = false;  // some beam's origin stands off the sequence start's
  TimeNs period_ns_;  // sequence period, rounded (only used to place the end-of-sequence pose)
};

}  // namespace rigcal::sim
