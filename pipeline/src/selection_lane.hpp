#pragma once
// The selector stage's work for one calibration lidar: keeps every candidate pairing, re-runs
// selectFrames() when an accepted one arrives, and builds the CalibrationDataset once the frame budget
// is full (or at end of input with at least lidar_calibration_min_frames). A candidate that may still be
// selected holds its scans and the clouds its target would be built from (spreadWindowPicks() of its
// dense window, at most kTargetWindowClouds); one that can never be (not accepted, too flat, near a lost
// keyframe, or any after the hand-over) keeps only its pairing, for the dataset's account of candidates.
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "pairing_lane.hpp"
#include "rigcal/pipeline/calibration_dataset.hpp"
#include "rigcal/pipeline/pipeline.hpp"
#include "rigcal/pipeline/pipeline_observer.hpp"

namespace rigcal::pipeline {

/// The stored mapping cloud of a stored frame index (nullptr once released).
using CloudLookup = std::function<std::shared_ptr<const Scan>(std::size_t stored_index)>;

class SelectionLane {
 public:
  SelectionLane(std::string mapping_sensor, std::string calibration_sensor, const Pose& T_base_mapping,
                const Pose& T_mapping_calib_guess, const config::Parameters& params);

  /// Returns the dataset when this candidate fills the budget (once).
  std::shared_ptr<const CalibrationDataset> add(CandidateMessage candidate, const CloudLookup& clouds);
  /// End of input: the dataset if enough frames are selected and it was not handed over yet.
  std::shared_ptr<const CalibrationDataset> finish();

  [[nodiscard]] bool handedOver() const { return handed_over_; }
  /// The first stored frame a future candidate's window may start at (none once handed over).
  [[nodiscard]] std::optional<std::size_t> neededFrom(const std::vector<std::size_t>& keyframes) const;
  [[nodiscard]] std::size_t candidates() const { return records_.size(); }
  [[nodiscard]] std::size_t accepted() const { return accepted_; }
  [[nodiscard]] std::size_t selected() const { return selection_.selected.size(); }
  [[nodiscard]] Shortfall shortfall() const;
  /// The latest candidate and the current selection, for a PipelineObserver.
  [[nodiscard]] CandidateEvent lastCandidateEvent(int lane) const;

 private:
  struct Record {
    CandidateMessage c;  // c.frames is reset: the lane keeps the latest snapshot only (trajectory_)
    std::vector<std::pair<std::size_t, MappingCloud>> window;  // its target's clouds, by stored index
  };
  /// The clouds of the candidate's dense window its target would be built from (isTargetCloud()).
  std::vector<std::pair<std::size_t, MappingCloud>> windowPicks(const CandidateMessage& c,
                                                                 const CloudLookup& clouds) const;
  /// A candidate that can never be selected: only its pairing is kept.
  static void release(Record& r);
  void reselect();
  std::shared_ptr<const CalibrationDataset> dataset(bool budget_full) const;
  /// The dataset, once; then releases every record's window clouds.
  std::shared_ptr<const CalibrationDataset> handOver(bool budget_full);

  CalibrationDataset base_;
  config::Parameters params_;
  std::vector<Record> records_;
  std::shared_ptr<const std::vector<MappingFrame>> trajectory_;  // the latest candidate's stored frames
  std::vector<int> lost_keyframes_;
  Selection selection_;
  std::size_t accepted_ = 0;
  int last_keyframe_ = -1;
  bool handed_over_ = false;
};

}  // namespace rigcal::pipeline
