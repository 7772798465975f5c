#include "bag_extrinsics.hpp"

#include <iostream>
#include <sstream>

#include "commands.hpp"
#include "exit_codes.hpp"
#include "rigcal/bag/bag_error.hpp"
#include "rigcal/bag/lidar_topic.hpp"
#include "rigcal/bag/tf_tree.hpp"

namespace rigcal::app {

void applyExtrinsicsFromBag(config::RigConfig& rig, const pipeline::PipelineOptions& options) {
  if (rig.extrinsics_from_bag.empty()) return;
  if (options.input != pipeline::InputKind::kBag)
    throw CommandFailed(kExitUsage, rig.file.string() + ": initial_extrinsics from_bag needs --bag");
  try {
    const bag::TfTree tree = bag::TfTree::fromBag(options.bag);
    std::string log;  // printed once every sensor's frame is found: an error stays one line
    for (const auto& name : rig.extrinsics_from_bag) {
      const config::SensorConfig& sensor = rig.sensor(name);
      std::string frame = sensor.source.frame.value_or("");
      if (frame.empty()) {
        std::string topic = sensor.source.topic.value_or("");
        if (const auto t = options.bag_topics.find(name); t != options.bag_topics.end()) topic = t->second;
        else if (const auto any = options.bag_topics.find(""); any != options.bag_topics.end()) topic = any->second;
        bag::Bag b(options.bag);
        frame = bag::firstFrameId(b, bag::chooseLidarTopic(b, topic));
        if (frame.empty())
          throw bag::BagError(options.bag.string() + ": sensor '" + name +
                              "': its topic gives no frame_id; name it in the rig (source: {frame: ...})");
      }
      std::vector<std::string> path;
      try {
        rig.initial_T_base_sensor[name] = tree.lookup(rig.roles.base_frame, frame, &path);
      } catch (const bag::BagError& e) {
        throw bag::BagError(options.bag.string() + ": initial extrinsic of '" + name + "' from_bag: " + e.what());
      }
      std::string chain;
      for (const auto& f : path) chain += (chain.empty() ? "" : " -> ") + f;
      const XyzRpy v = toXyzRpy(rig.initial_T_base_sensor[name]);
      std::ostringstream line;
      line << "initial extrinsic of '" << name << "' from the bag's tf: " << chain << " (x " << v.x << " y "
                << v.y << " z " << v.z << " m, roll " << v.roll << " pitch " << v.pitch << " yaw " << v.yaw
                << " rad)\n";
      log += line.str();
    }
    std::cerr << log;
  } catch (const bag::BagError& e) {
    throw CommandFailed(kExitInput, e.what());
  }
}

}  // namespace rigcal::app
