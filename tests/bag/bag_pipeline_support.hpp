#pragma once
// What the bag pipeline tests share: a short parking-lot recording turned into sqlite3 bags once per suite
// (the BagPipeline fixture: packets and PointCloud2 forms, /tf_static), rig files whose sources name bag
// topics, and trajectory.csv rows to compare runs of `rigcal map`.
#include <gtest/gtest.h>

#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "bag_from_recording.hpp"
#include "rigcal/config/rig_config.hpp"
#include "test_data.hpp"

namespace rigcal::test {


/// /sensing/lidar/<sensor>/<form>, the topics the BagPipeline recording's bags use.
std::string topicOf(const std::string& sensor, const char* form);

/// rig.yaml with every sensor's UDP source replaced by its bag topic (and, optionally, a new
/// initial_extrinsics section).
std::string rigWithTopics(const std::string& rig, const char* form, const std::string& extrinsics = {});

/// `--topic sensor=/<sensor>/<form>` for every sensor: the topics `rigcal sim --format` writes.
std::vector<std::string> simTopics(const config::RigConfig& rig, const char* form);

/// Frames at the end of a map run that depend on thread timing at the end of input (1-2 measured on a quiet
/// machine; more when a loaded machine lets the driver threads reach the end further apart: a busy
/// `ctest -j 2` once saw more than 3).
inline constexpr std::size_t kEndFrames = 8;

/// trajectory.csv's data rows (comments left out).
std::vector<std::string> trajectoryRows(const std::filesystem::path& out);

/// One short parking-lot recording and its bags, made once for the suite.
struct Recording {
  TempDir dir;
  config::RigConfig rig;
  std::filesystem::path pcap, packets_bag, clouds_bag;
  std::map<std::string, std::size_t> clouds;  // per sensor
  std::string error;
};

class BagPipeline : public ::testing::Test {
 protected:
  static void SetUpTestSuite();
  static void TearDownTestSuite();
  void SetUp() override { ASSERT_TRUE(g->error.empty()) << g->error; }
  /// `--topic sensor=<topicOf(sensor, form)>` for every sensor of the recording's rig.
  static std::vector<std::string> topicArgs(const char* form);

  static Recording* g;
};

}  // namespace rigcal::test
