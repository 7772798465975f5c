#pragma once
// nav_msgs/Odometry serialised as CDR: Header header (frame_id: the world/odom frame), string
// child_frame_id, PoseWithCovariance{Pose{Point position (3 f64), Quaternion orientation (x y z w f64)},
// f64[36] covariance}, TwistWithCovariance{Twist{Vector3 linear, Vector3 angular}, f64[36] covariance}.
// What `rigcal sim` writes on /odom as the vehicle's true trajectory.
#include <array>
#include <cstdint>
#include <string_view>
#include <vector>

#include "rigcal/core/pose.hpp"

namespace rigcal::bag {

inline constexpr const char* kOdometryType = "nav_msgs/msg/Odometry";

struct OdometrySample {
  TimeNs stamp_ns = 0;
  Pose T_world_body = Pose::Identity();  // the child (body) frame's pose in the header's frame
  Eigen::Vector3d linear_velocity = Eigen::Vector3d::Zero();   // in the child frame
  Eigen::Vector3d angular_velocity = Eigen::Vector3d::Zero();  // in the child frame
  std::array<double, 36> pose_covariance{}, twist_covariance{};
};

std::vector<std::uint8_t> encodeOdometry(const OdometrySample& sample, std::string_view frame_id,
                                         std::string_view child_frame_id);

}  // namespace rigcal::bag
