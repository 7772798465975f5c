// `rigcal map --bag` on the parking-lot recording's sqlite3 bags: the packet bag maps as the pcap, row for
// row; the PointCloud2 bag follows the same path; `initial_extrinsics: from_bag` composes the bag's
// /tf_static to base_link and names the frames it used.
#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <regex>
#include <sstream>

#include "bag_pipeline_support.hpp"
#include "rigcal/bag/tf_tree.hpp"
#include "run_command.hpp"
#include "sanitizers.hpp"

namespace rigcal::test {
namespace {

namespace fs = std::filesystem;
using bag::test::SqliteBagWriter;

TEST_F(BagPipeline, MapFromPacketBagEqualsMapFromPcapAndPointCloud2BagFollowsTheSamePath) {
  TempDir out;
  const auto from_pcap = runRigcal({"map", "--config", (g->dir / "rig.yaml").string(), "--pcap", g->pcap.string(),
                                    "--out", (out / "pcap").string()});
  ASSERT_EQ(from_pcap.exit_code, 0) << from_pcap.err;
  std::vector<std::string> args{"map", "--config", (g->dir / "rig.yaml").string(), "--bag", g->packets_bag.string(),
                                "--out", (out / "packets").string()};
  const auto topics = topicArgs("packets");
  args.insert(args.end(), topics.begin(), topics.end());
  const auto from_packets = runRigcal(args);
  ASSERT_EQ(from_packets.exit_code, 0) << from_packets.err;
  const auto pcap_rows = trajectoryRows(out / "pcap");
  ASSERT_GT(pcap_rows.size(), kSanitized ? 3u : 25u);
  // The same payloads and stamps: the same frames, bit for bit. The pipeline's last frames depend on how
  // the driver threads reach the end of input (two runs of the same pcap differ there too, by 1-2 frames
  // of 70 measured), so the common run is compared, and it must be nearly all of it.
  const auto packet_rows = trajectoryRows(out / "packets");
  const std::size_t common = std::min(packet_rows.size(), pcap_rows.size());
  EXPECT_GE(common + kEndFrames, std::max(packet_rows.size(), pcap_rows.size()));
  for (std::size_t i = 0; i + kEndFrames < common; ++i) EXPECT_EQ(packet_rows[i], pcap_rows[i]) << "row " << i;

  // PointCloud2: the rig names each sensor's topic (source: {topic: ...}); the clouds are the pcap's
  // sweeps, so the mapper sees the same points at the same times.
  std::ofstream(g->dir / "rig_clouds.yaml") << rigWithTopics(fileContents(g->dir / "rig.yaml"), "points");
  const auto from_clouds = runRigcal({"map", "--config", (g->dir / "rig_clouds.yaml").string(), "--bag",
                                      g->clouds_bag.string(), "--out", (out / "clouds").string()});
  ASSERT_EQ(from_clouds.exit_code, 0) << from_clouds.err;
  const auto cloud_rows = trajectoryRows(out / "clouds");
  const std::size_t cloud_common = std::min(cloud_rows.size(), pcap_rows.size());
  EXPECT_GE(cloud_common + kEndFrames, std::max(cloud_rows.size(), pcap_rows.size()));
  for (std::size_t i = 0; i + kEndFrames < cloud_common; ++i) {
    // sequence,stamp_ns,kind,lost,path_length_m,x,y,z,...
    std::vector<std::string> a, b;
    std::istringstream sa(pcap_rows[i]), sb(cloud_rows[i]);
    for (std::string f; std::getline(sa, f, ',');) a.push_back(f);
    for (std::string f; std::getline(sb, f, ',');) b.push_back(f);
    ASSERT_GE(a.size(), 8u);
    EXPECT_EQ(a[1], b[1]) << "row " << i << ": the same scan stamps";
    for (std::size_t k = 5; k < 8; ++k) EXPECT_NEAR(std::stod(a[k]), std::stod(b[k]), 1e-3) << "row " << i;
  }
}

TEST_F(BagPipeline, InitialExtrinsicsFromTheBagsTfStaticAreComposedToBaseLink) {
  const bag::TfTree tree = bag::TfTree::fromBag(g->clouds_bag);
  std::vector<std::string> path;
  const Pose T = tree.lookup("base_link", "front_left", &path);
  EXPECT_EQ(path, (std::vector<std::string>{"base_link", "sensor_kit_base_link", "front_left"}));
  const Pose expected = fromXyzRpy({0.5, 0, 1.5, 0, 0, 0.1}) * fromXyzRpy({0.2, -0.2, 0.3, 0.01, -0.02, 0.6});
  EXPECT_LT((T.matrix() - expected.matrix()).cwiseAbs().maxCoeff(), 1e-12);
  // The inverse direction walks the same tree.
  EXPECT_LT((tree.lookup("front_left", "base_link").matrix() - expected.inverse().matrix()).cwiseAbs().maxCoeff(), 1e-12);

  // Through the binary: the frames used are named, a missing frame lists the tree's frames. The frame
  // comes from each topic's first cloud; a small bag (the same /tf_static, two tiny clouds per sensor) is
  // enough: the extrinsics are resolved before any scan is mapped.
  TempDir out;
  const fs::path small = out / "small.db3";
  {
    SqliteBagWriter bag(small);
    std::vector<bag::test::TfEdge> edges;
    for (const auto& name : {"sensor_kit_base_link", "top", "front_left", "front_right"}) {
      std::vector<std::string> chain;
      const Pose T_parent_child = tree.lookup(name == std::string("sensor_kit_base_link") ? "base_link"
                                                                                           : "sensor_kit_base_link",
                                              name, &chain);
      edges.push_back({chain.front(), name, T_parent_child});
    }
    bag::test::writeTfStatic(bag, 1, edges);
    for (const auto& s : g->rig.sensors) {
      const int id = bag.topic(topicOf(s.name, "points"), "sensor_msgs/msg/PointCloud2");
      for (int k = 0; k < 2; ++k) {
        Scan scan;
        scan.stamp_ns = 1'700'000'000'000'000'000 + k * 100'000'000;
        for (int i = 0; i < 10; ++i) scan.push_back({float(i), 1.0f, 0.5f, 1.0f, std::uint16_t(i), scan.stamp_ns, 0});
        bag.write(id, scan.stamp_ns, bag::test::pointCloud2(scan, s.name));
      }
    }
  }
  // Decoded clouds need no packet model: `model: PointCloud2` (no calibration or metadata file).
  std::ofstream(g->dir / "rig_from_bag.yaml") << std::regex_replace(
      rigWithTopics(fileContents(g->dir / "rig.yaml"), "points", "initial_extrinsics: from_bag\n"),
      std::regex("model: \\S+"), "model: PointCloud2");
  const auto checked = runRigcal({"check-config", (g->dir / "rig_from_bag.yaml").string()});
  EXPECT_EQ(checked.exit_code, 0) << checked.err;
  EXPECT_NE(checked.out.find("topic /sensing/lidar/top/points  (initial extrinsic from_bag)"), std::string::npos)
      << checked.out;
  const auto pcap_for_clouds = runRigcal({"map", "--config", (g->dir / "rig_from_bag.yaml").string(), "--pcap",
                                          g->pcap.string(), "--out", out.path().string()});
  EXPECT_EQ(pcap_for_clouds.exit_code, 2) << pcap_for_clouds.err;
  EXPECT_NE(pcap_for_clouds.err.find("initial_extrinsics from_bag needs --bag"), std::string::npos) << pcap_for_clouds.err;
  const auto ok = runRigcal({"map", "--config", (g->dir / "rig_from_bag.yaml").string(), "--bag", small.string(),
                             "--out", out.path().string()});
  EXPECT_NE(ok.err.find("initial extrinsic of 'front_left' from the bag's tf: base_link -> sensor_kit_base_link -> "
                        "front_left"),
            std::string::npos)
      << ok.err;
  std::string rig = fileContents(g->dir / "rig_from_bag.yaml");
  rig = std::regex_replace(rig, std::regex("topic: /sensing/lidar/front_right/points\\}"),
                           "topic: /sensing/lidar/front_right/points, frame: front_right_optical}");
  std::ofstream(g->dir / "rig_bad_frame.yaml") << rig;
  const auto bad = runRigcal({"map", "--config", (g->dir / "rig_bad_frame.yaml").string(), "--bag", small.string(),
                              "--out", out.path().string()});
  EXPECT_EQ(bad.exit_code, 4) << bad.err;
  EXPECT_NE(bad.err.find("initial extrinsic of 'front_right' from_bag: frame front_right_optical is not in the tf "
                         "tree; its frames: base_link, front_left, front_right, sensor_kit_base_link, top"),
            std::string::npos)
      << bad.err;
  EXPECT_EQ(std::count(bad.err.begin(), bad.err.end(), '\n'), 1) << bad.err;
}

}  // namespace
}  // namespace rigcal::test
