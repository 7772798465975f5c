// Issue #18 (peak memory): a calibration lets each mapping cloud go once the last target built from it
// exists, not when the whole calibration (and the lidars after it) ends. The rule on a dataset made by hand,
// then the calibration and the worker on simulated data: the same result, and the clouds freed while the
// lidar is still being calibrated.
#include <gtest/gtest.h>

#include <chrono>
#include <memory>
#include <vector>

#include "lidar_lidar_sim_dataset.hpp"
#include "rigcal/calib/lidar_lidar/augmented_target.hpp"
#include "rigcal/calib/lidar_lidar/lidar_lidar_calibration.hpp"
#include "rigcal/calib/lidar_lidar/lidar_lidar_worker.hpp"
#include "rigcal/calib/lidar_lidar/mapping_cloud_release.hpp"
#include "sanitizers.hpp"

namespace rigcal::calib {
namespace {

std::shared_ptr<const Scan> cloudOf(std::size_t points) {
  auto s = std::make_shared<Scan>();
  for (std::size_t i = 0; i < points; ++i) s->x.push_back(float(i)), s->y.push_back(0.0F), s->z.push_back(0.0F);
  return s;
}

/// Four clouds; frame 0 is built from clouds {0, 1}, frame 1 from {1, 2}, frame 2 from {3}.
pipeline::CalibrationDataset handMade() {
  pipeline::CalibrationDataset d;
  d.mapping_clouds.resize(4);
  for (auto& c : d.mapping_clouds) c.cloud = cloudOf(10);
  d.frames.resize(3);
  d.frames[0].window = {0, 1};
  d.frames[1].window = {1, 2};
  d.frames[2].window = {3};
  return d;
}

std::vector<bool> held(const pipeline::CalibrationDataset& d) {
  std::vector<bool> out;
  for (const auto& c : d.mapping_clouds) out.push_back(c.cloud != nullptr);
  return out;
}

TEST(MappingCloudRelease, EachCloudGoesOnceNoPendingFrameNamesIt) {
  pipeline::CalibrationDataset d = handMade();
  std::vector<std::weak_ptr<const Scan>> watch;
  for (const auto& c : d.mapping_clouds) watch.push_back(c.cloud);
  EXPECT_EQ(dropMappingCloudsDoneWith(d, 0), 0u) << "every cloud is still to be read";
  EXPECT_EQ(dropMappingCloudsDoneWith(d, 1), 1u);  // frame 0 done: cloud 0; cloud 1 waits for frame 1
  EXPECT_EQ(held(d), (std::vector<bool>{false, true, true, true}));
  EXPECT_TRUE(watch[0].expired()) << "the dataset held the only reference: the cloud is freed";
  EXPECT_EQ(dropMappingCloudsDoneWith(d, 2), 2u);
  EXPECT_EQ(held(d), (std::vector<bool>{false, false, false, true}));
  EXPECT_EQ(dropMappingCloudsDoneWith(d, 3), 1u) << "all frames done (or out of time): the last one goes";
  for (const auto& w : watch) EXPECT_TRUE(w.expired());
  EXPECT_EQ(d.mapping_clouds.size(), 4u) << "frames and poses stay: the windows' indices keep their meaning";
  EXPECT_EQ(dropMappingCloudsDoneWith(d, 3), 0u);
}

TEST(MappingCloudRelease, APendingFrameWithoutAWindowKeepsEveryCloud) {
  pipeline::CalibrationDataset d = handMade();
  d.frames[2].window.clear();  // its target takes every cloud of its keyframe range
  EXPECT_EQ(dropMappingCloudsDoneWith(d, 2), 0u);
  EXPECT_EQ(held(d), (std::vector<bool>{true, true, true, true}));
  EXPECT_EQ(dropMappingCloudsDoneWith(d, 3), 4u);
}

class MappingCloudReleaseSim : public ::testing::Test {
 protected:
  static const test::SimDatasets& data() { return test::flatParkingLot(); }
  static void TearDownTestSuite() { test::releaseFlatParkingLot(); }

