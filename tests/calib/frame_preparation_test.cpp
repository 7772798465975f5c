// A later frame's source and crop prepared on a thread of its own (FramePrefetch) while the calibrator
// builds the previous frame's target: the same preparation as made on the spot, safe while the dataset
// lets go of its mapping clouds, and stopped at once when nobody will read it.
#include <gtest/gtest.h>

#include <chrono>
#include <memory>
#include <thread>

#include "lidar_lidar_sim_dataset.hpp"
#include "rigcal/calib/lidar_lidar/frame_preparation.hpp"

namespace rigcal::calib {
namespace {

using Clock = std::chrono::steady_clock;

double secondsSince(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

FramePreparationInputs inputsFor(const pipeline::CalibrationDataset& d, std::size_t frame,
                                 const config::Parameters& params) {
  FramePreparationInputs in;
  in.index = frame;
  in.deskewed = d.frames[frame].deskewed;
  in.target.near_poses = {d.T_mapping_calib_guess};
  in.target.near_radius = nearTargetRadius(params);
  in.window = targetWindowClouds(d, frame, params, in.target.max_clouds);
  return in;
}

void expectSameCloud(const registration::PointCloud& a, const registration::PointCloud& b) {
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i) ASSERT_EQ(a.points[i], b.points[i]) << "point " << i;
}

TEST(FramePrefetch, GivesWhatPreparingNowGives) {
  const auto& data = test::flatParkingLot();
  const auto& d = data.datasets.front();
  const std::size_t frame = d.frames.size() - 1;
  const PreparedFrame now = prepareFrame(inputsFor(d, frame, data.params), data.params, 10);
  ASSERT_GT(now.cloud.size(), 1000u);

  FramePrefetch prefetch;
  prefetch.start(inputsFor(d, frame, data.params), data.params, 10);
  EXPECT_FALSE(prefetch.take(frame - 1).has_value()) << "handed out as another frame";
  EXPECT_FALSE(prefetch.take(frame).has_value()) << "a preparation asked for the wrong frame is dropped";
  prefetch.start(inputsFor(d, frame, data.params), data.params, 10);
  const auto ahead = prefetch.take(frame);
  ASSERT_TRUE(ahead.has_value());
  EXPECT_FALSE(ahead->out_of_time);
  EXPECT_EQ(ahead->index, frame);
  EXPECT_EQ(ahead->clouds, now.clouds);
  EXPECT_EQ(ahead->cropped, now.cropped);
  expectSameCloud(ahead->source, now.source);
  expectSameCloud(ahead->cloud, now.cloud);
  EXPECT_FALSE(prefetch.take(frame).has_value()) << "taken twice";
}

// What the calibrator does when a target runs out of time: every mapping cloud goes, perhaps while the
// next frame's crop reads them. A dataset that alone owns its clouds (deep copies) frees them then, unless
// the preparation holds its own references (ASan would see a crop reading freed points).
TEST(FramePrefetch, HoldsTheCloudsOfAWindowTheDatasetDroppedMidCrop) {
  const auto& data = test::flatParkingLot();
  pipeline::CalibrationDataset d = data.datasets.front();
  for (auto& mc : d.mapping_clouds)
    if (mc.cloud != nullptr) mc.cloud = std::make_shared<const Scan>(*mc.cloud);
  const std::size_t frame = d.frames.size() - 1;
  const PreparedFrame now = prepareFrame(inputsFor(d, frame, data.params), data.params, 10);
  FramePrefetch prefetch;
  prefetch.start(inputsFor(d, frame, data.params), data.params, 10);
  for (auto& mc : d.mapping_clouds) mc.cloud.reset();
  const auto ahead = prefetch.take(frame);
  ASSERT_TRUE(ahead.has_value());
  expectSameCloud(ahead->cloud, now.cloud);
}

TEST(FramePrefetch, AbandonStopsAPreparationLongBeforeItWouldEnd) {
  const auto& data = test::flatParkingLot();
  const auto& d = data.datasets.front();
  const std::size_t frame = d.frames.size() - 1;
  FramePreparationInputs in = inputsFor(d, frame, data.params);
  auto t = Clock::now();
  (void)prepareFrame(in, data.params, 10);
  const double one_window = secondsSince(t);
  // The same clouds 200 times over: a crop some 200 windows long, polled between clouds.
  const auto clouds = in.window.clouds;
  for (int k = 1; k < 200; ++k) in.window.clouds.insert(in.window.clouds.end(), clouds.begin(), clouds.end());
  FramePrefetch prefetch;
  t = Clock::now();
  prefetch.start(in, data.params, 10);
  std::this_thread::sleep_for(std::chrono::duration<double>(2.0 * one_window));
  prefetch.abandon();
  const double until_stopped = secondsSince(t);
  EXPECT_LT(until_stopped, 0.25 * 200.0 * one_window) << "one window took " << one_window << " s";
  EXPECT_FALSE(prefetch.take(frame).has_value()) << "an abandoned preparation was handed out";
}

TEST(FramePrefetch, APreparationPastItsDeadlineSaysSo) {
  const auto& data = test::flatParkingLot();
  const auto& d = data.datasets.front();
  FramePreparationInputs in = inputsFor(d, d.frames.size() - 1, data.params);
  in.target.deadline = registration::Deadline::at(Clock::now());
  FramePrefetch prefetch;
  prefetch.start(in, data.params, 10);
  const auto ahead = prefetch.take(in.index);
  ASSERT_TRUE(ahead.has_value());
  EXPECT_TRUE(ahead->out_of_time);
  EXPECT_TRUE(ahead->cloud.empty());
}

}  // namespace
}  // namespace rigcal::calib
