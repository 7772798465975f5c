#pragma once
// overview.png: a top-down picture of the result, readable without any other tool. Two panels side by
// side, "BEFORE" (initial extrinsics) and "AFTER" (calibrated), each with the mapping lidar's map in grey
// and every calibration lidar's points in its own colour (legend at the top), plus a zoomed inset on a
// feature (the 4 m square where the calibration points are densest, 1 px = 1 cm) whose place is outlined.
#include <cstdint>
#include <filesystem>
#include <vector>

#include "rigcal/calib/outputs/calibration_outcome.hpp"

namespace rigcal::calib {

struct RgbImage {
  int width = 0, height = 0;
  std::vector<std::uint8_t> rgb;  // row-major, 3 bytes per pixel
  void set(int x, int y, std::uint8_t r, std::uint8_t g, std::uint8_t b);
};

/// Renders the overview (panel_size × panel_size per panel).
RgbImage renderOverview(const CalibrationOutcome& outcome, int panel_size = 800);

/// Throws std::runtime_error "<path>: <why>" when it cannot be written.
void writePng(const std::filesystem::path& path, const RgbImage& image);

void writeOverviewPng(const std::filesystem::path& path, const CalibrationOutcome& outcome, int panel_size = 800);

}  // namespace rigcal::calib
