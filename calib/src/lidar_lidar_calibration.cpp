#include "rigcal/calib/lidar_lidar_calibration.hpp"

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cmath>
#include <exception>
#include <memory>
#include <set>
#include <sstream>
#include <tuple>

#include "rigcal/calib/calibration_deskew.hpp"
#include "rigcal/calib/calibration_scheduler.hpp"
#include "rigcal/calib/calibration_source.hpp"
#include "rigcal/calib/ensemble_plan.hpp"

namespace rigcal::calib {
namespace {

using Clock = std::chrono::steady_clock;
using registration::Deadline;
using registration::PointCloud;
using registration::SourceTarget;
using registration::Target;

/// Under a short deadline the first target may use at most this share of the time left.
constexpr double kFirstTargetShare = 0.25;

double since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

bool finitePose(const Pose& T) { return T.matrix().allFinite(); }

/// Two starts closer than this give the same registration result: run it once.
bool samePose(const Pose& a, const Pose& b) {
  return (a.translation() - b.translation()).norm() < 1e-4 && rotationAngleBetween(a, b) < deg2rad(0.005);
}

struct Frame {
  std::size_t index = 0;  // in the dataset
  PointCloud source;
  PointCloud score_source;  // every stride-th point: what the all-frames score looks at
  std::shared_ptr<const Target> target;
};

class Calibrator {
 public:
  Calibrator(const pipeline::CalibrationDataset& dataset, const config::Parameters& params, const Deadline& deadline,
             const LidarLidarOptions& options, LidarLidarResult& out)
      : data_(dataset), params_(params), deadline_(deadline), opt_(options), out_(out) {}

  void run() {
    const auto t0 = Clock::now();
    out_.candidates = {data_.T_mapping_calib_guess};
    best_ = data_.T_mapping_calib_guess;
    // The most informative frame first, alone: its ensemble gives the big correction early.
    std::size_t next = 0;
    while (frames_.empty() && next < data_.frames.size() && !stopped()) buildFrame(next++);
    double target_seconds = since(t0);
    if (frames_.empty()) {
      out_.failure = out_.deadline_reached ? "deadline reached before any calibration frame's target was built"
                                           : "no calibration frame has a usable source and target";
      out_.stage_seconds.emplace_back("targets", target_seconds);
      return;
    }
    rescore();
    out_.initial_score = initial_score_;
    double ensemble_seconds = 0.0, batched_seconds = 0.0;
    auto t = Clock::now();
    frameEnsemble(0, /*exhaustive=*/false);
    ensemble_seconds += since(t);
    // Then every other frame, scored together from now on.
    t = Clock::now();
    const std::size_t first_frames = frames_.size();
    while (next < data_.frames.size() && !stopped()) {
      // A frame's whole preparation (crop, voxels, target) as long as the last one's, or it waits.
      if (!fits(deadline_, 1.2 * last_build_seconds_)) {
        out_.deadline_reached = true;
        break;
      }
      buildFrame(next++);
    }
    target_seconds += since(t);
    // Rescoring the guess and the best over the grown set costs two scores of the new size.
    const double grown = double(frames_.size()) / double(first_frames);
    if (frames_.size() > first_frames && fits(deadline_, 2.5 * grown * score_seconds_)) rescore();
    else if (frames_.size() > first_frames) {
      // No time to score the grown set: keep the frames the scores were computed on.
      frames_.resize(first_frames);
      out_.frames_used.resize(first_frames);
      out_.deadline_reached = true;
    }
    t = Clock::now();
    if (!stopped()) batchedChain(best_);
    batched_seconds += since(t);
    t = Clock::now();
    for (std::size_t k = 1; k < frames_.size() && !stopped(); ++k) frameEnsemble(k, false);
    ensemble_seconds += since(t);
    t = Clock::now();
    if (!stopped()) finalStep();
    const double final_seconds = since(t);
    // Whatever time is left: upstream's exhaustive ensemble (every registrator from every candidate),
    // which guards against a wrong basin; a better result gets the final batched refinement too.
    t = Clock::now();
    const Pose before_exhaustive = best_;
    for (std::size_t k = 0; k < frames_.size() && opt_.exhaustive && !stopped(); ++k) frameEnsemble(k, true);
    if (!samePose(before_exhaustive, best_) && !stopped()) batchedChain(best_);
    ensemble_seconds += since(t);
    out_.stage_seconds = {{"targets", target_seconds},
                          {"ensemble", ensemble_seconds},
                          {"batched", batched_seconds},
                          {"redeskew_final", final_seconds}};

    out_.T_mapping_calib = best_;
    out_.final_score = best_score_;
    if (!finitePose(best_)) {  // cannot happen (registrations never return NaN) but never hand one out
      out_.T_mapping_calib = data_.T_mapping_calib_guess;
      out_.final_score = out_.initial_score;
    }
    out_.ok = out_.final_score.betterThan(out_.initial_score);
    if (!out_.ok) {
      std::ostringstream msg;
      msg << "no registration beat the initial guess's score (" << out_.initial_score.value << " m², inliers "
          << out_.initial_score.inlier_ratio << ")" << (out_.deadline_reached ? " before the deadline" : "");
      out_.failure = msg.str();
    }
  }

