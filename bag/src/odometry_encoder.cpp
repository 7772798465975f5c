#include "rigcal/bag/odometry_encoder.hpp"

#include "rigcal/bag/cdr_writer.hpp"

namespace rigcal::bag {

std::vector<std::uint8_t> encodeOdometry(const OdometrySample& sample, std::string_view frame_id,
                                         std::string_view child_frame_id) {
  CdrWriter cdr;
  cdr.putHeader(sample.stamp_ns, frame_id);
  cdr.putString(child_frame_id);
  const Eigen::Vector3d p = sample.T_world_body.translation();
  for (int i = 0; i < 3; ++i) cdr.put(p[i]);
  const Eigen::Quaterniond q(sample.T_world_body.linear());
  for (double v : {q.x(), q.y(), q.z(), q.w()}) cdr.put(v);
  for (double v : sample.pose_covariance) cdr.put(v);
  for (int i = 0; i < 3; ++i) cdr.put(sample.linear_velocity[i]);
  for (int i = 0; i < 3; ++i) cdr.put(sample.angular_velocity[i]);
  for (double v : sample.twist_covariance) cdr.put(v);
  return cdr.take();
}

}  // namespace rigcal::bag
