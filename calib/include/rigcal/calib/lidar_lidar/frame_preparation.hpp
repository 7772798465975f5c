#pragma once
// A frame's source and cropped augmented cloud: the part of its build before the Target, single-threaded
// for the most part (the crop places and tests every point of a dozen mapping clouds: ~2.6 M on the
// street's VLS-128 map). FramePrefetch runs the next frame's on a thread of its own while the current
// frame's target is built and confirmed, so that the second core does it instead of idling through the
// serial stretches of that work.
#include <cstddef>
#include <future>
#include <memory>
#include <optional>

#include "rigcal/calib/lidar_lidar/augmented_target.hpp"
#include "rigcal/config/parameters.hpp"
#include "rigcal/core/scan.hpp"
#include "rigcal/registration/deadline.hpp"
#include "rigcal/registration/point_cloud.hpp"

namespace rigcal::calib {

struct PreparedFrame {
  std::size_t index = 0;             // in the dataset
  registration::PointCloud source;   // within the calibration range; no covariances yet
  registration::PointCloud cloud;    // the augmented cloud, cropped and voxelised (empty: too few source points)
  std::size_t clouds = 0;            // mapping clouds in its window
  std::size_t cropped = 0;           // points the crop kept, before the voxels
  double source_seconds = 0.0;
  double crop_seconds = 0.0;
  bool out_of_time = false;          // the deadline passed before it was done: nothing to build from
};

/// Everything a preparation reads, held by value: it may run while the dataset lets go of its clouds.
struct FramePreparationInputs {
  std::size_t index = 0;
  std::shared_ptr<const Scan> deskewed;
  TargetWindowClouds window;
  AugmentedTargetOptions target;  // its deadline ends the preparation
  int num_threads = 1;            // of the source's range filter
};

/// Builds the source; crops the window around it unless it has fewer than `min_source_points`.
PreparedFrame prepareFrame(const FramePreparationInputs& in, const config::Parameters& params,
                           std::size_t min_source_points);

/// At most one preparation running ahead of the frame being built.
class FramePrefetch {
 public:
  FramePrefetch() = default;
  FramePrefetch(const FramePrefetch&) = delete;
  FramePrefetch& operator=(const FramePrefetch&) = delete;
  ~FramePrefetch() { abandon(); }

  /// Starts preparing in.index on a thread of its own (abandoning any other), until `deadline` or abandon().
  void start(FramePreparationInputs in, const config::Parameters& params, std::size_t min_source_points);
  /// The preparation of frame `index`, once done; nullopt when none was started for it.
  std::optional<PreparedFrame> take(std::size_t index);
  /// Stops a preparation nobody will read and waits for its thread.
  void abandon();

 private:
  registration::CancelToken cancel_;
  std::size_t index_ = 0;
  std::future<PreparedFrame> pending_;
};

}  // namespace rigcal::calib
