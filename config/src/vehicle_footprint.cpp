#include "rigcal/config/vehicle_footprint.hpp"

namespace rigcal::config {

void setCropBoxFromFootprint(const VehicleFootprint& f, Parameters& p) {
  p.base_lidar_crop_box_min_x = -f.rear_overhang - kFootprintMargin;
  p.base_lidar_crop_box_max_x = f.length - f.rear_overhang + kFootprintMargin;
  p.base_lidar_crop_box_min_y = -0.5 * f.width - kFootprintMargin;
  p.base_lidar_crop_box_max_y = 0.5 * f.width + kFootprintMargin;
  p.base_lidar_crop_box_min_z = kFootprintMinZ;
  p.base_lidar_crop_box_max_z = kFootprintMaxZ;
}

}  // namespace rigcal::config
