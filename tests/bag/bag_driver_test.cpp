// `rigcal driver --bag`: one sensor's packets or clouds from the bag into its ring, as from the pcap.
#include <gtest/gtest.h>
#include <unistd.h>

#include <string>

#include "bag_pipeline_support.hpp"
#include "run_command.hpp"
#include "sanitizers.hpp"

namespace rigcal::test {
namespace {

TEST_F(BagPipeline, DriverPublishesTheBagsScansAsThePcaps) {
  const std::string rig = (g->dir / "rig.yaml").string();
  const std::string prefix = "rigcal.bagtest" + std::to_string(::getpid()) + ".";
  const auto published = [](const CommandResult& r) {
    const auto at = r.out.find(" scans published");
    const auto from = r.out.rfind(' ', at - 1);
    return at == std::string::npos ? -1 : std::stoi(r.out.substr(from + 1, at - from - 1));
  };
  const auto pcap = runRigcal({"driver", "--config", rig, "--sensor", "front_left", "--pcap", g->pcap.string(),
                               "--rate", "max", "--shm-prefix", prefix});
  ASSERT_EQ(pcap.exit_code, 0) << pcap.err;
  const auto packets = runRigcal({"driver", "--config", rig, "--sensor", "front_left", "--bag", g->packets_bag.string(),
                                  "--topic", topicOf("front_left", "packets"), "--rate", "max", "--shm-prefix", prefix});
  ASSERT_EQ(packets.exit_code, 0) << packets.err;
  EXPECT_NE(packets.out.find("reading bag topic /sensing/lidar/front_left/packets (nebula_msgs/msg/NebulaPackets)"),
            std::string::npos) << packets.out;
  const auto clouds = runRigcal({"driver", "--config", rig, "--sensor", "front_left", "--bag", g->clouds_bag.string(),
                                 "--topic", topicOf("front_left", "points"), "--rate", "max", "--shm-prefix", prefix});
  ASSERT_EQ(clouds.exit_code, 0) << clouds.err;
  ASSERT_GT(published(pcap), 3);
  EXPECT_EQ(published(packets), published(pcap)) << packets.out;
  EXPECT_EQ(published(clouds), int(g->clouds["front_left"])) << clouds.out;
}

}  // namespace
}  // namespace rigcal::test
