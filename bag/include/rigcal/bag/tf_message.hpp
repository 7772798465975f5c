#pragma once
// tf2_msgs/TFMessage decoded from CDR: geometry_msgs/TransformStamped[]{Header header (frame_id = parent),
// string child_frame_id, Transform{Vector3 translation (3 f64), Quaternion rotation (x y z w f64)}}.
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "rigcal/core/pose.hpp"

namespace rigcal::bag {

inline constexpr const char* kTfMessageType = "tf2_msgs/msg/TFMessage";

struct StampedTransform {
  TimeNs stamp_ns = 0;
  std::string parent_frame, child_frame;
  Pose T_parent_child = Pose::Identity();  // maps points in the child frame into the parent frame
};

/// Throws BagError naming `what` and the field when the message is shorter than its layout.
std::vector<StampedTransform> decodeTfMessage(std::span<const std::uint8_t> message, const std::string& what);

}  // namespace rigcal::bag