 private:
  bool stopped() {
    if (deadline_.expired()) out_.deadline_reached = true;
    return out_.deadline_reached;
  }

  /// Source and augmented target of dataset frame i; a frame without enough points is skipped (noted).
  void buildFrame(std::size_t i) {
    const auto& df = data_.frames[i];
    std::ostringstream skip;
    skip << "frame " << i << ": ";
    const auto tb = Clock::now();
    Frame f;
    f.index = i;
    SourceOptions so;
    so.num_threads = opt_.num_threads;
    f.source = buildSource(*df.deskewed, params_, so);
    if (f.source.size() < std::size_t(std::max(params_.min_calibration_pointcloud_size, 10))) {
      skip << f.source.size() << " source points within the calibration range (min_calibration_pointcloud_size "
           << params_.min_calibration_pointcloud_size << ")";
      out_.frames_skipped.push_back(skip.str());
      return;
    }
    AugmentedTargetOptions to = opt_.target;
    to.num_threads = opt_.num_threads;
    std::size_t clouds = 0, cropped = 0;
    auto cloud = augmentedCloud(data_, i, f.source, params_, to, &clouds, &cropped);
    // The first frame must leave time to register: under a short deadline its target is built from
    // fewer mapping clouds (the keyframe's own always among them) rather than not at all.
    const double allowed = kFirstTargetShare * secondsLeft(deadline_);
    if (frames_.empty() && clouds > 1 && seconds_per_point_ * double(cloud.size()) > allowed) {
      const double points_per_cloud = double(cloud.size()) / double(clouds);
      to.max_clouds = std::max<std::size_t>(1, std::size_t(allowed / (seconds_per_point_ * points_per_cloud)));
      cloud = augmentedCloud(data_, i, f.source, params_, to, &clouds, &cropped);
    }
    // Do not start a build that the deadline would cut (a Target cannot be interrupted).
    if (!fits(deadline_, seconds_per_point_ * double(cloud.size()))) {
      out_.deadline_reached = true;
      return;
    }
    if (cloud.size() < 100) {
      skip << "augmented target has " << cloud.size() << " points from " << clouds << " mapping clouds";
      out_.frames_skipped.push_back(skip.str());
      return;
    }
    const double n = double(cloud.size());
    registration::TargetOptions topt;
    topt.normals_and_covariances = true;
    topt.ndt_resolutions = {to.ndt_resolution};
    topt.num_threads = opt_.num_threads;
    f.target = std::make_shared<const Target>(std::move(cloud), topt);
    seconds_per_point_ = since(tb) / n;
    last_build_seconds_ = since(tb);
    out_.frames_used.push_back(i);
    frames_.push_back(std::move(f));
  }

