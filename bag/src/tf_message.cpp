#include "rigcal/bag/tf_message.hpp"

#include "rigcal/bag/cdr_reader.hpp"

namespace rigcal::bag {

std::vector<StampedTransform> decodeTfMessage(std::span<const std::uint8_t> message, const std::string& what) {
  CdrReader cdr(message, what);
  // Smallest TransformStamped: stamp 8, two empty strings 8, seven doubles 56.
  const auto n = cdr.readCount("transforms", 8 + 8 + 56);
  std::vector<StampedTransform> out(n);
  for (auto& t : out) {
    const RosHeader header = cdr.readHeader();
    t.stamp_ns = header.stamp_ns;
    t.parent_frame = header.frame_id;
    t.child_frame = cdr.readString("transforms[].child_frame_id");
    Eigen::Vector3d translation;
    for (int i = 0; i < 3; ++i) translation[i] = cdr.read<double>("transforms[].transform.translation");
    double q[4];
    for (double& v : q) v = cdr.read<double>("transforms[].transform.rotation");
    Eigen::Quaterniond rotation(q[3], q[0], q[1], q[2]);
    if (!(rotation.norm() > 1e-9))
      throw BagError(what + ": transform " + t.parent_frame + " -> " + t.child_frame + " has a zero quaternion");
    t.T_parent_child = Pose::Identity();
    t.T_parent_child.linear() = rotation.normalized().toRotationMatrix();
    t.T_parent_child.translation() = translation;
  }
  return out;
}

}  // namespace rigcal::bag
