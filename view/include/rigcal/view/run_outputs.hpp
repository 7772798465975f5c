#pragma once
// A finished run's outputs as view messages: report.json, map.pcd (decimated), and per calibration lidar
// <name>_before.pcd / <name>_after.pcd. Used by `rigcal view OUT_DIR` and by `calibrate --view` once its
// outputs are written. Only these fixed names in the given folder are read.
#include <cstddef>
#include <filesystem>
#include <string>
#include <vector>

#include "rigcal/view/view_server.hpp"

namespace rigcal::view {

struct RunOutputsSummary {
  std::vector<std::string> lidars;  // in lane order
  std::size_t map_points = 0;       // sent (after decimation)
  std::size_t cloud_points = 0;     // before + after, all lidars
};

/// The calibration lidars of report.json, in its order (its "lidars" entries' "calibration_sensor"), else
/// the <name>_before.pcd files of `dir`, sorted.
std::vector<std::string> lidarsOfRun(const std::filesystem::path& dir, const std::string& report_json);

/// Publishes `dir`'s outputs to `server` (kept for later clients). `lidars` empty: lidarsOfRun().
/// Throws std::runtime_error (one line naming the file) when report.json is missing or unreadable, or a
/// cloud that exists cannot be read. `with_map`: false when the live view already sent the map.
RunOutputsSummary publishRunOutputs(ViewServer& server, const std::filesystem::path& dir,
                                    std::vector<std::string> lidars = {}, bool with_map = true,
                                    double voxel_m = 0.25);

}  // namespace rigcal::view
