// The run: the most informative frame first, then the others' targets, the batched ICP, the re-deskew,
// the other frames' ensembles; the searches for another basin in the time the caller gives them; the
// all-frames scores that pick the best candidate.
#include "lidar_lidar_calibrator.hpp"

#include <sstream>

#include "rigcal/calib/lidar_lidar/calibration_budget.hpp"
#include "rigcal/calib/lidar_lidar/ensemble_plan.hpp"
#include "rigcal/calib/lidar_lidar/lidar_lidar_verdict.hpp"

namespace rigcal::calib::detail {

Calibrator::Calibrator(const pipeline::CalibrationDataset& dataset, const config::Parameters& params,
                       const Deadline& share, const LidarLidarOptions& options, LidarLidarResult& out,
                       TargetsDone targets_done)
    : data_(dataset), params_(params), share_(share), deadline_(share), opt_(options), out_(out),
      targets_done_(std::move(targets_done)) {
  reserveClockEstimate();
}

bool Calibrator::run() {
  out_.candidates = {data_.T_mapping_calib_guess};
  best_ = data_.T_mapping_calib_guess;
  std::size_t next = 0;  // the next dataset frame to build
  if (!firstFrame(next)) return false;
  const std::size_t first_frames = frames_.size();
  const bool targets_cut = laterTargets(next, first_frames);
  const bool finished = restOfPlan(first_frames);
  // A run cancelled from outside (the user stopping it) is cut wherever it was.
  const bool cancelled = deadline_.token() != nullptr && deadline_.token()->cancelled();
  out_.deadline_reached = targets_cut || !finished || cancelled;
  publish();
  return !out_.deadline_reached;
}

bool Calibrator::searchForAnotherBasin(const Deadline& until) {
  // Upstream's batched chain from the initial guess (on the street's VLS-128 map it ran its 200 iterations
  // at 0.5 m without converging: 0.6 s of a 3.3 s share), then its exhaustive ensemble (every registrator
  // from every candidate); a better result gets the final batched refinement too.
  deadline_ = until.when() < share_.when() ? until : share_;
  const auto t = Clock::now();
  const Pose before_search = best_;
  if (!stopped()) batchedChain(data_.T_mapping_calib_guess);
  for (std::size_t k = 0; k < frames_.size() && opt_.exhaustive && !stopped(); ++k) frameEnsemble(k, true);
  if (!samePose(before_search, best_) && !stopped()) batchedChain(best_);
  seconds_.ensemble += since(t);
  if (deadline_.token() != nullptr && deadline_.token()->cancelled()) out_.deadline_reached = true;
  publish();
  return !samePose(before_search, best_);
}

void Calibrator::publish() {
  out_.stage_seconds = {{"targets", seconds_.targets},
                        {"ensemble", seconds_.ensemble},
                        {"batched", seconds_.batched},
                        {"redeskew_final", seconds_.redeskew_final}};
  out_.T_mapping_calib = best_;
  out_.final_score = best_score_;
  if (!finitePose(best_)) {  // cannot happen (registrations never return NaN) but never hand one out
    out_.T_mapping_calib = data_.T_mapping_calib_guess;
    out_.final_score = out_.initial_score;
  }
  out_.ok = out_.final_score.betterThan(out_.initial_score);
  out_.failure.clear();
  if (!out_.ok) {
    std::ostringstream msg;
    msg << "no registration beat the initial guess's score (" << out_.initial_score.value << " m², inliers "
        << out_.initial_score.inlier_ratio << ")" << (out_.deadline_reached ? " before the deadline" : "");
    out_.failure = msg.str();
  }
}

void Calibrator::reserveClockEstimate() {
  if (!opt_.trajectory_clock) return;
  double expected = opt_.trajectory_clock_share * std::max(0.0, secondsLeft(share_));  // until a score is timed
  if (score_points_ > 0) {
    const auto& c = opt_.trajectory_clock_options;
    // Its trials (and the vertex's, and one step outwards), each iterations + 1 passes over max_points.
    const double passes = double(c.shifts_ms.size() + 2) * double(c.iterations + 1);
    // A pass point cost 0.7-1.3 score points on the street (3 lidars, 2 threads); three leave room for a
    // machine that gets busier after the score was timed.
    constexpr double kPassPointInScorePoints = 3.0;
    expected = kPassPointInScorePoints * passes * double(c.max_points) * score_seconds_ / double(score_points_);
  }
  deadline_ = earlierBy(share_, std::min(opt_.trajectory_clock_max_s, expected));
}

bool Calibrator::firstFrame(std::size_t& next) {
  // The most informative frame first, alone: its ensemble gives the big correction early.
  auto t = Clock::now();
  bool out_of_time = false;
  while (frames_.empty() && next < data_.frames.size() && !out_of_time)
    out_of_time = stopped() || buildFrame(next++) == FrameBuild::kOutOfTime;
  seconds_.targets += since(t);
  if (frames_.empty()) {
    out_.deadline_reached = out_of_time;
    out_.failure = out_of_time ? "deadline reached before any calibration frame's target was built"
                               : "no calibration frame has a usable source and target";
    out_.stage_seconds.emplace_back("targets", seconds_.targets);
    return false;
  }
  rescore();
  t = Clock::now();
  frameEnsemble(0, /*exhaustive=*/false);
  seconds_.ensemble += since(t);
  return true;
}

bool Calibrator::laterTargets(std::size_t& next, std::size_t first_frames) {
  // Every other frame, scored together from now on.
  auto t = Clock::now();
  bool targets_cut = false;
  while (next < data_.frames.size() && !targets_cut) {
    // After a frame's target, time for what makes one estimate of the frames: the grown set's rescore (else
    // the new frames are dropped) and the batched chain. Without that reserve a loaded machine spent the
    // whole share on targets and never ran the batched ICP (parking lot at load 7: front_right 1.0-1.3 cm
    // off). The source and crop must fit as long as the last ones took; whether the target build fits is
    // judged on the cropped cloud (buildFrame).
    const double grown_next = double(frames_.size() + 1) / double(first_frames);
    const double reserve = 2.5 * grown_next * score_seconds_ + batchedChainEstimate(frames_.size() + 1);
    const std::size_t built = frames_.size();
    targets_cut = !fits(deadline_, 1.2 * last_prepare_seconds_ + reserve) ||
                  buildFrame(next++, reserve) == FrameBuild::kOutOfTime;
    if (targets_cut) break;
    seconds_.targets += since(t);
    // Its own view of the best at once (one ICP), before the next target: if the deadline cuts the
    // targets, the frames built so far still count as evidence for the verdict (lidar_lidar_verdict.hpp).
    t = Clock::now();
    if (frames_.size() > built && !stopped()) confirmOnFrame(frames_.size() - 1);
    seconds_.ensemble += since(t);
    t = Clock::now();
  }
  prefetch_.abandon();  // a frame prepared ahead that will not be built
  seconds_.targets += since(t);
  return targets_cut;
}

bool Calibrator::restOfPlan(std::size_t first_frames) {
  // A next target that did not fit ends the targets, not the plan: the frames built so far still get the
  // rescore, the batched chain and their ensembles in the time left (it had skipped all of them: under load
  // the batched ICP never ran).
  // Rescoring the guess and the best over the grown set costs two scores of the new size.
  const double grown = double(frames_.size()) / double(first_frames);
  if (frames_.size() > first_frames && !fits(deadline_, 2.5 * grown * score_seconds_)) {
    // No time to score the grown set: keep the frames the scores were computed on.
    frames_.resize(first_frames);
    out_.frames_used.resize(first_frames);
    return false;
  }
  if (frames_.size() > first_frames) rescore();
  auto t = Clock::now();
  if (!stopped()) batchedChain(best_);
  seconds_.batched += since(t);
  if (stopped()) return false;
  // The re-deskew before the other frames' ensembles: it is worth more, and last in the plan it was what
  // a loaded machine never reached (parking lot at load 8, every frame built: front_right 0.63 cm off
  // without it, 0.01 cm with it on a quiet machine). Those ensembles then run on the re-deskewed sources.
  t = Clock::now();
  const bool redeskewed = finalStep();
  seconds_.redeskew_final = since(t);
  if (!redeskewed) return false;
  t = Clock::now();
  const Pose before_ensembles = best_;
  for (std::size_t k = 1; k < frames_.size() && !stopped(); ++k) frameEnsemble(k, false);
  if (!samePose(before_ensembles, best_) && !stopped()) batchedChain(best_);
  seconds_.ensemble += since(t);
  t = Clock::now();
  if (!stopped() && setAsideDisagreeingFrames()) batchedChain(best_);
  seconds_.batched += since(t);
  // Complete only if the registrations' own deadline has not passed either: the last ones ran into it
  // otherwise (a 1 s plan ended with two ensembles "timeout" 1 ms in, before the real deadline).
  return !registrationDeadline().expired();
}

double Calibrator::batchedChainEstimate(std::size_t frames) const {
  // Its three stages each cost about one ICP over every frame; an ICP fine on one frame is what each
  // frame's confirmation (and the first frame's ensemble) ran.
  double seconds = 0.0;
  std::size_t n = 0;
  for (const auto& run : out_.runs) {
    if (run.registrator != toString(Registrator::kIcpFine)) continue;
    seconds += run.seconds;
    ++n;
  }
  return n == 0 ? 0.0 : 3.0 * seconds / double(n) * double(frames);
}

bool Calibrator::stopped() const { return deadline_.expired(); }

void Calibrator::rescore() {
  rebuildScorePairs();
  const auto ts = Clock::now();
  initial_score_ = score(data_.T_mapping_calib_guess);
  score_seconds_ = since(ts);
  score_points_ = 0;
  for (const auto& pair : score_pairs_) score_points_ += pair.source->size();
  reserveClockEstimate();  // from the score just timed
  best_score_ = samePose(best_, data_.T_mapping_calib_guess) ? initial_score_ : score(best_);
  if (!best_score_.betterThan(initial_score_)) {
    best_ = data_.T_mapping_calib_guess;
    best_score_ = initial_score_;
  }
  out_.initial_score = initial_score_;
}

void Calibrator::rebuildScorePairs() {
  std::vector<SourceTarget> full;
  for (auto& f : frames_)
    if (!f.set_aside) full.push_back({&f.source, f.target.get()});
  const std::size_t stride = scoreStride(full, opt_.score_points);
  score_pairs_.clear();
  for (auto& f : frames_) {
    if (f.set_aside) continue;
    f.score_source.points.clear();
    for (std::size_t i = 0; i < f.source.size(); i += stride) f.score_source.points.push_back(f.source.points[i]);
    score_pairs_.push_back({&f.score_source, f.target.get()});
  }
}

bool Calibrator::setAsideDisagreeingFrames() {
  if (!redeskewed_) return false;
  std::size_t aside = 0;
  for (auto& f : frames_) {
    const RegistratorRun* own = nullptr;  // the frame's best run on its re-deskewed source
    for (const auto& run : out_.runs)
      if (run.frame == int(f.index) && run.redeskewed && run.frame_score >= 0 && run.result < out_.candidates.size() &&
          (own == nullptr || run.frame_score < own->frame_score))
        own = &run;
    f.set_aside = own != nullptr && !agrees(out_.candidates[own->result], best_);
    if (f.set_aside) ++aside;
  }
  const std::size_t agreeing = frames_.size() - aside;
  // Two scores over the frames kept (the guess's and the best's), which the comparisons from here on need.
  if (aside == 0 || agreeing < 2 || aside >= agreeing || !fits(deadline_, 2.0 * score_seconds_)) {
    for (auto& f : frames_) f.set_aside = false;
    return false;
  }
  rebuildScorePairs();
  initial_score_ = score(data_.T_mapping_calib_guess);
  out_.initial_score = initial_score_;
  best_score_ = score(best_);
  for (const auto& f : frames_)
    if (f.set_aside) out_.frames_set_aside.push_back(f.index);
  return true;
}

CalibrationScore Calibrator::score(const Pose& T) {
  return scoreAllFrames(score_pairs_, T, params_.calibration_eval_max_corr_distance, 1, opt_.num_threads);
}

Deadline Calibrator::registrationDeadline() const { return earlierBy(deadline_, 2.5 * score_seconds_ + 0.01); }

bool Calibrator::consider(const Pose& T, RegistratorRun* run) {
  if (!finitePose(T) || !fits(deadline_, score_seconds_)) return false;
  const CalibrationScore s = score(T);
  if (run != nullptr) run->score = s.value;
  if (s.betterThan(best_score_)) {
    best_score_ = s;
    best_ = T;
  }
  return true;
}

std::size_t Calibrator::addCandidate(const Pose& T) {
  for (std::size_t c = 0; c < out_.candidates.size(); ++c)
    if (samePose(out_.candidates[c], T)) return c;
  out_.candidates.push_back(T);
  return out_.candidates.size() - 1;
}

}  // namespace rigcal::calib::detail
