#include "rigcal/calib/lidar_lidar/mapping_cloud_release.hpp"

#include <vector>

namespace rigcal::calib {

std::size_t dropMappingCloudsDoneWith(pipeline::CalibrationDataset& dataset, std::size_t first_pending) {
  std::vector<bool> needed(dataset.mapping_clouds.size(), false);
  for (std::size_t f = first_pending; f < dataset.frames.size(); ++f) {
    const auto& window = dataset.frames[f].window;
    if (window.empty()) return 0;
    for (const std::size_t c : window)
      if (c < needed.size()) needed[c] = true;
  }
  std::size_t dropped = 0;
  for (std::size_t c = 0; c < needed.size(); ++c) {
    auto& cloud = dataset.mapping_clouds[c].cloud;
    if (needed[c] || cloud == nullptr) continue;
    cloud.reset();
    ++dropped;
  }
  return dropped;
}

}  // namespace rigcal::calib
