#pragma once
// The contract between the pipeline and the calibration stage: everything one calibration lidar's
// calibration needs, handed over once when its frame budget is full (or at end of input with at least
// lidar_calibration_min_frames). Clouds are shared, immutable: the mapper goes on while calibration runs.
#include <cstddef>
#include <memory>
#include <string>
#include <vector>

#include "rigcal/core/pose.hpp"
#include "rigcal/core/scan.hpp"
#include "rigcal/core/time.hpp"
#include "rigcal/pipeline/frame_selector.hpp"
#include "rigcal/pipeline/mapping_frame.hpp"
#include "rigcal/pipeline/pairing.hpp"
#include "rigcal/pipeline/target_window_picks.hpp"

namespace rigcal::pipeline {

/// A stored mapping-lidar frame with its cloud: deskewed, in the mapping-lidar frame at its stamp.
struct MappingCloud {
  MappingFrame frame;
  std::shared_ptr<const Scan> cloud;
};

/// One selected calibration frame.
struct CalibrationFrame {
  Pairing pairing;                       // keyframe, scan stamp, T_map_mapping_at_scan, statistics
  std::shared_ptr<const Scan> raw;       // the calibration lidar's scan as decoded (own frame, skewed)
  /// Deskewed through the initial extrinsic, own frame at scan stamp, cropped (calibration_crop.hpp):
  /// positions only (x, y, z; the other arrays empty: never point(), filter()).
  std::shared_ptr<const Scan> deskewed;
  double information = 0.0;              // pcaInformation() of `deskewed`
  /// The mapping clouds its target is built from: indices into CalibrationDataset::mapping_clouds, by
  /// sequence (the keyframes of its window that isTargetCloud() names, target_window_picks.hpp). Empty:
  /// every mapping cloud between its keyframe's kid±N keyframes (a dataset made by hand).
  std::vector<std::size_t> window;
};

struct CalibrationDataset {
  std::string mapping_sensor;
  std::string calibration_sensor;
  Pose T_base_mapping = Pose::Identity();       // from the rig config
  Pose T_mapping_calib_guess = Pose::Identity();  // initial extrinsic: T_base_mapping⁻¹ · T_base_calib
  /// The mapper's whole trajectory so far (poses only, small): lets calibration re-deskew `raw` with
  /// the calibrated extrinsic.
  std::vector<MappingFrame> trajectory;
  /// The mapping clouds the selected frames' targets are built from (each frame's `window`), by sequence,
  /// each once: at most kTargetWindowClouds per frame, picked from the stored mapping frames within
  /// ±dense_pointcloud_num_keyframes keyframes of its keyframe. pairing.keyframe_frame indexes `trajectory`.
  std::vector<MappingCloud> mapping_clouds;
  std::vector<CalibrationFrame> frames;  // selected, most informative first
  std::vector<Rejection> rejected;       // every other candidate and why (ids index `candidates`)
  std::vector<Pairing> candidates;       // every pairing considered
  bool budget_full = false;              // false: handed over at end of input
};

}  // namespace rigcal::pipeline
