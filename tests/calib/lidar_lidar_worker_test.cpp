// One calibration_deadline_s for the whole calibration, whenever the lidars' datasets come: the worker
// `rigcal calibrate` uses (LidarLidarWorker) fed in two batches, as the pipeline does when one lidar's
// frame budget fills during the drive and the others' at the end of input. Before, each batch got the
// whole deadline (street: 120 s of lidar-lidar with a 60 s deadline).
#include <gtest/gtest.h>

#include <chrono>
#include <cstdio>
#include <memory>
#include <string>
#include <thread>

#include "lidar_lidar_sim_dataset.hpp"
#include "rigcal/calib/lidar_lidar/calibration_budget.hpp"
#include "rigcal/calib/lidar_lidar/lidar_lidar_worker.hpp"
#include "sanitizers.hpp"

namespace rigcal::calib {
namespace {

using Clock = std::chrono::steady_clock;
using namespace std::chrono_literals;

double secondsFrom(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

class LidarLidarWorkerSim : public ::testing::Test {
 protected:
  static const test::SimDatasets& data() { return test::flatParkingLot(); }
  static void TearDownTestSuite() { test::releaseFlatParkingLot(); }

  static std::shared_ptr<const pipeline::CalibrationDataset> dataset(std::size_t i) {
    return std::make_shared<const pipeline::CalibrationDataset>(data().datasets.at(i));
  }

  /// Waits (bounded) until the worker has calibrated `n` datasets.
  static bool waitCompleted(const LidarLidarWorker& worker, std::size_t n) {
    const auto end = Clock::now() + 120s;
    while (worker.completed() < n && Clock::now() < end) std::this_thread::sleep_for(5ms);
    return worker.completed() >= n;
  }
  /// Waits (bounded) until the worker has started calibrating `n` datasets.
  static bool waitStarted(const LidarLidarWorker& worker, std::size_t n) {
    const auto end = Clock::now() + 120s;
    while (worker.started() < n && Clock::now() < end) std::this_thread::sleep_for(1ms);
    return worker.started() >= n;
  }

  /// A lidar that ran out of time says so; any other failure is a bug here.
  static void expectResultOrDeadline(const LidarLidarResult& r) {
    if (!r.ok) {
      EXPECT_TRUE(r.deadline_reached) << r.calibration_sensor << ": " << r.failure;
      EXPECT_EQ(r.failure.rfind("deadline:", 0), 0u) << r.calibration_sensor << ": " << r.failure;
    }
    EXPECT_TRUE(r.T_mapping_calib.matrix().allFinite());
  }

};

// Lidar A's dataset comes alone (its budget filled during the drive), lidar B's after a pause longer than
// the deadline: A gets half of the 2 s, not all of it; the pause is not calibration time, so B still gets
// what A left; the two together stay within the deadline plus a small overshoot.
TEST_F(LidarLidarWorkerSim, TwoBatchesShareOneDeadline) {
  if (RIGCAL_SANITIZED) GTEST_SKIP() << "wall-clock bound measured in the optimised build only";
  ASSERT_EQ(data().datasets.size(), 2u);
  config::Parameters params = data().params;
  params.calibration_deadline_s = 2.0;
  LidarLidarWorker worker(params, 2);
  const auto start = Clock::now();
  worker.add(dataset(0));
  ASSERT_TRUE(waitCompleted(worker, 1));
  const double first_batch = secondsFrom(start);
  std::this_thread::sleep_for(2500ms);  // the drive goes on; B's budget fills later
  worker.add(dataset(1));
  worker.finish();
  ASSERT_EQ(worker.results.size(), 2u);
  const auto &a = worker.results[0], &b = worker.results[1];
  std::printf("batch 1: %s %.3f s (share %.3f s, dl %d); batch 2: %s %.3f s (share %.3f s, dl %d); "
              "calibration %.3f s, wall %.3f s\n",
              a.calibration_sensor.c_str(), a.seconds, a.deadline_share_s, int(a.deadline_reached),
              b.calibration_sensor.c_str(), b.seconds, b.deadline_share_s, int(b.deadline_reached), worker.seconds,
              secondsFrom(start));
  EXPECT_EQ(a.calibration_sensor, data().datasets[0].calibration_sensor);
  EXPECT_NEAR(a.deadline_share_s, 1.0, 0.02) << "the first of two lidars gets half the deadline";
  EXPECT_LT(a.seconds, 1.05);
  EXPECT_LT(first_batch, 1.15);
  EXPECT_NEAR(b.deadline_share_s, 2.0 - a.seconds, 0.05) << "the second gets what is left, the wait excluded";
  EXPECT_GT(b.deadline_share_s, 0.9);
  EXPECT_LT(worker.seconds, 2.1) << "the whole calibration within the deadline + 5 %";
  expectResultOrDeadline(a);
  expectResultOrDeadline(b);
  EXPECT_TRUE(a.ok && b.ok) << "one second each is enough to beat a 0.3 m / 5° guess: " << a.failure << " / "
                            << b.failure;
}

// A rig with three calibration lidars of which only two send data: the first gets a third; at the end of
// input the one still pending gets all that is left (not half of it, as if the third were still to come).
TEST_F(LidarLidarWorkerSim, AtEndOfInputThePendingLidarsShareAllThatIsLeft) {
  if (RIGCAL_SANITIZED) GTEST_SKIP() << "wall-clock bound measured in the optimised build only";
  config::Parameters params = data().params;
  params.calibration_deadline_s = 1.5;
  LidarLidarWorker worker(params, 3);
  worker.add(dataset(0));
  ASSERT_TRUE(waitStarted(worker, 1));  // it starts before the input ends: a third of the deadline
  worker.add(dataset(1));               // queued while the first runs
  worker.finish();                      // end of input during the first run: the third lidar never comes
  ASSERT_EQ(worker.results.size(), 2u);
  const auto &a = worker.results[0], &b = worker.results[1];
  std::printf("3 expected, 2 came: %.3f s (share %.3f s), %.3f s (share %.3f s); calibration %.3f s\n", a.seconds,
              a.deadline_share_s, b.seconds, b.deadline_share_s, worker.seconds);
  EXPECT_NEAR(a.deadline_share_s, 0.5, 0.02);
  EXPECT_LT(a.seconds, 0.55);
  EXPECT_NEAR(b.deadline_share_s, 1.5 - a.seconds, 0.05) << "all that is left, not half of it";
  EXPECT_LT(worker.seconds, 1.6);
  expectResultOrDeadline(a);
  expectResultOrDeadline(b);
}

// A deadline far too short for any target: every lidar still comes back, at once, each with its best
// (the guess) or a failure that names the deadline — never a crash, a hang or a NaN.
TEST_F(LidarLidarWorkerSim, ATinyDeadlineGivesEachLidarAResultOrADeadlineFailure) {
  if (RIGCAL_SANITIZED) GTEST_SKIP() << "wall-clock bound measured in the optimised build only";
  config::Parameters params = data().params;
  params.calibration_deadline_s = 0.1;
  LidarLidarWorker worker(params, 2);
  worker.add(dataset(0));
  ASSERT_TRUE(waitCompleted(worker, 1));
  worker.add(dataset(1));
  worker.finish();
  ASSERT_EQ(worker.results.size(), 2u);
  for (const auto& r : worker.results) {
    std::printf("%s: %.3f s, share %.3f s, ok %d, %s\n", r.calibration_sensor.c_str(), r.seconds, r.deadline_share_s,
                int(r.ok), r.failure.c_str());
    expectResultOrDeadline(r);
    EXPECT_TRUE(r.deadline_reached) << r.calibration_sensor;
  }
  // Bounded overshoot: a step that does not fit is not started, but each lidar first crops its first
  // frame's source and target cloud to learn the target's size (0.08 s each here, quiet machine).
  EXPECT_LT(worker.seconds, 0.1 + 2 * 0.2) << "bounded overshoot";
}

// The worker's thread hand-over (also under ASan and TSan): datasets added from another thread while one
// is being calibrated all come back, in order, with no limit when calibration_deadline_s is off.
TEST_F(LidarLidarWorkerSim, CalibratesEveryDatasetHandedOverFromAnotherThread) {
  config::Parameters params = data().params;
  // No limit: each run ends by itself (no exhaustive pass). Instrumented code is 10-50x slower: bounded there.
  params.calibration_deadline_s = RIGCAL_SANITIZED ? 6.0 : 0.0;
  LidarLidarOptions quick;
  quick.exhaustive = false;
  auto first = data().datasets.at(0), second = data().datasets.at(1);
  first.frames.resize(2);
  second.frames.resize(2);
  LidarLidarWorker worker(params, 2, quick);
  std::thread producer([&] {
    worker.add(std::make_shared<const pipeline::CalibrationDataset>(first));
    std::this_thread::sleep_for(20ms);
    worker.add(std::make_shared<const pipeline::CalibrationDataset>(second));
  });
  producer.join();
  worker.finish();
  ASSERT_EQ(worker.results.size(), 2u);
  ASSERT_EQ(worker.datasets.size(), 2u);
  EXPECT_EQ(worker.results[0].calibration_sensor, first.calibration_sensor);
  EXPECT_EQ(worker.results[1].calibration_sensor, second.calibration_sensor);
  for (const auto& r : worker.results) {
    if (RIGCAL_SANITIZED) {
      expectResultOrDeadline(r);
      continue;
    }
    EXPECT_TRUE(r.ok) << r.calibration_sensor << ": " << r.failure;
    EXPECT_FALSE(r.deadline_reached);
    EXPECT_LT(r.deadline_share_s, 0.0) << "no limit";
  }
  EXPECT_EQ(worker.completed(), 2u);
}

TEST(CalibrationBudget, SharesWhatIsLeftEquallyAndHandsOnUnusedTime) {
  const auto start = Clock::now();
  CalibrationBudget budget(start, 3.0, 3);
  const auto first = budget.next();
  EXPECT_NEAR(std::chrono::duration<double>(first.when() - start).count(), 1.0, 0.05);
  const auto second = budget.next();  // the first lidar used ~nothing: the rest is split in two
  EXPECT_NEAR(std::chrono::duration<double>(second.when() - start).count(), 1.5, 0.05);
  const auto third = budget.next();
  EXPECT_NEAR(std::chrono::duration<double>(third.when() - start).count(), 3.0, 0.05);
  EXPECT_FALSE(budget.othersToCome()) << "the third lidar's share was all that was left";
  CalibrationBudget two(start, 2.0, 2);
  (void)two.next();
  EXPECT_TRUE(two.othersToCome());
  EXPECT_EQ(optionsForShare({}, two).search_share, 0.0) << "what its plan leaves goes on to the next";
  (void)two.next();
  EXPECT_FALSE(two.othersToCome());
  EXPECT_EQ(optionsForShare({}, two).search_share, 1.0);
  CalibrationBudget unlimited(start, 0.0, 2);
  EXPECT_FALSE(unlimited.limited());
  EXPECT_FALSE(unlimited.next().expired());
}

TEST(CalibrationBudget, TheClockStartsWithTheFirstRunAndPausesBetweenRuns) {
  CalibrationBudget budget(1.0, 2);
  std::this_thread::sleep_for(100ms);  // before the first calibration: not counted
  EXPECT_DOUBLE_EQ(budget.spentSeconds(), 0.0);
  const auto t0 = Clock::now();
  const auto first = budget.next();
  EXPECT_NEAR(std::chrono::duration<double>(first.when() - t0).count(), 0.5, 0.02);
  std::this_thread::sleep_for(100ms);
  budget.pause();
  const double spent = budget.spentSeconds();
  EXPECT_GE(spent, 0.1);
  std::this_thread::sleep_for(300ms);  // waiting for the next dataset: not counted
  EXPECT_DOUBLE_EQ(budget.spentSeconds(), spent) << "a paused clock stands still";
  EXPECT_LT(spent, 0.3) << "a sleep of 100 ms overslept by 200 ms? (then this test cannot tell)";
  const auto t1 = Clock::now();
  const auto second = budget.next();  // the last lidar: all that is left
  EXPECT_NEAR(std::chrono::duration<double>(second.when() - t1).count(), 1.0 - spent, 0.01);
  EXPECT_NEAR(std::chrono::duration<double>(budget.overall().when() - t1).count(), 1.0 - spent, 0.01);
}

TEST(CalibrationBudget, ExpectRunsHandsTheRestToThoseStillToCome) {
  CalibrationBudget budget(3.0, 3);
  const auto t0 = Clock::now();
  (void)budget.next();  // a third
  budget.expectRuns(1);  // end of input: only one more
  const auto last = budget.next();
  EXPECT_NEAR(std::chrono::duration<double>(last.when() - t0).count(), 3.0, 0.02);
  CalibrationBudget unlimited(0.0, 2);
  EXPECT_FALSE(unlimited.next().expired());
  unlimited.pause();
  EXPECT_EQ(unlimited.next().when(), registration::Deadline::Clock::time_point::max());
}

// An offline replay waits in its dataset callback until the calibration is done (so that it has both cores):
// waitIdle returns only once every dataset added so far is calibrated, and at once when there is none.
TEST_F(LidarLidarWorkerSim, WaitIdleReturnsOnceEveryDatasetAddedIsCalibrated) {
  config::Parameters params = data().params;
  params.calibration_deadline_s = 0.3;
  LidarLidarWorker worker(params, 2);
  worker.waitIdle();  // nothing added: returns at once
  EXPECT_EQ(worker.completed(), 0u);
  worker.add(dataset(0));
  worker.waitIdle();
  EXPECT_EQ(worker.started(), 1u);
  EXPECT_EQ(worker.completed(), 1u);
  worker.add(dataset(1));
  worker.waitIdle();
  EXPECT_EQ(worker.completed(), 2u);
  worker.finish();
  ASSERT_EQ(worker.results.size(), 2u);
  for (const auto& r : worker.results) expectResultOrDeadline(r);
}

}  // namespace
}  // namespace rigcal::calib
