#include "bag_pipeline_support.hpp"

#include <regex>
#include <sstream>

#include "run_command.hpp"
#include "sanitizers.hpp"

namespace rigcal::test {

namespace fs = std::filesystem;
using bag::test::SqliteBagWriter;

std::string topicOf(const std::string& sensor, const char* form) { return "/sensing/lidar/" + sensor + "/" + form; }

std::string rigWithTopics(const std::string& rig, const char* form, const std::string& extrinsics) {
  std::istringstream in(rig);
  std::ostringstream out;
  std::string line, sensor;
  bool skipping = false;
  const std::regex name(R"(^\s*- name: (\S+))");
  while (std::getline(in, line)) {
    std::smatch m;
    if (std::regex_search(line, m, name)) sensor = m[1];
    if (!extrinsics.empty() && line.rfind("initial_extrinsics:", 0) == 0) {
      out << extrinsics;
      skipping = true;
      continue;
    }
    if (skipping && line.rfind("  ", 0) == 0) continue;
    skipping = false;
    if (line.find("source: {") != std::string::npos) {
      out << line.substr(0, line.find("source:")) << "source: {topic: " << topicOf(sensor, form) << "}\n";
      continue;
    }
    out << line << '\n';
  }
  return out.str();
}

std::vector<std::string> simTopics(const config::RigConfig& rig, const char* form) {
  std::vector<std::string> args;
  for (const auto& s : rig.sensors) args.insert(args.end(), {"--topic", s.name + "=/" + s.name + "/" + form});
  return args;
}

std::vector<std::string> trajectoryRows(const fs::path& out) {
  std::istringstream in(fileContents(out / "trajectory.csv"));
  std::vector<std::string> rows;
  for (std::string line; std::getline(in, line);)
    if (!line.empty() && line[0] != '#') rows.push_back(line);
  return rows;
}

Recording* BagPipeline::g = nullptr;

void BagPipeline::SetUpTestSuite() {
  g = new Recording;
  const auto sim = runRigcal({"sim", "--scenario", "parking-lot", "--duration", kSanitized ? "1.5" : "4", "--out",
                              g->dir.path().string()});
  if (sim.exit_code != 0) {
    g->error = sim.err;
    return;
  }
  g->rig = config::loadRigConfig(g->dir / "rig.yaml");
  g->pcap = g->dir / "recording.pcap";
  g->packets_bag = g->dir / "packets.db3";
  g->clouds_bag = g->dir / "clouds.db3";
  {
    SqliteBagWriter packets(g->packets_bag);
    for (const auto& s : g->rig.sensors) bag::test::writePacketTopic(packets, topicOf(s.name, "packets"), s, g->pcap);
  }
  SqliteBagWriter clouds(g->clouds_bag);
  // /tf_static as Autoware publishes it: base_link -> sensor_kit_base_link -> each lidar (the truth
  // would do; any chain does: the test checks the composition).
  std::vector<bag::test::TfEdge> edges{{"base_link", "sensor_kit_base_link", fromXyzRpy({0.5, 0, 1.5, 0, 0, 0.1})}};
  for (const auto& s : g->rig.sensors)
    edges.push_back({"sensor_kit_base_link", s.name,
                     fromXyzRpy({0.1 * double(edges.size()), -0.2, 0.3, 0.01, -0.02, 0.3 * double(edges.size())})});
  bag::test::writeTfStatic(clouds, 1, edges);
  for (const auto& s : g->rig.sensors)
    g->clouds[s.name] = bag::test::writeCloudTopic(clouds, topicOf(s.name, "points"), s, g->pcap);
}

void BagPipeline::TearDownTestSuite() {
  delete g;
  g = nullptr;
}

std::vector<std::string> BagPipeline::topicArgs(const char* form) {
  std::vector<std::string> args;
  for (const auto& s : g->rig.sensors) args.insert(args.end(), {"--topic", s.name + "=" + topicOf(s.name, form)});
  return args;
}

}  // namespace rigcal::test
