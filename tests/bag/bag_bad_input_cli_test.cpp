// Bad bag input through the pipeline commands: each a one-line error naming the bag, topic or record, exit 4.
#include <gtest/gtest.h>

#include <algorithm>

#include "bag_pipeline_support.hpp"
#include "run_command.hpp"
#include "sanitizers.hpp"

namespace rigcal::test {
namespace {

using bag::test::SqliteBagWriter;

TEST_F(BagPipeline, BadBagInputIsOneLineWithExitCode4) {
  TempDir out;
  const std::string rig = (g->dir / "rig.yaml").string();
  const auto missing = runRigcal({"map", "--config", rig, "--bag", g->clouds_bag.string(), "--topic",
                                  "top=/sensing/lidar/top/nope", "--out", out.path().string()});
  EXPECT_EQ(missing.exit_code, 4);
  EXPECT_NE(missing.err.find("topic /sensing/lidar/top/nope not in the bag; it has /tf_static, /sensing/lidar/top/points"),
            std::string::npos)
      << missing.err;
  EXPECT_EQ(std::count(missing.err.begin(), missing.err.end(), '\n'), 1) << missing.err;

  const auto wrong_type = runRigcal({"calibrate", "--config", rig, "--bag", g->clouds_bag.string(), "--topic",
                                     "top=/tf_static", "--out", (out / "cal").string()});
  EXPECT_EQ(wrong_type.exit_code, 4);
  EXPECT_NE(wrong_type.err.find("topic /tf_static has type tf2_msgs/msg/TFMessage, not a lidar type"), std::string::npos)
      << wrong_type.err;
  EXPECT_EQ(std::count(wrong_type.err.begin(), wrong_type.err.end(), '\n'), 1) << wrong_type.err;

  { SqliteBagWriter empty(out / "empty.db3"); }
  const auto empty = runRigcal({"map", "--config", rig, "--bag", (out / "empty.db3").string(), "--out",
                                out.path().string()});
  EXPECT_EQ(empty.exit_code, 4);
  EXPECT_NE(empty.err.find("empty.db3: empty bag"), std::string::npos) << empty.err;
  EXPECT_EQ(std::count(empty.err.begin(), empty.err.end(), '\n'), 1) << empty.err;

  const auto unnamed = runRigcal({"map", "--config", rig, "--bag", g->packets_bag.string(), "--out", out.path().string()});
  EXPECT_EQ(unnamed.exit_code, 4);
  EXPECT_NE(unnamed.err.find("several lidar topics"), std::string::npos) << unnamed.err;
}

}  // namespace
}  // namespace rigcal::test
