#pragma once
// Stamped poses recorded as ROS messages, decoded from CDR without ROS. Layouts from the definitions:
//   geometry_msgs/PoseStamped      = Header, Pose{Point position (3 f64), Quaternion orientation (x y z w f64)}
//   nav_msgs/Odometry              = Header, string child_frame_id, PoseWithCovariance{Pose, f64[36]}, Twist...
//   geometry_msgs/TransformStamped = Header, string child_frame_id, Transform{Vector3, Quaternion}
//   tf2_msgs/TFMessage             = TransformStamped[] (one named parent -> child pair is taken)
// The pose maps the child (body) frame into the header's frame: T_world_body.
#include <filesystem>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "rigcal/core/pose.hpp"

namespace rigcal::bag {

enum class PoseMessageType { kPoseStamped, kOdometry, kTransformStamped, kTfMessage };

/// The pose family of a ROS type name, nullopt when not a pose type.
std::optional<PoseMessageType> poseMessageType(std::string_view ros_type);
/// Every ROS type name poseMessageType accepts (for error messages).
std::string poseMessageTypeList();

struct StampedPose {
  TimeNs stamp_ns = 0;  // the header stamp
  Pose T_world_body = Pose::Identity();
};

/// One pose message (not kTfMessage). Throws BagError naming `what` and the field when the message is
/// shorter than its layout or its quaternion is zero.
StampedPose decodePoseMessage(PoseMessageType type, std::span<const std::uint8_t> message, const std::string& what);

/// Every pose of a bag, in log-time order: from `topic` (any pose type), or, when `tf_frames` is given as
/// {parent, child}, from the transforms between those two frames on /tf (then /tf_static). Throws BagError
/// "<bag>: ..." when the topic is missing (listing the bag's topics), of another type (listing the pose
/// types), or no transform joins the frames (listing the frames seen). Malformed messages are counted in
/// `malformed` and skipped.
std::vector<StampedPose> readBagPoses(const std::filesystem::path& bag, const std::string& topic,
                                      const std::optional<std::pair<std::string, std::string>>& tf_frames,
                                      std::size_t* malformed = nullptr);

}  // namespace rigcal::bag
