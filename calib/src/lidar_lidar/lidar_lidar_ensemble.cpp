// The registrations: upstream's per-frame ensemble (NDT, GICP, ICP coarse/fine/ultra-fine), the batched ICP
// over all frames and the final step after re-deskewing with the best extrinsic.
#include "lidar_lidar_calibrator.hpp"

#include <cmath>
#include <cstdint>

#include "rigcal/calib/lidar_lidar/calibration_deskew.hpp"
#include "rigcal/calib/lidar_lidar/calibration_budget.hpp"
#include "rigcal/calib/lidar_lidar/calibration_source.hpp"
#include "rigcal/calib/lidar_lidar/ensemble_plan.hpp"
#include "rigcal/registration/covariance.hpp"

namespace rigcal::calib::detail {

void Calibrator::frameEnsemble(std::size_t k, bool exhaustive) {
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
      if (!tried_.insert({f.index, int(r), start, redeskewed_}).second) continue;  // this run was done already
      if (stopped()) return;
      if (r == Registrator::kGicp && !ensureSourceCovariances(k)) continue;  // the ICPs may still fit
      RegistratorRun run;
      run.frame = int(f.index);
      run.registrator = toString(r);
      run.start = start;
      run.redeskewed = redeskewed_;
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
        run.result = id;
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

bool Calibrator::ensureSourceCovariances(std::size_t k) {
  PointCloud& source = frames_[k].source;
  if (source.hasCovariances() || source.size() < 3) return true;
  // Its temporary kd-tree cannot be cut: start only when the estimate (a target's cost per point, which
  // also covers a tree and covariances) fits.
  if (!fits(deadline_, seconds_per_point_ * double(source.size()))) return false;
  registration::CovarianceOptions cov;
  cov.num_threads = opt_.num_threads;
  cov.deadline = deadline_;
  registration::estimateCovariances(source, cov);
  if (!stopped()) return true;
  source.clearAttributes();  // cut short: incomplete, never used
  return false;
}

void Calibrator::confirmOnFrame(std::size_t k) {
  const Frame& f = frames_[k];
  const Registrator r = Registrator::kIcpFine;
  RegistratorRun run;
  run.frame = int(f.index);
  run.registrator = toString(r);
  run.start = addCandidate(best_);
  run.redeskewed = redeskewed_;
  if (!tried_.insert({f.index, int(r), run.start, redeskewed_}).second) return;
  const auto tr = Clock::now();
  const auto res = runRegistrator(r, *f.target, f.source, best_, params_, opt_.num_threads, registrationDeadline());
  run.seconds = since(tr);
  run.iterations = res.iterations;
  run.status = std::string(registration::toString(res.status));
  if (res.status != registration::Status::kInvalidInput && res.status != registration::Status::kTooFewCorrespondences &&
      finitePose(res.T_target_source) && fits(deadline_, score_seconds_ / 2)) {
    run.frame_score = scoreFrame(*f.target, f.source, res.T_target_source, params_.calibration_eval_max_corr_distance,
                                 opt_.num_threads)
                          .value;
    run.result = addCandidate(res.T_target_source);
  }
  out_.runs.push_back(run);
}

void Calibrator::batchedChain(const Pose& start) {
  std::vector<SourceTarget> pairs;
  for (auto& f : frames_)
    if (!f.set_aside) pairs.push_back({&f.source, f.target.get()});
  Pose T = start;
  for (const double d : batchedDistances(params_)) {
    if (stopped()) return;
    RegistratorRun run;
    run.registrator = "batched_icp";
    run.max_distance = d;
    run.start = addCandidate(T);
    run.redeskewed = redeskewed_;
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
    run.result = addCandidate(T);
    consider(T, &run);
    out_.runs.push_back(run);
  }
}

bool Calibrator::finalStep() {
  if (opt_.redeskew && !samePose(best_, data_.T_mapping_calib_guess) && data_.trajectory.size() >= 2) {
    std::vector<PointCloud> sources;
    for (const auto& f : frames_) {
      if (stopped()) return false;
      const Scan deskewed = deskewThroughMapping(*data_.frames[f.index].raw, data_.trajectory, best_);
      SourceOptions so;
      so.covariances = false;
      sources.push_back(buildSource(deskewed, params_, so));
    }
    for (std::size_t k = 0; k < frames_.size(); ++k) frames_[k].source = std::move(sources[k]);
    redeskewed_ = true;
    rebuildScorePairs();
    // Scores under the new sources are not comparable with the old ones: rescore the best.
    if (!fits(deadline_, score_seconds_)) return false;
    best_score_ = score(best_);
  }
  batchedChain(best_);
  // Each frame's own view of the result on the sources it was refined on. The first ensemble ran on scans
  // deskewed with the guess: in a turn (10 deg/s, a 0.1 s sweep) a guess 5 deg / 0.3 m off bends a scan
  // by ~0.1 deg / 0.5 cm, and the rear lidar's frames in the two turns of yard-corners put it 0.1 deg either
  // side of a result 0.005 deg from the truth, which the verdict then could not call ok.
  if (redeskewed_)
    for (std::size_t k = 0; k < frames_.size() && !stopped(); ++k) confirmOnFrame(k);
  return !stopped();
}

}  // namespace rigcal::calib::detail
