#pragma once
// Which mapping clouds a calibration frame's augmented target is built from. Its window, the keyframes
// kid±dense_pointcloud_num_keyframes, holds ~150 stored mapping frames (one every few centimetres of path),
// most of them redundant once voxelised; a target takes every stride-th keyframe of it (by keyframe_index)
// and its own keyframe: at most kTargetWindowClouds clouds ~2 m apart. Because the rule names keyframes, not
// positions within a window, neighbouring candidates pick the same clouds and share them, and the pipeline
// stores no other cloud (issue #18: with picks spread within each window, the candidates waiting for a
// lidar's budget held ~200 different clouds). A dataset made by hand, without windows, is spread evenly
// (spreadWindowPicks, calib's targetWindow()).
#include <cstddef>
#include <vector>

#include "rigcal/pipeline/mapping_frame.hpp"

namespace rigcal::pipeline {

/// The most mapping clouds one calibration frame's target is built from (calib's default max_clouds).
inline constexpr std::size_t kTargetWindowClouds = 12;

/// Every how many keyframes a target cloud is taken: the smallest stride at which a window of
/// ±window_keyframes keyframes holds at most max_picks − 1 of them, the last place kept for the frame's own
/// keyframe (2 for the defaults: ±10 keyframes, 12 clouds).
int targetKeyframeStride(int window_keyframes, std::size_t max_picks);

/// Whether stored mapping frame `f` is a cloud the target of a frame paired with keyframe `own_keyframe`
/// (a keyframe_index) is built from, when `f` lies in that frame's window: a keyframe on the stride, or
/// that keyframe itself.
bool isTargetCloud(const MappingFrame& f, int own_keyframe, int stride);

/// Positions in [0, count) of at most `max_picks` window clouds, evenly spread and ascending, always
/// including `own` when own < count (it replaces the nearest pick). All of them when count <= max_picks
/// or max_picks == 0.
std::vector<std::size_t> spreadWindowPicks(std::size_t count, std::size_t own, std::size_t max_picks);

}  // namespace rigcal::pipeline
