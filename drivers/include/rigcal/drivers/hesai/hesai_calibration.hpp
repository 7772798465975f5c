#pragma once
// Hesai angle-correction CSV: one row per channel, "channel, elevation (deg), azimuth offset (deg)",
// after one header line (e.g. "Channel,Elevation,Azimuth" or "Laser id,Elevation,Azimuth").
#include <filesystem>
#include <string_view>
#include <vector>

#include "rigcal/drivers/hesai/hesai_packet.hpp"

namespace rigcal::drivers::hesai {

struct Calibration {
  std::vector<double> elevation_deg;       // index = channel − 1
  std::vector<double> azimuth_offset_deg;  // added to the block azimuth
  [[nodiscard]] std::size_t channels() const { return elevation_deg.size(); }
};

/// Reads `file` for a sensor with `channels` channels. Throws std::runtime_error with one line
/// "<file>:<line>: <what is wrong>" (or "<file>: ..." for whole-file problems): a row without three
/// columns, a value that is not a finite number, an out-of-range angle, channels not numbered
/// 1, 2, 3, ... in order, or a channel count other than `channels`.
Calibration readCalibrationCsv(const std::filesystem::path& file, std::size_t channels);

/// Parses CSV text; `name` is used in error messages in place of a file name.
Calibration parseCalibrationCsv(std::string_view text, std::string_view name, std::size_t channels);

/// The nominal angles of a model when no CSV is given (XT16: +15° to −15° in 2° steps, XT32: +15°
/// to −16° in 1° steps, no azimuth offsets). Throws for PandarQT128, whose per-unit azimuth offsets
/// (up to ±10°) make a calibration file mandatory.
Calibration nominalCalibration(const ModelSpec& spec);

}  // namespace rigcal::drivers::hesai
