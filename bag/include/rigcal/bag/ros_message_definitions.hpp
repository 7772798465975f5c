#pragma once
// The ROS 2 message definitions (.msg text with its dependencies, the "ros2msg" schema encoding rosbag2
// writes into MCAP) of the types rigcal writes, so that other tools (Foxglove, ros2 bag) can decode our
// bags without the packages installed.
#include <string>
#include <string_view>

namespace rigcal::bag {

/// The schema text of `type` ("sensor_msgs/msg/PointCloud2", ...); throws std::invalid_argument for a
/// type rigcal does not write.
std::string rosMessageDefinition(std::string_view type);

}  // namespace rigcal::bag
