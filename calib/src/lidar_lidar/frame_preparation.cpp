#include "rigcal/calib/lidar_lidar/frame_preparation.hpp"

#include <chrono>
#include <utility>

#include "rigcal/calib/lidar_lidar/calibration_source.hpp"

namespace rigcal::calib {

namespace {
double secondsSince(std::chrono::steady_clock::time_point t) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
}
}  // namespace

PreparedFrame prepareFrame(const FramePreparationInputs& in, const config::Parameters& params,
                           std::size_t min_source_points) {
  PreparedFrame p;
  p.index = in.index;
  auto t = std::chrono::steady_clock::now();
  SourceOptions so;
  so.covariances = false;  // GICP's, estimated when a GICP first runs on the frame
  so.num_threads = in.num_threads;
  p.source = buildSource(*in.deskewed, params, so);
  p.source_seconds = secondsSince(t);
  p.out_of_time = in.target.deadline.expired();
  if (p.out_of_time || p.source.size() < min_source_points) return p;
  t = std::chrono::steady_clock::now();
  p.clouds = in.window.clouds.size();
  p.cloud = augmentedCloud(in.window, p.source, params, in.target, &p.cropped);
  p.crop_seconds = secondsSince(t);
  p.out_of_time = in.target.deadline.expired();
  return p;
}

void FramePrefetch::start(FramePreparationInputs in, const config::Parameters& params,
                          std::size_t min_source_points) {
  abandon();
  index_ = in.index;
  // Its own token on the same deadline, so that abandon() can stop it without cancelling the run. A
  // cancelled run stops it through the owner, which abandons it.
  in.target.deadline = registration::Deadline::at(in.target.deadline.when(), &cancel_);
  pending_ = std::async(std::launch::async, [in = std::move(in), &params, min_source_points] {
    return prepareFrame(in, params, min_source_points);
  });
}

std::optional<PreparedFrame> FramePrefetch::take(std::size_t index) {
  if (!pending_.valid()) return std::nullopt;
  if (index_ != index) {
    abandon();
    return std::nullopt;
  }
  auto prepared = pending_.get();  // leaves pending_ invalid
  return prepared;
}

void FramePrefetch::abandon() {
  if (!pending_.valid()) return;
  cancel_.cancel();
  pending_.wait();
  pending_ = {};
  cancel_.reset();
}

}  // namespace rigcal::calib
