#pragma once
// The vehicle's outline on the ground in base_link (x forward, y left, z up; base_link on the ground).
// Base-lidar calibration fits the ground plane on this patch: on uneven ground that plane is the
// surface the wheels stand on, whereas a wide box fits the terrain's mean and carries its tilt.
#include "rigcal/config/parameters.hpp"

namespace rigcal::config {

struct VehicleFootprint {
  double length = 4.5;         // bumper to bumper, m
  double width = 2.0;          // side to side (mirrors included), m
  double rear_overhang = 1.0;  // from base_link's origin back to the rear bumper, m (Autoware's name)
};

/// What the footprint box adds around the outline: the crop is made under the *initial* extrinsic,
/// which may be ~0.3 m off, and the points under the bumpers still belong to the wheels' ground.
inline constexpr double kFootprintMargin = 0.5;
/// The box's height range in base_link: the ground (z = 0) with room for a wrong initial z or tilt.
inline constexpr double kFootprintMinZ = -1.0;
inline constexpr double kFootprintMaxZ = 0.5;

/// The base_lidar_crop_box_* values the footprint implies (all six), written into `params`.
void setCropBoxFromFootprint(const VehicleFootprint& footprint, Parameters& params);

}  // namespace rigcal::config