  /// Dataset i with each frame's window given (the picks the calibration would make by itself, as the
  /// pipeline gives them) and its own copies of the clouds: no one else holds them.
  static pipeline::CalibrationDataset owned(std::size_t i) {
    pipeline::CalibrationDataset d = data().datasets.at(i);
    for (std::size_t f = 0; f < d.frames.size(); ++f)
      d.frames[f].window = targetWindow(d, f, data().params, AugmentedTargetOptions{}.max_clouds);
    for (auto& c : d.mapping_clouds) c.cloud = std::make_shared<const Scan>(*c.cloud);
    return d;
  }
};

// The same result, bit for bit, and no cloud left in the dataset afterwards; some went before the last
// frame's target (the windows do not all overlap), which the rule above decides.
TEST_F(MappingCloudReleaseSim, DroppingCloudsGivesTheSameResult) {
  if (RIGCAL_SANITIZED) GTEST_SKIP() << "two calibrations: Release only (the rule is tested above, instrumented)";
  const auto deadline = registration::Deadline::after(std::chrono::seconds(600));
  LidarLidarOptions options;
  options.exhaustive = false;  // a run that ends by itself, not by the clock: comparable bit for bit
  pipeline::CalibrationDataset kept = owned(0), dropped = owned(0);
  const LidarLidarResult a = calibrateLidarLidar(kept, data().params, deadline, options);
  const LidarLidarResult b = calibrateLidarLidarDroppingClouds(dropped, data().params, deadline, options);
  ASSERT_TRUE(a.ok) << a.failure;
  ASSERT_FALSE(a.deadline_reached);
  EXPECT_TRUE(a.T_mapping_calib.matrix() == b.T_mapping_calib.matrix())
      << a.T_mapping_calib.matrix() << "\nvs\n" << b.T_mapping_calib.matrix();
  EXPECT_EQ(a.final_score.value, b.final_score.value);
  EXPECT_EQ(a.frames_used, b.frames_used);
  EXPECT_EQ(a.runs.size(), b.runs.size());
  for (const auto& c : kept.mapping_clouds) EXPECT_NE(c.cloud, nullptr);
  for (const auto& c : dropped.mapping_clouds) EXPECT_EQ(c.cloud, nullptr);
  // Frame 0's window differs from the last frame's: the rule had something to drop before the end.
  pipeline::CalibrationDataset probe = owned(0);
  EXPECT_GT(dropMappingCloudsDoneWith(probe, probe.frames.size() - 1), 0u);
}

// Through the worker `rigcal calibrate` uses (the mapping clouds not kept): it owns the dataset from the
// hand-over, so the clouds are freed during the lidar's calibration — each cloud's deleter runs on the
// worker's thread before the lidar's result exists. Before, the worker kept the handed-over dataset whole
// until its calibration had ended.
TEST_F(MappingCloudReleaseSim, TheWorkerFreesTheCloudsDuringTheCalibration) {
  if (RIGCAL_SANITIZED) GTEST_SKIP() << "a whole calibration: Release only (the rule is tested above, instrumented)";
  config::Parameters params = data().params;
  params.calibration_deadline_s = 30.0;
  LidarLidarOptions options;
  options.exhaustive = false;
  LidarLidarWorker worker(params, 1, options, nullptr, /*keep_mapping_clouds=*/false);
  std::vector<std::size_t> results_when_freed;  // written on the worker's thread only, read after finish()
  auto d = std::make_shared<pipeline::CalibrationDataset>(owned(0));
  const std::size_t clouds = d->mapping_clouds.size();
  for (auto& c : d->mapping_clouds) {
    c.cloud = std::shared_ptr<const Scan>(new Scan(*c.cloud), [&](const Scan* s) {
      results_when_freed.push_back(worker.results.size());
      delete s;
    });
  }
  worker.add(std::move(d));
  worker.finish();
  ASSERT_EQ(worker.results.size(), 1u);
  ASSERT_TRUE(worker.results[0].ok) << worker.results[0].failure;
  ASSERT_EQ(results_when_freed.size(), clouds) << "every cloud freed by the time the worker is done";
  for (const std::size_t n : results_when_freed) EXPECT_EQ(n, 0u) << "freed only after the lidar's result";
  EXPECT_TRUE(worker.datasets.at(0).mapping_clouds.empty());
  EXPECT_FALSE(worker.datasets.at(0).frames.empty()) << "the rest of the dataset stays for the outputs";
}

}  // namespace
}  // namespace rigcal::calib
