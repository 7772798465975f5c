#pragma once
// What a spinning lidar model is, as the simulator and the packet encoders need it: its beams (real
// vendor angle tables), when each beam fires within a firing sequence, how fast the rotor spins, and
// how ranges are measured and quantised.
//
// Conventions (shared with rigcal's decoders):
//  - Sensor frame: x forward, y left, z up. Velodyne and Hesai native frames (y forward, x right) are
//    rotated into it; Ouster points are in Ouster's "sensor" frame (lidar_to_sensor_transform applied).
//  - Azimuth a is measured clockwise seen from above, from +x, as the rotor turns (the Velodyne and
//    Hesai packet azimuth). A beam with elevation ω at azimuth a points along
//    (cos ω·cos a, −cos ω·sin a, sin ω).
//  - A firing sequence fires every beam once; sequences repeat every `firingPeriodNs()`. The rotor
//    azimuth at sensor-clock time t is  scan_phase + 360°·rotation_hz·t  (phase-locked to the second).
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include <Eigen/Core>

#include "rigcal/core/time.hpp"

namespace rigcal::sim {

enum class LidarVendor : std::uint8_t { kVelodyne, kOuster, kHesai, kRobosense };

struct LidarBeam {
  double elevation_deg = 0;       // ω
  double azimuth_offset_deg = 0;  // added to the rotor azimuth (Velodyne: −rot_correction)
  TimeNs time_offset_ns = 0;      // when this beam fires after its sequence starts
  // Rotor azimuth, from the sequence start's, where the beam origin stands when it fires (RS-Helios-16P:
  // the decoders' share of the block's azimuth step; 0 for the others).
  double origin_azimuth_deg = 0;
};

struct LidarModel {
  std::string name;  // as rig files and decoders spell it: "VLP-16", "OS1-64", "PandarXT32", ...
  LidarVendor vendor = LidarVendor::kVelodyne;
  std::vector<LidarBeam> beams;  // in the order the packets carry them (laser id / channel / pixel row)

  double rotation_hz = 10.0;
  // One firing sequence lasts period_num / period_den ns (rational: Ouster's 100 ms / 1024 is not a
  // whole number of nanoseconds).
  std::int64_t period_num_ns = 55'296;
  std::int64_t period_den = 1;

  double distance_unit_m = 0.002;  // range quantum in packets
  double min_range_m = 0.5;        // returns nearer than this are not reported
  double max_range_m = 100.0;      // for a bright (80 %) target; dark targets fade sooner

  // Ouster measures range from a beam origin on a circle of radius `beam_origin_radius_m` around the
  // rotor axis, at height `beam_origin_z_m` in the sensor frame, and reports range from the lidar
  // origin (travel + radius). Zero for Velodyne and Hesai.
  double beam_origin_radius_m = 0.0;
  double beam_origin_z_m = 0.0;
  // RoboSense reports the range from the beam origin (its lens, 34.98 mm off the axis) instead: the
  // decoder adds the lens position to range · direction.
  bool range_from_beam_origin = false;

  // True when each beam sees the rotor where it stands at the beam's own firing time (Velodyne: the
  // decoder interpolates the azimuth by firing time); false when the vendor's angle table already
  // describes each beam at the sequence start azimuth (Hesai, Ouster).
  bool azimuth_follows_firing_time = true;
  // Rotor azimuth where a frame (one sweep) begins: 0 (forward) for Velodyne/Hesai cut at 0°, 180°
  // for Ouster, whose measurement id 0 faces backwards.
  double frame_start_azimuth_deg = 0.0;
  // Ouster: columns per frame (measurement ids); 0 for the others.
  int columns_per_frame = 0;

  [[nodiscard]] std::size_t beamCount() const { return beams.size(); }
  [[nodiscard]] double firingPeriodNs() const { return double(period_num_ns) / double(period_den); }
  [[nodiscard]] TimeNs framePeriodNs() const { return TimeNs(1e9 / rotation_hz + 0.5); }
  /// Firing sequences per rotation (not a whole number for Velodyne, which is not column-locked).
  [[nodiscard]] double firingsPerRotation() const { return 1e9 / rotation_hz / firingPeriodNs(); }
  /// Unit direction of `beam` when the rotor stands at `rotor_azimuth_deg` at the sequence start.
  [[nodiscard]] Eigen::Vector3d direction(std::size_t beam, double rotor_azimuth_deg) const;
  /// Where the beams leave the sensor (sensor frame) at that rotor azimuth (see LidarBeam::origin_azimuth_deg).
  [[nodiscard]] Eigen::Vector3d beamOrigin(double rotor_azimuth_deg) const;
  /// Total azimuth of a beam at a sequence starting at rotor_azimuth_deg (offset and, when the
  /// azimuth follows firing time, the rotation during the beam's delay).
  [[nodiscard]] double beamAzimuthDeg(std::size_t beam, double rotor_azimuth_deg) const;
  /// The point a decoder reconstructs from a reported range (metres, from the lidar origin).
  [[nodiscard]] Eigen::Vector3d point(std::size_t beam, double rotor_azimuth_deg, double range_m) const;
};

/// The built-in model called `name`; throws std::invalid_argument listing the known names.
const LidarModel& lidarModel(std::string_view name);
/// Names of every built-in model.
std::vector<std::string> lidarModelNames();

/// Unit direction for clockwise azimuth a and elevation ω (degrees), sensor frame.
Eigen::Vector3d beamDirection(double azimuth_deg, double elevation_deg);

namespace detail {
// Vendor tables, one file each (lidar_models_<vendor>.cpp).
LidarModel makeVlp16();
LidarModel makeVlp32c();
LidarModel makeVls128();
LidarModel makeOs1_64();
LidarModel makeOs1_128();
LidarModel makePandarXt32();
LidarModel makePandar64();
// Pandar64 timing shared by its model and encoder: one firing round, and how long before the round's
// block time its earliest laser fires (the manual's table starts at −54.668 µs).
inline constexpr std::int64_t kPandar64RoundNs = 55'560;
inline constexpr std::int64_t kPandar64EarliestNs = 54'668;
LidarModel makeHelios16p();
// RS-Helios-16P: the DIFOP horizontal offset of `beam` (0.01° steps): its azimuth offset from where its
// lens stands (lidar_models_robosense.cpp).
double helios16pHorizontalOffsetDeg(const LidarModel& model, std::size_t beam);
}  // namespace detail

}  // namespace rigcal::sim
