#include "rigcal/calib/lidar_lidar/lidar_lidar_calibration.hpp"

#include <algorithm>
#include <exception>
#include <iomanip>
#include <sstream>

#include "lidar_lidar_calibrator.hpp"
#include "rigcal/calib/lidar_lidar/calibration_budget.hpp"
#include "rigcal/calib/lidar_lidar/lidar_lidar_verdict.hpp"
#include "rigcal/calib/lidar_lidar/mapping_cloud_release.hpp"

namespace rigcal::calib {

using detail::Clock;
using detail::finitePose;
using detail::since;

namespace {

TrajectoryClockEstimate trajectoryClock(const pipeline::CalibrationDataset& dataset, const detail::Calibrator& calibrator,
                                        const LidarLidarResult& result, const registration::Deadline& deadline,
                                        const LidarLidarOptions& options) {
  std::vector<TrajectoryClockFrame> frames;
  for (const auto& f : calibrator.frames())
    frames.push_back({&f.source, f.target.get(), dataset.frames[f.index].pairing.scan_stamp_ns});
  TrajectoryClockOptions clock = options.trajectory_clock_options;
  clock.num_threads = options.num_threads;
  try {
    return estimateTrajectoryClockOffset(frames, dataset.trajectory, result.T_mapping_calib, deadline, clock);
  } catch (const std::exception& e) {  // a trajectory it cannot interpolate: no estimate, the calibration stands
    TrajectoryClockEstimate none;
    none.status = TrajectoryClockEstimate::Status::kUnobservable;
    none.note = e.what();
    return none;
  }
}

/// Each frame's information at the result, estimated from at most `max_points` source points in all (every
/// stride-th, times the stride: the verdict sets it against the frame's score as the points' noise): ~20k
/// nearest-neighbour queries, tens of milliseconds, not cut.
void frameInformation(const detail::Calibrator& calibrator, const config::Parameters& params, LidarLidarResult& out,
                      std::size_t max_points = 20000) {
  std::size_t total = 0;
  for (const auto& f : calibrator.frames()) total += f.source.size();
  const std::size_t stride = std::max<std::size_t>(1, (total + max_points - 1) / max_points);
  for (const auto& f : calibrator.frames())
    out.frame_information[int(f.index)] =
        double(stride) * framePoseInformation(*f.target, f.source, out.T_mapping_calib,
                                              params.calibration_eval_max_corr_distance, stride);
}

/// Where the searches for another basin stop: `search_share` of the time left, less what a second clock
/// estimate would take (as long as the first, and half again) should they find a better result.
registration::Deadline searchDeadline(const registration::Deadline& deadline, const LidarLidarOptions& options,
                                      const LidarLidarResult& out) {
  if (deadline.when() == registration::Deadline::Clock::time_point::max()) return deadline;
  const double reestimate = options.trajectory_clock ? 1.5 * out.trajectory_clock.seconds : 0.0;
  const double left = std::max(0.0, secondsLeft(deadline) - reestimate);
  return earlierBy(deadline, reestimate + (1.0 - std::clamp(options.search_share, 0.0, 1.0)) * left);
}

/// calibrateLidarLidar; `drop_clouds` is null or `dataset`, whose mapping clouds then go as the targets are built.
LidarLidarResult calibrate(const pipeline::CalibrationDataset& dataset, const config::Parameters& params,
                           const registration::Deadline& deadline, const LidarLidarOptions& options,
                           pipeline::CalibrationDataset* drop_clouds) {
  const auto t0 = Clock::now();
  LidarLidarResult out;
  out.mapping_sensor = dataset.mapping_sensor;
  out.calibration_sensor = dataset.calibration_sensor;
  out.T_mapping_calib_guess = dataset.T_mapping_calib_guess;
  out.T_mapping_calib = finitePose(dataset.T_mapping_calib_guess) ? dataset.T_mapping_calib_guess : Pose::Identity();
  if (deadline.when() != registration::Deadline::Clock::time_point::max())
    out.deadline_share_s = std::max(0.0, secondsLeft(deadline));
  out.failure = validateDataset(dataset, params);
  if (out.failure.empty()) {
    try {
      detail::Calibrator::TargetsDone release;
      if (drop_clouds != nullptr)
        release = [drop_clouds](std::size_t first_pending) { dropMappingCloudsDoneWith(*drop_clouds, first_pending); };
      detail::Calibrator calibrator(dataset, params, deadline, options, out, release);
      const bool plan_complete = calibrator.run();
      // A plan cut before its last target: the clouds of the frames never built go too.
      if (release) release(dataset.frames.size());
      // The evidence the verdict weighs besides the runs: each frame's information, the clock's offset.
      const auto evidence = [&] {
        if (out.ok) frameInformation(calibrator, params, out);
        if (options.trajectory_clock && out.ok)
          out.trajectory_clock = trajectoryClock(dataset, calibrator, out, deadline, options);
      };
      evidence();
      // Only a complete plan searches further (the clock estimate came first: the plan reserved its time).
      if (plan_complete && calibrator.searchForAnotherBasin(searchDeadline(deadline, options, out)))
        evidence();
    } catch (const std::exception& e) {  // a bad dataset the validation did not foresee: a clear failure
      out.ok = false;
      out.T_mapping_calib = dataset.T_mapping_calib_guess;  // validated finite
      out.failure = dataset.calibration_sensor + ": " + e.what();
    }
  }
  out.seconds = since(t0);
  if (!out.ok && out.deadline_reached && out.deadline_share_s >= 0) {  // say that time, not data, was short
    std::ostringstream msg;
    msg << "deadline: its share of calibration_deadline_s was " << std::fixed << std::setprecision(2)
        << out.deadline_share_s << " s; " << out.failure;
    out.failure = msg.str();
  }
  judgeLidarLidar(out, dataset.frames.size(), params.calibration_deadline_s);
  return out;
}

}  // namespace

LidarLidarResult calibrateLidarLidar(const pipeline::CalibrationDataset& dataset, const config::Parameters& params,
                                     const registration::Deadline& deadline, const LidarLidarOptions& options) {
  return calibrate(dataset, params, deadline, options, nullptr);
}

LidarLidarResult calibrateLidarLidarDroppingClouds(pipeline::CalibrationDataset& dataset, const config::Parameters& params,
                                                   const registration::Deadline& deadline,
                                                   const LidarLidarOptions& options) {
  return calibrate(dataset, params, deadline, options, &dataset);
}

}  // namespace rigcal::calib
