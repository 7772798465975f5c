#include "rigcal/bag/pose_message.hpp"

#include <set>

#include "rigcal/bag/bag.hpp"
#include "rigcal/bag/cdr_reader.hpp"
#include "rigcal/bag/tf_message.hpp"

namespace rigcal::bag {

namespace {

struct TypeName {
  const char* name;
  PoseMessageType type;
};
constexpr TypeName kTypes[] = {{"geometry_msgs/msg/PoseStamped", PoseMessageType::kPoseStamped},
                               {"nav_msgs/msg/Odometry", PoseMessageType::kOdometry},
                               {"geometry_msgs/msg/TransformStamped", PoseMessageType::kTransformStamped},
                               {"tf2_msgs/msg/TFMessage", PoseMessageType::kTfMessage}};

/// Point/Vector3 then Quaternion (x y z w), all f64.
Pose readPose(CdrReader& cdr, const char* field) {
  Eigen::Vector3d t;
  for (int i = 0; i < 3; ++i) t[i] = cdr.read<double>(field);
  double q[4];
  for (double& v : q) v = cdr.read<double>(field);
  const Eigen::Quaterniond rotation(q[3], q[0], q[1], q[2]);
  if (!(rotation.norm() > 1e-9)) throw BagError(cdr.what() + ": " + field + " has a zero quaternion");
  Pose p = Pose::Identity();
  p.linear() = rotation.normalized().toRotationMatrix();
  p.translation() = t;
  return p;
}

}  // namespace

std::optional<PoseMessageType> poseMessageType(std::string_view ros_type) {
  for (const auto& t : kTypes)
    if (ros_type == t.name) return t.type;
  return std::nullopt;
}

std::string poseMessageTypeList() {
  std::string out;
  for (const auto& t : kTypes) out += (out.empty() ? "" : ", ") + std::string(t.name);
  return out;
}

StampedPose decodePoseMessage(PoseMessageType type, std::span<const std::uint8_t> message, const std::string& what) {
  CdrReader cdr(message, what);
  StampedPose out;
  out.stamp_ns = cdr.readHeader().stamp_ns;
  switch (type) {
    case PoseMessageType::kPoseStamped:
      out.T_world_body = readPose(cdr, "pose");
      break;
    case PoseMessageType::kOdometry:
      (void)cdr.readString("child_frame_id");
      out.T_world_body = readPose(cdr, "pose.pose");
      break;
    case PoseMessageType::kTransformStamped:
      (void)cdr.readString("child_frame_id");
      out.T_world_body = readPose(cdr, "transform");
      break;
    case PoseMessageType::kTfMessage:
      throw BagError(what + ": a TFMessage holds several transforms; read it with tf frames");
  }
  return out;
}

std::vector<StampedPose> readBagPoses(const std::filesystem::path& path, const std::string& topic,
                                      const std::optional<std::pair<std::string, std::string>>& tf_frames,
                                      std::size_t* malformed) {
  Bag bag(path);
  const std::string where = path.string() + ": ";
  if (bag.topics().empty()) throw BagError(where + "empty bag (no topics)");
  std::set<std::size_t> wanted;
  PoseMessageType type = PoseMessageType::kTfMessage;
  if (tf_frames) {
    for (const char* name : {"/tf", "/tf_static"})
      if (const auto t = bag.findTopic(name)) wanted.insert(*t);
    if (wanted.empty()) throw BagError(where + "no /tf or /tf_static topic; it has " + bag.topicList());
  } else {
    const auto t = bag.findTopic(topic);
    if (!t) throw BagError(where + "topic " + topic + " not in the bag; it has " + bag.topicList());
    const auto pose_type = poseMessageType(bag.topics()[*t].type);
    if (!pose_type || *pose_type == PoseMessageType::kTfMessage)
      throw BagError(where + "topic " + topic + " has type " + bag.topics()[*t].type + ", not a pose type (" +
                     poseMessageTypeList() + "; for /tf name the two frames)");
    type = *pose_type;
    wanted.insert(*t);
  }
  std::vector<StampedPose> out;
  std::set<std::string> frames;
  std::size_t bad = 0;
  while (const auto m = bag.next()) {
    if (!wanted.count(m->topic)) continue;
    const std::string what = where + bag.topics()[m->topic].name + " message at log time " + std::to_string(m->log_time_ns);
    try {
      if (!tf_frames) {
        out.push_back(decodePoseMessage(type, m->data, what));
        continue;
      }
      for (const auto& t : decodeTfMessage(m->data, what)) {
        frames.insert(t.parent_frame);
        frames.insert(t.child_frame);
        if (t.parent_frame == tf_frames->first && t.child_frame == tf_frames->second)
          out.push_back({t.stamp_ns, t.T_parent_child});
        else if (t.parent_frame == tf_frames->second && t.child_frame == tf_frames->first)
          out.push_back({t.stamp_ns, t.T_parent_child.inverse()});
      }
    } catch (const BagError&) {
      ++bad;
    }
  }
  if (malformed) *malformed = bad;
  if (tf_frames && out.empty()) {
    std::string list;
    for (const auto& f : frames) list += (list.empty() ? "" : ", ") + f;
    throw BagError(where + "no transform between " + tf_frames->first + " and " + tf_frames->second +
                   " on /tf; its frames are " + (list.empty() ? "(none)" : list));
  }
  return out;
}

}  // namespace rigcal::bag