  /// The initial guess's and the best's scores over the frames built so far (the set just grew).
  void rescore() {
    rebuildScorePairs();
    const auto ts = Clock::now();
    initial_score_ = score(data_.T_mapping_calib_guess);
    score_seconds_ = since(ts);
    best_score_ = samePose(best_, data_.T_mapping_calib_guess) ? initial_score_ : score(best_);
    if (!best_score_.betterThan(initial_score_)) {
      best_ = data_.T_mapping_calib_guess;
      best_score_ = initial_score_;
    }
    out_.initial_score = initial_score_;
  }

  void rebuildScorePairs() {
    std::vector<SourceTarget> full;
    for (auto& f : frames_) full.push_back({&f.source, f.target.get()});
    const std::size_t stride = scoreStride(full, opt_.score_points);
    score_pairs_.clear();
    for (auto& f : frames_) {
      f.score_source.points.clear();
      for (std::size_t i = 0; i < f.source.size(); i += stride) f.score_source.points.push_back(f.source.points[i]);
      score_pairs_.push_back({&f.score_source, f.target.get()});
    }
  }

  CalibrationScore score(const Pose& T) {
    return scoreAllFrames(score_pairs_, T, params_.calibration_eval_max_corr_distance, 1, opt_.num_threads);
  }

  /// A registration stops early enough that its result can still be scored before the real deadline.
  [[nodiscard]] Deadline registrationDeadline() const {
    if (deadline_.when() == Deadline::Clock::time_point::max()) return deadline_;
    const auto reserve = std::chrono::duration_cast<Deadline::Clock::duration>(
        std::chrono::duration<double>(2.5 * score_seconds_ + 0.01));
    return Deadline::at(deadline_.when() - reserve, deadline_.token());
  }

  /// Scores a candidate over all frames and keeps it when it is the best so far; false when out of time.
  bool consider(const Pose& T, RegistratorRun* run) {
    if (!finitePose(T) || !fits(deadline_, score_seconds_)) return false;
    const CalibrationScore s = score(T);
    if (run != nullptr) run->score = s.value;
    if (s.betterThan(best_score_)) {
      best_score_ = s;
      best_ = T;
    }
    return true;
  }

  std::size_t addCandidate(const Pose& T) {
    for (std::size_t c = 0; c < out_.candidates.size(); ++c)
      if (samePose(out_.candidates[c], T)) return c;
    out_.candidates.push_back(T);
    return out_.candidates.size() - 1;
  }

  /// Upstream's per-frame ensemble: each registrator in turn, its best result becoming a candidate.
  /// Quick pass (exhaustive = false): each registrator from the frame's best candidate so far — the
  /// chain NDT → GICP → ICP coarse → fine → ultra-fine that brings the largest improvement per second.
  /// Exhaustive pass: each registrator from every candidate so far not yet tried with it on this frame.
  void frameEnsemble(std::size_t k, bool exhaustive) {
    const Frame& f = frames_[k];
    const double d_eval = params_.calibration_eval_max_corr_distance;
    std::size_t frame_best = addCandidate(best_);
    double frame_best_score = scoreFrame(*f.target, f.source, out_.candidates[frame_best], d_eval, opt_.num_threads).value;
    for (const Registrator r : perFrameRegistrators()) {
      std::vector<std::size_t> starts;
      if (exhaustive) {
        for (std::size_t c = 0; c < out_.candidates.size(); ++c) starts.push_back(c);
      } else {
        starts.push_back(frame_best);
      }
      std::size_t reg_best = SIZE_MAX;
      double reg_best_score = INFINITY;
      for (const std::size_t start : starts) {
        if (!tried_.insert({f.index, int(r), start}).second) continue;  // this run was done already
        if (stopped()) return;
        RegistratorRun run;
        run.frame = int(f.index);
        run.registrator = toString(r);
        run.start = start;
        const auto tr = Clock::now();
        const auto res = runRegistrator(r, *f.target, f.source, out_.candidates[start], params_, opt_.num_threads,
                                        registrationDeadline());
        run.seconds = since(tr);
        run.iterations = res.iterations;
        run.status = std::string(registration::toString(res.status));
        if (res.status != registration::Status::kInvalidInput &&
            res.status != registration::Status::kTooFewCorrespondences && finitePose(res.T_target_source) &&
            fits(deadline_, score_seconds_ / 2)) {
          run.frame_score = scoreFrame(*f.target, f.source, res.T_target_source, d_eval, opt_.num_threads).value;
          const std::size_t id = addCandidate(res.T_target_source);
          if (run.frame_score < reg_best_score) {
            reg_best_score = run.frame_score;
            reg_best = id;
          }
        }
        out_.runs.push_back(run);
      }
      if (reg_best != SIZE_MAX && reg_best_score < frame_best_score) {
        frame_best_score = reg_best_score;
        frame_best = reg_best;
        // A better frame result competes at once on its score over all frames (recorded on its run),
        // so a deadline in the next registrator does not lose it.
        RegistratorRun* winner = nullptr;
        for (auto it = out_.runs.rbegin(); it != out_.runs.rend() && it->frame == int(f.index); ++it)
          if (it->frame_score == frame_best_score) winner = &*it;
        if (!samePose(out_.candidates[frame_best], best_)) consider(out_.candidates[frame_best], winner);
      }
    }
  }

