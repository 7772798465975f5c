// `rigcal rig-from-bag BAG [--out rig.yaml]`: prints what `rigcal inspect` prints, then a starter rig file
// for the bag's lidar topics (packet scans and PointCloud2), for a user to check rather than write:
// one sensor per lidar topic named after its frame id (source: {topic: ...}), the model guessed from the
// packets (factory byte, layout, size) or the cloud's ring count, the lidar with the most data per
// second as mapping lidar, and initial extrinsics composed along /tf_static (or /tf) to base_link.
// Every guess carries a "# check" comment saying what it rests on.
#include <cctype>
#include <iomanip>
#include <iostream>
#include <set>
#include <sstream>

#include "../bag_summary.hpp"
#include "../commands.hpp"
#include "../exit_codes.hpp"
#include "rigcal/bag/bag_error.hpp"
#include "rigcal/bag/tf_tree.hpp"
#include "rigcal/core/atomic_file.hpp"

namespace rigcal::app {

namespace {

constexpr const char* kBaseFrame = "base_link";

std::string sanitize(const std::string& name) {
  std::string out;
  for (const char c : name) out += std::isalnum(static_cast<unsigned char>(c)) || c == '-' || c == '_' ? c : '_';
  while (!out.empty() && out.front() == '_') out.erase(0, 1);
  return out.empty() ? "lidar" : out;
}

std::string number(double v) {
  std::ostringstream s;
  s << std::fixed << std::setprecision(6) << (std::abs(v) < 5e-7 ? 0.0 : v);
  return s.str();
}

// A sensor name from a topic without a frame id: its last component that is not a generic word
// ("/sensing/lidar/front/packets" -> "front").
std::string nameFromTopic(const std::string& topic) {
  static const std::set<std::string> kGeneric = {"packets", "points", "pointcloud", "pointcloud_raw",
                                                 "pointcloud_raw_ex", "velodyne_packets", "pandar_packets",
                                                 "robosense_packets", "lidar_packets", "sensing", "lidar"};
  std::vector<std::string> parts;
  std::istringstream in(topic);
  for (std::string part; std::getline(in, part, '/');)
    if (!part.empty() && !kGeneric.count(part)) parts.push_back(part);
  return sanitize(parts.empty() ? topic : parts.back());
}

// The summary's tf edges as a tree: /tf_static first, so it wins over /tf for the same child (as
// `initial_extrinsics: from_bag` reads the bag).
bag::TfTree tfTree(const BagSummary& summary) {
  bag::TfTree tree;
  for (const bool statics : {true, false})
    for (const auto& [edge, t] : summary.tf)
      if ((t.second == "/tf_static") == statics) tree.add(t.first);
  return tree;
}

// T_base_frame composed along the tree, nullopt when `frame` is not connected to base_link; `path` names
// the frames walked ("base_link -> sensor_kit -> top").
std::optional<Pose> toBase(const bag::TfTree& tree, const std::string& frame, std::string& path) {
  std::vector<std::string> frames;
  try {
    const Pose T = tree.lookup(kBaseFrame, frame, &frames);
    path.clear();
    for (const auto& f : frames) path += (path.empty() ? "" : " -> ") + f;
    return T;
  } catch (const bag::BagError&) {
    return std::nullopt;
  }
}

struct Lidar {
  const BagTopicSummary* topic;
  std::string name, frame;
  double bytes_per_s;
};

std::string starterRig(const BagSummary& summary) {
  std::vector<Lidar> lidars;
  std::set<std::string> names;
  for (const auto& t : summary.topics) {
    if (!t.lidar || t.count == 0) continue;
    std::string name = !t.frame_id.empty() ? sanitize(t.frame_id) : nameFromTopic(t.info.name);
    while (!names.insert(name).second) name += "_2";
    const double seconds = std::max(toSeconds(t.last - t.first), 1e-3);
    lidars.push_back({&t, name, t.frame_id.empty() ? name : t.frame_id, double(t.bytes) / seconds});
  }
  if (lidars.empty()) return {};
  const auto mapping = std::max_element(lidars.begin(), lidars.end(), [](const Lidar& a, const Lidar& b) {
    return a.bytes_per_s < b.bytes_per_s;
  });
  std::ostringstream y;
  y << "# Starter rig written by `rigcal rig-from-bag " << summary.path << "`: check every line marked 'check'.\n";
  y << "rig: " << sanitize(std::filesystem::path(summary.path).filename().string()) << "\n";
  y << "sensors:\n";
  for (const auto& l : lidars) {
    y << "  - name: " << l.name << "\n";
    if (l.topic->info.type == "sensor_msgs/msg/PointCloud2") {
      // Clouds are read as they are (no decoder, calibration or metadata): the rig runs without edits.
      y << "    model: PointCloud2  # the clouds as recorded; the sensor: "
        << (l.topic->model.model.empty() ? "unknown" : l.topic->model.model) << " ("
        << (l.topic->model.note.empty() ? "no guess" : l.topic->model.note) << ")\n";
    } else {
      y << "    model: " << (l.topic->model.model.empty() ? "UNKNOWN" : l.topic->model.model) << "  # check: "
        << (l.topic->model.note.empty() ? "no guess" : l.topic->model.note) << "\n";
    }
    y << "    source: {topic: " << l.topic->info.name << "}  # " << l.topic->info.type << ", " << l.topic->count
      << " messages";
    if (l.topic->cloud_points) y << ", " << l.topic->cloud_points << " points in the first";
    y << "\n";
  }
  y << "roles:\n";
  y << "  mapping_lidar: " << mapping->name << "  # check: the lidar with the most data per second\n";
  y << "  calibration_lidars: [";
  bool first = true;
  for (const auto& l : lidars)
    if (&l != &*mapping) {
      y << (first ? "" : ", ") << l.name;
      first = false;
    }
  y << "]\n";
  y << "  base_frame: " << kBaseFrame << "\n";
  y << "initial_extrinsics:\n";
  const bag::TfTree tree = tfTree(summary);
  for (const auto& l : lidars) {
    std::string path;
    const auto T = toBase(tree, l.frame, path);
    const XyzRpy v = toXyzRpy(T.value_or(Pose::Identity()));
    y << "  " << l.name << ": {x: " << number(v.x) << ", y: " << number(v.y) << ", z: " << number(v.z)
      << ", roll: " << number(v.roll) << ", pitch: " << number(v.pitch) << ", yaw: " << number(v.yaw) << "}";
    if (T)
      y << "  # from tf " << path << "\n";
    else
      y << "  # check: no tf from " << kBaseFrame << " to " << l.frame << " in the bag: measure it\n";
  }
  return y.str();
}

struct RigFromBagArgs {
  std::string bag, out;
};

void run(const RigFromBagArgs& a) {
  BagSummary summary;
  try {
    summary = summarizeBag(a.bag);
  } catch (const bag::BagError& e) {
    throw CommandFailed(kExitInput, e.what());
  }
  printBagSummary(summary);
  if (summary.total == 0) throw CommandFailed(kExitNotEnoughData, a.bag + ": the bag holds no messages");
  const std::string rig = starterRig(summary);
  if (rig.empty())
    throw CommandFailed(kExitNotEnoughData, a.bag + ": no lidar topic (packet scans or sensor_msgs/msg/PointCloud2) with messages");
  if (a.out.empty()) {
    std::cout << "\n" << rig;
    return;
  }
  writeFileAtomically(a.out, [&](std::ostream& o) { o << rig; });
  std::cout << "wrote " << a.out << ": a starter rig; check the lines marked 'check'\n";
}

}  // namespace

void addRigFromBagCommand(CLI::App& app) {
  auto a = std::make_shared<RigFromBagArgs>();
  auto* cmd = app.add_subcommand("rig-from-bag", "List a ROS 2 bag (as inspect) and write a starter rig file for its lidar topics");
  cmd->add_option("bag", a->bag, "rosbag2 folder, .mcap or .db3")->required();
  cmd->add_option("--out", a->out, "Where to write the rig (default: print it)");
  cmd->footer(kExitCodesHelp);
  cmd->callback([a] { run(*a); });
}

}  // namespace rigcal::app
