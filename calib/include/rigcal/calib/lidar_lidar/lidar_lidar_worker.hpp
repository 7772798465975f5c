#pragma once
// Calibrates the datasets the pipeline hands over — one per calibration lidar, as soon as its frame
// budget is full, the others at the end of input — on its own thread while mapping goes on. Every lidar
// of the rig shares one calibration_deadline_s (CalibrationBudget): a lidar whose dataset comes early
// gets its fair share of the whole (deadline / number of calibration lidars, plus whatever the lidars
// before it left), not the whole deadline; the clock is paused while the worker waits for a dataset, and
// at the end of input the lidars still pending share all that is left.
#include <condition_variable>
#include <cstddef>
#include <deque>
#include <memory>
#include <mutex>
#include <thread>
#include <vector>

#include "rigcal/calib/lidar_lidar/calibration_budget.hpp"
#include "rigcal/calib/lidar_lidar/lidar_lidar_calibration.hpp"

namespace rigcal::calib {

/// `options` for the lidar whose share `budget.next()` just gave: while other lidars are still to come, what
/// its complete plan leaves goes on to their plans, not to its searches for another basin (search_share 0);
/// the last lidar searches with all that is left. On the street the first lidar's searches had filled its
/// share and the second one's plan was cut in every run; with half of it handed on, in 6 of 8; with all, in
/// none of 3.
LidarLidarOptions optionsForShare(LidarLidarOptions options, const CalibrationBudget& budget);

class LidarLidarWorker {
 public:
  /// `calibration_lidars`: how many datasets may come (the rig's calibration lidars).
  /// `keep_mapping_clouds` false: `datasets` keeps each dataset without its mapping clouds once it is
  /// calibrated, for a caller with a map of its own. They are most of a dataset's bytes, and the lidars
  /// calibrated after it (the rest of the drive) would otherwise hold them too. The worker then also lets
  /// each cloud go during the calibration, once the last target built from it exists
  /// (calibrateLidarLidarDroppingClouds): it owns the dataset from the hand-over on (add() should get the
  /// only reference; the clouds another holder keeps are not freed).
  LidarLidarWorker(const config::Parameters& params, std::size_t calibration_lidars,
                   const LidarLidarOptions& options = {}, const registration::CancelToken* cancel = nullptr,
                   bool keep_mapping_clouds = true);
  ~LidarLidarWorker();  // finish()
  LidarLidarWorker(const LidarLidarWorker&) = delete;
  LidarLidarWorker& operator=(const LidarLidarWorker&) = delete;

  /// Queues one lidar's dataset (any thread; returns at once).
  void add(std::shared_ptr<const pipeline::CalibrationDataset> dataset);
  /// No more datasets will come: the pending ones share what is left. Waits until all are calibrated.
  void finish();
  /// Datasets whose calibration has started / is done so far (any thread).
  [[nodiscard]] std::size_t started() const;
  [[nodiscard]] std::size_t completed() const;
  /// Blocks until every dataset added so far is calibrated. An offline replay calls it from the dataset
  /// callback: the lossless pipeline then waits (its queues fill and the pcap reader pauses), so the
  /// calibration has both cores for its whole budget instead of sharing them with mapping at full speed.
  void waitIdle();

  /// After finish(): the datasets in the order they were calibrated, their results, and the calibration
  /// seconds spent (waits for datasets excluded: what calibration_deadline_s bounds).
  std::vector<pipeline::CalibrationDataset> datasets;
  std::vector<LidarLidarResult> results;
  double seconds = 0.0;

 private:
  void loop();

  config::Parameters params_;
  LidarLidarOptions options_;
  bool keep_mapping_clouds_;
  CalibrationBudget budget_;
  mutable std::mutex mutex_;
  std::condition_variable wake_;
  std::condition_variable idle_;  // a calibration completed
  std::deque<std::shared_ptr<const pipeline::CalibrationDataset>> pending_;
  bool input_done_ = false;
  std::size_t started_ = 0, completed_ = 0;
  std::thread thread_;
};

}  // namespace rigcal::calib
