#include "rigcal/calib/lidar_lidar/lidar_lidar_worker.hpp"

#include <chrono>

#include "rigcal/core/heap_release.hpp"

namespace rigcal::calib {

LidarLidarOptions optionsForShare(LidarLidarOptions options, const CalibrationBudget& budget) {
  if (budget.othersToCome()) options.search_share = 0.0;
  return options;
}

LidarLidarWorker::LidarLidarWorker(const config::Parameters& params, std::size_t calibration_lidars,
                                   const LidarLidarOptions& options, const registration::CancelToken* cancel,
                                   bool keep_mapping_clouds)
    : params_(params),
      options_(options),
      keep_mapping_clouds_(keep_mapping_clouds),
      budget_(params.calibration_deadline_s, calibration_lidars, cancel),
      thread_([this] { loop(); }) {}

LidarLidarWorker::~LidarLidarWorker() { finish(); }

void LidarLidarWorker::add(std::shared_ptr<const pipeline::CalibrationDataset> dataset) {
  {
    const std::lock_guard lock(mutex_);
    pending_.push_back(std::move(dataset));
  }
  wake_.notify_one();
}

void LidarLidarWorker::finish() {
  {
    const std::lock_guard lock(mutex_);
    input_done_ = true;
  }
  wake_.notify_one();
  if (thread_.joinable()) thread_.join();
}

std::size_t LidarLidarWorker::started() const {
  const std::lock_guard lock(mutex_);
  return started_;
}

std::size_t LidarLidarWorker::completed() const {
  const std::lock_guard lock(mutex_);
  return completed_;
}

void LidarLidarWorker::waitIdle() {
  std::unique_lock lock(mutex_);
  idle_.wait(lock, [&] { return pending_.empty() && completed_ == started_; });
}

void LidarLidarWorker::loop() {
  for (;;) {
    std::shared_ptr<const pipeline::CalibrationDataset> dataset;
    {
      std::unique_lock lock(mutex_);
      if (pending_.empty()) budget_.pause();  // waiting for a dataset is not calibration time
      wake_.wait(lock, [&] { return input_done_ || !pending_.empty(); });
      if (pending_.empty()) return;
      // After the end of input no other lidar will come: the pending ones share all that is left.
      if (input_done_) budget_.expectRuns(pending_.size());
      dataset = std::move(pending_.front());
      pending_.pop_front();
      ++started_;
    }
    // The worker's own copy (the clouds are shared, not copied): with the pipeline's reference gone at the
    // hand-over, it alone holds the clouds no other lane or the pipeline's store still needs, and can let
    // each go once its targets are built rather than after the whole calibration.
    pipeline::CalibrationDataset owned = *dataset;
    dataset.reset();
    // The pipeline's freed clouds before the targets are built; the targets (and clouds) once freed.
    releaseFreedHeap();
    const auto t0 = std::chrono::steady_clock::now();
    const registration::Deadline share = budget_.next();
    const LidarLidarOptions options = optionsForShare(options_, budget_);
    LidarLidarResult result = keep_mapping_clouds_
                                  ? calibrateLidarLidar(owned, params_, share, options)
                                  : calibrateLidarLidarDroppingClouds(owned, params_, share, options);
    seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    results.push_back(std::move(result));
    if (!keep_mapping_clouds_) owned.mapping_clouds = {};
    datasets.push_back(std::move(owned));
    releaseFreedHeap();
    {
      const std::lock_guard lock(mutex_);
      ++completed_;
    }
    idle_.notify_all();
  }
}

}  // namespace rigcal::calib
