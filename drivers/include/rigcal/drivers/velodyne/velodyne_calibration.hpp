#pragma once
// Per-laser calibration of a Velodyne sensor, read from the ROS velodyne_pointcloud YAML (angles in
// radians, lengths in metres) or a VeloView XML (boost_serialization "DB": angles in degrees, lengths
// in centimetres), or the built-in nominal table of the model.
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "rigcal/drivers/velodyne/velodyne_packet.hpp"

namespace rigcal::drivers::velodyne {

struct LaserCorrection {
  double rot_correction_rad = 0;   // subtracted from the rotor azimuth (ROS/VeloView convention)
  double vert_correction_rad = 0;  // elevation of the beam
  double dist_correction_m = 0;    // added to every non-zero distance
  double vert_offset_m = 0;        // beam origin above the optical centre
  double horiz_offset_m = 0;       // beam origin beside the optical centre
};

struct Calibration {
  std::vector<LaserCorrection> lasers;  // indexed by laser id
  std::string source;                   // file name, or "nominal VLP-16"
};

/// Reads a calibration file for `model`: VeloView XML when the text starts with '<' (after
/// whitespace), ROS YAML otherwise. Throws std::runtime_error "<file>: <field>: <what is wrong>".
Calibration loadCalibration(const std::filesystem::path& file, Model model);

/// The same from text; `name` is used in error messages.
Calibration parseYamlCalibration(std::string_view text, const std::string& name, Model model);
Calibration parseXmlCalibration(std::string_view text, const std::string& name, Model model);

/// Nominal elevation / azimuth-offset tables from the user manuals (VLP-16, VLP-32C, HDL-32E);
/// nullopt for the VLS-128, whose per-unit table must come from a file.
std::optional<Calibration> nominalCalibration(Model model);

}  // namespace rigcal::drivers::velodyne
