#pragma once
// The bounded-time lidar-lidar calibration of one dataset (calibrateLidarLidar's engine), one concept per
// source file: the run's order of work and the scores (lidar_lidar_calibrator.cpp), each frame's source and
// augmented target (lidar_lidar_frames.cpp), the per-frame ensemble and the batched ICP
// (lidar_lidar_ensemble.cpp). Private to calib/.
#include <chrono>
#include <cstddef>
#include <functional>
#include <memory>
#include <set>
#include <tuple>
#include <vector>

#include "rigcal/calib/lidar_lidar/calibration_score.hpp"
#include "rigcal/calib/lidar_lidar/frame_preparation.hpp"
#include "rigcal/calib/lidar_lidar/lidar_lidar_calibration.hpp"

namespace rigcal::calib::detail {

using Clock = std::chrono::steady_clock;
using registration::Deadline;
using registration::PointCloud;
using registration::SourceTarget;
using registration::Target;

inline double since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

inline bool finitePose(const Pose& T) { return T.matrix().allFinite(); }

/// Two starts closer than this give the same registration result: run it once.
inline bool samePose(const Pose& a, const Pose& b) {
  return (a.translation() - b.translation()).norm() < 1e-4 && rotationAngleBetween(a, b) < deg2rad(0.005);
}

struct Frame {
  std::size_t index = 0;  // in the dataset
  PointCloud source;        // covariances only once a GICP ran on the frame (ensureSourceCovariances)
  PointCloud score_source;  // every stride-th point: what the all-frames score looks at
  std::shared_ptr<const Target> target;
  bool set_aside = false;  // out of the objective (setAsideDisagreeingFrames)
};

/// What building a frame came to: the frame, a frame skipped for want of points, or no time to build it.
enum class FrameBuild { kBuilt, kSkipped, kOutOfTime };

class Calibrator {
 public:
  /// Called after each frame's target was tried, with the first frame whose target is still to come
  /// (frames.size(): none will be built); the dataset's owner may then let go of what only those targets read
  /// (calibrateLidarLidarDroppingClouds: the mapping clouds). Frames are built in order.
  using TargetsDone = std::function<void(std::size_t first_pending)>;

  /// `share`: this lidar's deadline. The plan ends early enough for the trajectory clock estimate after it
  /// (LidarLidarOptions::trajectory_clock): at first by `trajectory_clock_share` of the share, then, once a
  /// score was timed, by what the estimate's residual passes are expected to take.
  Calibrator(const pipeline::CalibrationDataset& dataset, const config::Parameters& params, const Deadline& share,
             const LidarLidarOptions& options, LidarLidarResult& out, TargetsDone targets_done = {});

  /// The plan: the most informative frame first, then the others' targets, the batched ICP, the re-deskew and
  /// the other frames' ensembles. out_ holds the best result (or the failure); true when the plan ran to its
  /// end (out_.deadline_reached when the deadline cut it).
  bool run();

  /// After a complete plan, until `until` (no later than the share): upstream's batched chain from the
  /// initial guess, then the exhaustive ensembles. True when it found a better result (out_ updated). The
  /// deadline ending it does not make the result "the best so far of a cut plan".
  bool searchForAnotherBasin(const Deadline& until);

  /// The frames registered (sources re-deskewed with the result), for the trajectory clock estimate.
  [[nodiscard]] const std::vector<Frame>& frames() const { return frames_; }

 private:
  // The plan, in run()'s order. Each phase stops when the deadline passes.
  /// The first dataset frame that builds, and its ensemble; `next` moves past the frames tried. False (with
  /// out_.failure) when no frame could be built.
  bool firstFrame(std::size_t& next);
  /// The other frames' targets, each confirmed by one ICP, while each leaves time for the rescore and the
  /// batched chain; true when the deadline cut them.
  bool laterTargets(std::size_t& next, std::size_t first_frames);
  /// The grown set's rescore, the batched chain, the re-deskew, then the other frames' ensembles; true when
  /// all of it ran.
  bool restOfPlan(std::size_t first_frames);
  /// The best so far into out_ (result, scores, ok / failure, stage seconds).
  void publish();

  /// The plan's deadline: the share less what the trajectory clock estimate after it is expected to take,
  /// from the last score's time per point (`trajectory_clock_share` of the share until a score is timed).
  void reserveClockEstimate();

  /// The deadline passed (or the run was cancelled): every step stops. Whether that cut the plan is run()'s
  /// call (out_.deadline_reached): the exhaustive pass at the end only fills the time left.
  [[nodiscard]] bool stopped() const;

