#pragma once
// Which of a calibration frame's window clouds its augmented target is built from: a window of
// 2·dense_pointcloud_num_keyframes keyframes holds ~150 stored mapping frames (one every few centimetres
// of path), most of them redundant once voxelised, so a target takes at most kTargetWindowClouds of them,
// evenly spread, the keyframe's own always among them. The pipeline keeps only these clouds for a
// candidate and hands only these over; calib's targetWindow() picks with the same rule, so both agree.
#include <cstddef>
#include <vector>

namespace rigcal::pipeline {

/// The most mapping clouds one calibration frame's target is built from (calib's default max_clouds).
inline constexpr std::size_t kTargetWindowClouds = 12;

/// Positions in [0, count) of at most `max_picks` window clouds, evenly spread and ascending, always
/// including `own` when own < count (it replaces the nearest pick). All of them when count <= max_picks
/// or max_picks == 0.
std::vector<std::size_t> spreadWindowPicks(std::size_t count, std::size_t own, std::size_t max_picks);

}  // namespace rigcal::pipeline
