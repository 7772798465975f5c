#include "rigcal/bag/tf_message_encoder.hpp"

#include "rigcal/bag/cdr_writer.hpp"

namespace rigcal::bag {

std::vector<std::uint8_t> encodeTfMessage(std::span<const StampedTransform> transforms) {
  CdrWriter cdr;
  cdr.put(std::uint32_t(transforms.size()));
  for (const auto& t : transforms) {
    cdr.putHeader(t.stamp_ns, t.parent_frame);
    cdr.putString(t.child_frame);
    const Eigen::Vector3d translation = t.T_parent_child.translation();
    for (int i = 0; i < 3; ++i) cdr.put(translation[i]);
    const Eigen::Quaterniond q(t.T_parent_child.linear());
    for (double v : {q.x(), q.y(), q.z(), q.w()}) cdr.put(v);
  }
  return cdr.take();
}

}  // namespace rigcal::bag
