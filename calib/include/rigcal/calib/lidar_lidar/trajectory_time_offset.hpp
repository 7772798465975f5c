#pragma once
// The residual clock offset of a calibration lidar against the mapping lidar's trajectory, from the
// calibration frames already registered (their sources and augmented targets reused): for each trial
// offset δ the mapping pose of every frame is taken at (stamp − δ) instead of its stamp, the extrinsic is
// re-fitted over all frames (a few point-to-plane Gauss-Newton steps) and the fit's robust cost recorded;
// a minimum at the last trial is followed outwards; a parabola
// through the best and its neighbours gives δ̂, its curvature and a leave-one-frame-out jackknife its
// uncertainty. Needs no capture time, so it also works on live and shared-memory input.
// Observable only when the frames' motions differ (turning, speed changes): on a straight drive at one
// speed a late clock moves every frame by the same v·δ, which the extrinsic absorbs (the cost is flat).
// Then it says so instead of giving a number.
#include <cstddef>
#include <string>
#include <utility>
#include <vector>

#include "rigcal/core/pose.hpp"
#include "rigcal/core/time.hpp"
#include "rigcal/pipeline/mapping_frame.hpp"
#include "rigcal/registration/deadline.hpp"
#include "rigcal/registration/point_cloud.hpp"
#include "rigcal/registration/target.hpp"

namespace rigcal::calib {

/// One registered calibration frame: its source (calibration-lidar frame at `stamp_ns`) and its target
/// (the mapping lidar's cloud in the mapping-lidar frame at `stamp_ns`, with normals).
struct TrajectoryClockFrame {
  const registration::PointCloud* source = nullptr;
  const registration::Target* target = nullptr;
  TimeNs stamp_ns = 0;
};

struct TrajectoryClockOptions {
  std::vector<double> shifts_ms = {-50, -20, -10, -5, 0, 5, 10, 20, 50};  // trial offsets δ
  /// A minimum at the last trial is followed outwards (doubling) up to this offset.
  double max_shift_ms = 400.0;
  std::size_t max_points = 8000;    // source points over all frames (every k-th of each frame)
  int iterations = 4;               // Gauss-Newton steps per trial offset (warm-started from its neighbour)
  double max_distance = 0.2;        // m: correspondences farther count as outliers at this distance
  /// A larger σ is no estimate: "unobservable". 20: over shared memory a lidar 35 ms late registered on
  /// two frames gave +38.7 ± 15.5 ms (and a 3.6 cm error printed ok without it).
  double max_uncertainty_ms = 20.0;
  /// Residuals per frame counted as independent in the curvature's σ (points on one surface share its
  /// error in the map): 200 put a flat two-frame profile (0.2 % over ±50 ms) at ± 69 ms, a 15 % one at ± 2.6 ms.
  double independent_points_per_frame = 200.0;
  int num_threads = 1;  // the residual passes (the estimate does not depend on it)
};

struct TrajectoryClockEstimate {
  enum class Status { kNotRun, kEstimated, kUnobservable, kDeadline };
  Status status = Status::kNotRun;
  double offset_ms = 0.0;       // δ̂: the calibration lidar's stamps are this much late (time_offset_ns sign)
  double uncertainty_ms = 0.0;  // one standard error
  std::string note;             // why unobservable / not estimated, or how it was estimated
  std::vector<std::pair<double, double>> profile;  // (δ ms, cost m² per point) for each trial done
  std::size_t frames = 0;
  std::size_t points = 0;
  double seconds = 0.0;
};

const char* toString(TrajectoryClockEstimate::Status s);

/// `trajectory`: the mapping lidar's poses (strictly increasing stamps); `T_mapping_calib`: the calibrated
/// extrinsic. Stops with kDeadline when `deadline` expires before every trial offset was fitted.
TrajectoryClockEstimate estimateTrajectoryClockOffset(const std::vector<TrajectoryClockFrame>& frames,
                                                      const std::vector<pipeline::MappingFrame>& trajectory,
                                                      const Pose& T_mapping_calib,
                                                      const registration::Deadline& deadline,
                                                      const TrajectoryClockOptions& options = {});

/// How far (ms) the farthest local minimum of a cost profile over sorted trial offsets lies from `offset_ms`
/// (0 with a single dip): a second dip is noise as large as the signal, so the estimate is no better than that.
double farthestDip(const std::vector<double>& shifts_ms, const std::vector<double>& cost, double offset_ms);

/// The vertex of the parabola through three (x, y) points: (x at the minimum, curvature a of y ≈ a·x² + …).
/// a ≤ 0: no minimum.
std::pair<double, double> parabolaVertex(const std::pair<double, double>& p0, const std::pair<double, double>& p1,
                                         const std::pair<double, double>& p2);

}  // namespace rigcal::calib