  /// Source and augmented target of dataset frame i; a frame without enough points is skipped (noted).
  /// Out of time when the target's build would leave less than `reserve` seconds.
  FrameBuild buildFrame(std::size_t i, double reserve = 0.0);
  FrameBuild buildFrameTarget(std::size_t i, double reserve);  // buildFrame's work, before the clouds' release
  /// The augmented target's options for the next frame built: near the best once it moved from the guess.
  [[nodiscard]] AugmentedTargetOptions targetOptions() const;
  /// What preparing frame i reads, held (the crop may run on another thread).
  [[nodiscard]] FramePreparationInputs preparationInputs(std::size_t i, int num_threads) const;
  [[nodiscard]] std::size_t minSourcePoints() const;

  /// The initial guess's and the best's scores over the frames built so far (the set just grew).
  void rescore();

  void rebuildScorePairs();

  CalibrationScore score(const Pose& T);

  /// A registration stops early enough that its result can still be scored before the real deadline.
  [[nodiscard]] Deadline registrationDeadline() const;

  /// Scores a candidate over all frames and keeps it when it is the best so far; false when out of time.
  bool consider(const Pose& T, RegistratorRun* run);

  std::size_t addCandidate(const Pose& T);

  /// Upstream's per-frame ensemble: each registrator in turn, its best result becoming a candidate.
  /// Quick pass (exhaustive = false): each registrator from the frame's best candidate so far — the
  /// chain NDT → GICP → ICP coarse → fine → ultra-fine that brings the largest improvement per second.
  /// Exhaustive pass: each registrator from every candidate so far not yet tried with it on this frame.
  void frameEnsemble(std::size_t k, bool exhaustive);

  /// Frame k's source covariances for GICP, estimated once, when a GICP is first run on it (most frames cut
  /// by the deadline never need them); false when it does not fit in the time left or the deadline cut it.
  bool ensureSourceCovariances(std::size_t k);

  /// One cheap registration of frame k alone (ICP fine from the best so far): where that frame puts the
  /// lidar, so that the verdict can check that the frames agree before the deadline cuts the full ensembles.
  void confirmOnFrame(std::size_t k);

  /// Frames whose own registration on their re-deskewed source lands away from the best (beyond the verdict's
  /// agreement distance) leave the all-frames score and the batched ICP, when a majority of at least two
  /// agrees: a frame that sees a target the others contradict (a slid or mis-posed augmented cloud) pulls the
  /// result by its share otherwise. True when some were set aside (the scores and the best were redone).
  bool setAsideDisagreeingFrames();

  /// What batchedChain over `frames` frames is expected to take, from the ICP fine runs so far (0 before any).
  [[nodiscard]] double batchedChainEstimate(std::size_t frames) const;

  /// Batched ICP over all frames (but those set aside) at 0.5 → 0.1 → 0.05 m from `start`.
  void batchedChain(const Pose& start);

  /// Re-deskews every frame with the best extrinsic, then the batched ICP chain from the best, then each
  /// frame's confirmation on its re-deskewed source (what the verdict compares with the result); false when
  /// the deadline cut it. (Upstream, where this is the last step, also runs the chain from the initial guess
  /// here: run() does that after the plan, as a search for another basin like the exhaustive pass.)
  bool finalStep();

  const pipeline::CalibrationDataset& data_;
  const config::Parameters& params_;
  const Deadline share_;  // the lidar's
  Deadline deadline_;     // the current step's: the plan's (the share less the clock's reserve), or the search's
  const LidarLidarOptions& opt_;
  LidarLidarResult& out_;
  TargetsDone targets_done_;
  std::vector<Frame> frames_;
  struct StageSeconds {
    double targets = 0.0, ensemble = 0.0, batched = 0.0, redeskew_final = 0.0;
  } seconds_;  // out_.stage_seconds
  std::vector<SourceTarget> score_pairs_;
  double score_seconds_ = 0.0;
  std::size_t score_points_ = 0;  // over all score pairs, when score_seconds_ was timed
  // Target build cost per point; until measured, a pessimistic guess (measured 2–7 µs on a loaded 2-core box).
  double seconds_per_point_ = 6e-6;
  double last_prepare_seconds_ = 0.0;  // the last frame's source and crop, before its target build
  CalibrationScore initial_score_;
  // (frame, registrator, start, re-deskewed) runs done: a re-deskewed source is another registration problem.
  std::set<std::tuple<std::size_t, int, std::size_t, bool>> tried_;
  bool redeskewed_ = false;  // the sources were re-deskewed with the best extrinsic (finalStep)
  Pose best_ = Pose::Identity();
  CalibrationScore best_score_;
  FramePrefetch prefetch_;  // the next later frame's source and crop (last member: joined first)
};

}  // namespace rigcal::calib::detail
