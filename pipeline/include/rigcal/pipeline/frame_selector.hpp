#pragma once
// Chooses the calibration frames of one calibration lidar among its accepted pairings: away from lost
// keyframes, not flat (PCA), spread along the path, within the frame budget. Ranked (calibration_frame_ranking)
// by "information": greedily, each next frame the one that most raises the weakest direction of the summed
// point-to-plane information of the frames chosen so far (frame_information.hpp), so the first frames a
// deadline lets through already constrain all six directions; or by "pca": the PCA spread alone.
#include <cstddef>
#include <string>
#include <vector>

#include "rigcal/config/parameters.hpp"
#include "rigcal/core/scan.hpp"
#include "rigcal/registration/point_to_plane_information.hpp"

namespace rigcal::pipeline {

struct SelectionCandidate {
  std::size_t id = 0;        // the caller's handle
  int keyframe_index = 0;    // among the mapper's keyframes
  double path_length = 0.0;  // of that keyframe, metres
  double information = 0.0;  // pcaInformation() of the calibration cloud
  registration::PointToPlaneInformation planes;  // frameInformation() of the calibration cloud
};

struct Rejection {
  std::size_t id;
  std::string reason;
};

struct Selection {
  std::vector<std::size_t> selected;  // ids, in the order chosen (most informative first)
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

/// Deterministic: ties are broken by PCA information, then by id.
Selection selectFrames(const std::vector<SelectionCandidate>& candidates,
                       const std::vector<int>& lost_keyframe_indices, const config::Parameters& params);

}  // namespace rigcal::pipeline
