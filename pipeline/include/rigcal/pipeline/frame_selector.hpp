#pragma once
// Chooses the calibration frames of one calibration lidar among its accepted pairings: away from lost
// keyframes, informative (PCA), spread along the path, within the frame budget.
#include <cstddef>
#include <string>
#include <vector>

#include "rigcal/config/parameters.hpp"
#include "rigcal/core/scan.hpp"

namespace rigcal::pipeline {

struct SelectionCandidate {
  std::size_t id = 0;        // the caller's handle
  int keyframe_index = 0;    // among the mapper's keyframes
  double path_length = 0.0;  // of that keyframe, metres
  double information = 0.0;  // pcaInformation() of the calibration cloud
};

struct Rejection {
  std::size_t id;
  std::string reason;
};

struct Selection {
  std::vector<std::size_t> selected;  // ids, most informative first
  std::vector<Rejection> rejected;    // every other candidate and why
  [[nodiscard]] bool budgetFull(const config::Parameters& p) const {
    return int(selected.size()) >= p.lidar_calibration_max_frames;
  }
  [[nodiscard]] bool enough(const config::Parameters& p) const {
    return int(selected.size()) >= p.lidar_calibration_min_frames;
  }
};

/// sqrt of the smallest eigenvalue of the points' covariance: small for a plane or a line.
double pcaInformation(const Scan& cloud);

/// Deterministic: ties in information are broken by id.
Selection selectFrames(const std::vector<SelectionCandidate>& candidates,
                       const std::vector<int>& lost_keyframe_indices, const config::Parameters& params);

}  // namespace rigcal::pipeline