  /// Batched ICP over all frames at 0.5 → 0.1 → 0.05 m from `start`.
  void batchedChain(const Pose& start) {
    std::vector<SourceTarget> pairs;
    for (auto& f : frames_) pairs.push_back({&f.source, f.target.get()});
    Pose T = start;
    for (const double d : batchedDistances(params_)) {
      if (stopped()) return;
      RegistratorRun run;
      run.registrator = "batched_icp";
      run.max_distance = d;
      run.start = addCandidate(T);
      const auto tr = Clock::now();
      const auto res = runBatched(pairs, T, d, params_, opt_.num_threads, registrationDeadline());
      run.seconds = since(tr);
      run.iterations = res.iterations;
      run.status = std::string(registration::toString(res.status));
      if (res.status == registration::Status::kInvalidInput || res.status == registration::Status::kTooFewCorrespondences ||
          !finitePose(res.T_target_source)) {
        out_.runs.push_back(run);
        return;
      }
      T = res.T_target_source;
      addCandidate(T);
      consider(T, &run);
      out_.runs.push_back(run);
    }
  }

  /// Re-deskews every frame with the best extrinsic, then batched ICP from {initial, best}.
  void finalStep() {
    if (opt_.redeskew && !samePose(best_, data_.T_mapping_calib_guess) && data_.trajectory.size() >= 2) {
      std::vector<PointCloud> sources;
      for (const auto& f : frames_) {
        if (stopped()) return;
        const Scan deskewed = deskewThroughMapping(*data_.frames[f.index].raw, data_.trajectory, best_);
        SourceOptions so;
        so.covariances = false;
        sources.push_back(buildSource(deskewed, params_, so));
      }
      for (std::size_t k = 0; k < frames_.size(); ++k) frames_[k].source = std::move(sources[k]);
      rebuildScorePairs();
      // Scores under the new sources are not comparable with the old ones: rescore the best.
      if (!fits(deadline_, score_seconds_)) {
        out_.deadline_reached = true;
        return;
      }
      best_score_ = score(best_);
    }
    const Pose best_before = best_;
    batchedChain(data_.T_mapping_calib_guess);
    batchedChain(best_before);
  }

