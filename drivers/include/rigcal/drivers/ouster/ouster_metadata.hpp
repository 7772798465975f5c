#pragma once
// The Ouster sensor_info JSON ("metadata"), as written by the sensor and ouster-sdk from firmware 1.12
// to 3.x, in either layout:
//  - legacy (flat): beam_altitude_angles, beam_azimuth_angles, lidar_mode, data_format{...},
//    lidar_origin_to_beam_origin_mm, lidar_to_sensor_transform, prod_line, ... at the top level;
//  - current (nested): sensor_info{}, beam_intrinsics{}, lidar_intrinsics{}, lidar_data_format{},
//    config_params{}, calibration_status{}.
// A file with any of the nested sections is read as the current layout, and then needs sensor_info,
// calibration_status, beam_intrinsics, lidar_intrinsics and lidar_data_format (firmware 1.12/1.13
// answered "error: Command not recognized." for lidar_data_format: the format then follows lidar_mode).
// A data_format that is present must be complete. Missing optional items take ouster-sdk's defaults.
#include <array>
#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "rigcal/drivers/ouster/ouster_packet_format.hpp"

namespace rigcal::drivers::ouster {

struct Metadata {
  std::string source;            // file name (or label) used in messages
  bool nested_layout = false;    // the current (non-legacy) layout
  std::string prod_line;         // "OS-1-64", "OS-0-128", ... (empty when the file does not say)
  std::uint64_t serial = 0;      // prod_sn, 0 when unknown
  std::uint32_t init_id = 0;     // initialization_id, 0 when unknown
  std::string firmware;          // "v2.3.0" as found in build_rev / image_rev, empty when unknown
  int fw_major = -1, fw_minor = -1, fw_patch = -1;

  std::string lidar_mode;        // "1024x10"
  int columns_per_frame = 1024;
  int frames_per_second = 10;
  int pixels_per_column = 0;
  int columns_per_packet = 16;
  int column_window_first = 0, column_window_last = 1023;  // inclusive, may wrap (first > last)
  std::vector<int> pixel_shift_by_row;
  UdpProfile profile = UdpProfile::kLegacy;

  std::vector<double> beam_altitude_deg, beam_azimuth_deg;
  double lidar_origin_to_beam_origin_mm = 0;
  std::array<double, 16> beam_to_lidar{};     // row-major 4x4, mm
  std::array<double, 16> lidar_to_sensor{};   // row-major 4x4, mm

  /// The packet footer carries a CRC-64 (firmware ≥ 3.1, eUDP profiles other than FUSA).
  [[nodiscard]] bool crcFooter() const;
  /// Packet slots in a frame: columns_per_frame / columns_per_packet.
  [[nodiscard]] int packetSlots() const { return columns_per_frame / columns_per_packet; }
  /// Whether the sensor sends packet slot `slot` (columns slot·cpp ... slot·cpp+cpp−1): true when one
  /// of its columns lies in the column window.
  [[nodiscard]] bool slotInWindow(int slot) const;
  [[nodiscard]] bool columnInWindow(int column) const;
};

/// Parses a sensor_info JSON file. Throws std::runtime_error with one line
/// "<file>: <field>: <what is wrong>" when the file is unreadable, not JSON, or misses/has a bad field.
Metadata parseMetadataFile(const std::filesystem::path& file);
/// Same, from text; `source` names it in messages.
Metadata parseMetadata(std::string_view json_text, const std::string& source);

}  // namespace rigcal::drivers::ouster