  const pipeline::CalibrationDataset& data_;
  const config::Parameters& params_;
  const Deadline& deadline_;
  const LidarLidarOptions& opt_;
  LidarLidarResult& out_;
  std::vector<Frame> frames_;
  std::vector<SourceTarget> score_pairs_;
  double score_seconds_ = 0.0;
  // Target build cost per point; until measured, a pessimistic guess (measured 2–7 µs on a loaded 2-core box).
  double seconds_per_point_ = 6e-6;
  double last_build_seconds_ = 0.0;
  CalibrationScore initial_score_;
  std::set<std::tuple<std::size_t, int, std::size_t>> tried_;  // (frame, registrator, start) runs done
  Pose best_ = Pose::Identity();
  CalibrationScore best_score_;
};

}  // namespace

std::string validateDataset(const pipeline::CalibrationDataset& d, const config::Parameters& params) {
  std::ostringstream msg;
  const std::string who = d.calibration_sensor.empty() ? std::string("<unnamed>") : d.calibration_sensor;
  if (d.calibration_sensor.empty()) return "calibration dataset: calibration_sensor is empty";
  if (!finitePose(d.T_mapping_calib_guess)) return who + ": T_mapping_calib_guess is not finite";
  if (d.frames.empty()) return who + ": no selected calibration frames";
  if (int(d.frames.size()) < params.lidar_calibration_min_frames) {
    msg << who << ": " << d.frames.size() << " of " << params.lidar_calibration_min_frames
        << " frames needed (lidar_calibration_min_frames)";
    return msg.str();
  }
  if (d.trajectory.size() < 2) return who + ": the mapping trajectory has fewer than two poses";
  for (std::size_t i = 1; i < d.trajectory.size(); ++i)
    if (d.trajectory[i].stamp_ns <= d.trajectory[i - 1].stamp_ns) {
      msg << who << ": mapping trajectory stamps not increasing at index " << i;
      return msg.str();
    }
  if (d.mapping_clouds.empty()) return who + ": no mapping clouds around the selected keyframes";
  for (std::size_t i = 0; i < d.mapping_clouds.size(); ++i)
    if (d.mapping_clouds[i].cloud == nullptr || !finitePose(d.mapping_clouds[i].frame.T_map_lidar)) {
      msg << who << ": mapping_clouds[" << i << "] has no cloud or a non-finite pose";
      return msg.str();
    }
  for (std::size_t i = 0; i < d.frames.size(); ++i) {
    const auto& f = d.frames[i];
    if (f.raw == nullptr || f.deskewed == nullptr) {
      msg << who << ": frames[" << i << "] has no " << (f.raw == nullptr ? "raw" : "deskewed") << " scan";
      return msg.str();
    }
    if (!finitePose(f.pairing.T_map_mapping_at_scan)) {
      msg << who << ": frames[" << i << "].pairing.T_map_mapping_at_scan is not finite";
      return msg.str();
    }
    if (f.pairing.keyframe_frame >= d.trajectory.size() || d.trajectory[f.pairing.keyframe_frame].keyframe_index < 0) {
      msg << who << ": frames[" << i << "].pairing.keyframe_frame " << f.pairing.keyframe_frame
          << " is not a keyframe of the trajectory";
      return msg.str();
    }
  }
  return {};
}

LidarLidarResult calibrateLidarLidar(const pipeline::CalibrationDataset& dataset, const config::Parameters& params,
                                     const registration::Deadline& deadline, const LidarLidarOptions& options) {
  const auto t0 = Clock::now();
  LidarLidarResult out;
  out.mapping_sensor = dataset.mapping_sensor;
  out.calibration_sensor = dataset.calibration_sensor;
  out.T_mapping_calib_guess = dataset.T_mapping_calib_guess;
  out.T_mapping_calib = finitePose(dataset.T_mapping_calib_guess) ? dataset.T_mapping_calib_guess : Pose::Identity();
  out.failure = validateDataset(dataset, params);
  if (out.failure.empty()) {
    try {
      Calibrator(dataset, params, deadline, options, out).run();
    } catch (const std::exception& e) {  // a bad dataset the validation did not foresee: a clear failure
      out.ok = false;
      out.T_mapping_calib = dataset.T_mapping_calib_guess;  // validated finite
      out.failure = dataset.calibration_sensor + ": " + e.what();
    }
  }
  out.seconds = since(t0);
  return out;
}

std::vector<LidarLidarResult> calibrateLidarsLidar(const std::vector<pipeline::CalibrationDataset>& datasets,
                                                   const config::Parameters& params,
                                                   const registration::CancelToken* cancel,
                                                   const LidarLidarOptions& options) {
  CalibrationBudget budget(Clock::now(), params.calibration_deadline_s, datasets.size(), cancel);
  std::vector<LidarLidarResult> results;
  for (const auto& d : datasets) results.push_back(calibrateLidarLidar(d, params, budget.next(), options));
  return results;
}

}  // namespace rigcal::calib
