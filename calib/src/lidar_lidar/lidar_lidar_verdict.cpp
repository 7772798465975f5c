#include "rigcal/calib/lidar_lidar/lidar_lidar_verdict.hpp"

#include <algorithm>
#include <Eigen/Eigenvalues>

#include <cmath>
#include <iomanip>
#include <map>
#include <set>
#include <sstream>

namespace rigcal::calib {
namespace {

struct Distance {
  double m = 0.0, deg = 0.0;
};

Distance distance(const Pose& a, const Pose& b) {
  return {(a.translation() - b.translation()).norm(), rad2deg(rotationAngleBetween(a, b))};
}

bool near(const Distance& d, const VerdictOptions& opt) { return d.m <= opt.agree_m && d.deg <= opt.agree_deg; }

using Vector6d = Eigen::Matrix<double, 6, 1>;

/// `frame` as a small change of `result`: frame = result · exp([δt, δr]) (the calibration lidar's own frame).
Vector6d deviation(const Pose& result, const Pose& frame) {
  const Pose D = result.inverse() * frame;
  const Eigen::AngleAxisd aa(D.rotation());
  Vector6d d;
  d << D.translation(), aa.angle() * aa.axis();
  return d;
}

/// What one agreeing frame says about the result, and how well.
struct FrameEvidence {
  Vector6d deviation = Vector6d::Zero();                  // the mean of its tied runs, deviation(result, ·)
  PoseInformation information = PoseInformation::Zero();  // result.frame_information
  double score = 0.0;                                     // its best frame score (m²)
  PoseInformation ambiguity = PoseInformation::Zero();    // the spread of its tied runs about their mean
};

/// Frame evidence from its runs (those the verdict judges it by) whose scores are at most `tie` (m²): answers the
/// frame cannot tell apart. Where its cost is flat they spread, and the best of them is chance: yard-side's rolled
/// lidars had frames whose runs lay 1.7-6.8 cm apart along the spin axis at scores 0.5 % apart, and the best
/// (or a frame's hundreds of runs in the exhaustive search) chose among them. So the frame says their mean, as
/// far as their spread.
FrameEvidence frameEvidence(const LidarLidarResult& r, const std::vector<const RegistratorRun*>& runs, double tie,
                            const PoseInformation& information) {
  std::vector<Vector6d> tied;
  FrameEvidence f;
  f.information = information;
  f.score = tie;
  for (const auto* run : runs) {
    if (run->frame_score > tie) continue;
    tied.push_back(deviation(r.T_mapping_calib, r.candidates[run->result]));
    f.deviation += tied.back();
    f.score = std::min(f.score, run->frame_score);
  }
  f.deviation /= double(tied.size());
  for (const auto& d : tied) f.ambiguity += (d - f.deviation) * (d - f.deviation).transpose();
  f.ambiguity /= double(tied.size());
  return f;
}

/// The weight of a frame's deviation: the inverse of its covariance, which is what its points' noise leaves
/// (score · H⁻¹; the score counts outliers at d_max², so an upper bound) plus what its own registrators leave
/// open (`ambiguity`). Zero when the frame has no information.
PoseInformation frameWeight(const FrameEvidence& f) {
  const Eigen::SelfAdjointEigenSolver<PoseInformation> es(f.information);
  const double largest = es.eigenvalues()(5);
  if (!(largest > 0.0)) return PoseInformation::Zero();
  const Vector6d noise = std::max(f.score, 1e-12) * es.eigenvalues().cwiseMax(1e-12 * largest).cwiseInverse();
  const PoseInformation C = es.eigenvectors() * noise.asDiagonal() * es.eigenvectors().transpose() + f.ambiguity;
  return C.ldlt().solve(PoseInformation::Identity());
}

/// Two standard errors (m, deg) of the result from its frames' deviations d_k and weights W_k. Refined
/// over all frames, the result is to first order their weighted mean, A⁻¹ Σ W_k x_k with A = Σ W_k, so its
/// covariance from their scatter is A⁻¹ (Σ W_k d_k d_kᵀ W_k) A⁻¹: a frame's deviation along a direction it
/// hardly sees, or cannot tell apart, counts as little as it pulls the result there. With equal W_k it is
/// Σ d_k d_kᵀ / n², the frames' plain standard error. {-1, -1} when A is singular.
Distance weightedUncertainty(const std::vector<FrameEvidence>& frames) {
  PoseInformation A = PoseInformation::Zero(), B = PoseInformation::Zero();
  for (const auto& f : frames) {
    const PoseInformation W = frameWeight(f);
    A += W;
    const Vector6d w = W * f.deviation;
    B += w * w.transpose();
  }
  const Eigen::SelfAdjointEigenSolver<PoseInformation> es(A);
  const auto& ev = es.eigenvalues();
  if (!(ev(0) > 1e-9 * ev(5))) return {-1.0, -1.0};
  const PoseInformation A_inv = es.eigenvectors() * ev.cwiseInverse().asDiagonal() * es.eigenvectors().transpose();
  const PoseInformation C = A_inv * B * A_inv;
  return {2.0 * std::sqrt(std::max(0.0, C.topLeftCorner<3, 3>().trace())),
          2.0 * rad2deg(std::sqrt(std::max(0.0, C.bottomRightCorner<3, 3>().trace())))};
}

/// The calibration_deadline_s that gives every selected frame its ensemble, from the share of frames
/// this one reached: at least twice the deadline it had, rounded up to 10 s.
double suggestDeadline(double deadline_s, std::size_t frames_selected, std::size_t frames_registered) {
  const double ratio = std::max(2.0, double(frames_selected) / double(std::max<std::size_t>(1, frames_registered)));
  return std::ceil(deadline_s * ratio / 10.0) * 10.0;
}

}  // namespace

bool agrees(const Pose& T, const Pose& result, const VerdictOptions& options) {
  return near(distance(T, result), options);
}

const char* toString(Verdict v) {
  switch (v) {
    case Verdict::kOk: return "ok";
    case Verdict::kUnverified: return "unverified";
    case Verdict::kFailed: return "failed";
  }
  return "?";
}

void judgeLidarLidar(LidarLidarResult& r, std::size_t frames_selected, double deadline_s, const VerdictOptions& opt) {
  LidarLidarEvidence& e = r.evidence;
  e = {};
  e.frames_selected = frames_selected;
  e.inlier_ratio = r.final_score.inlier_ratio;
  if (r.initial_score.value > 0) e.improvement = 1.0 - r.final_score.value / r.initial_score.value;
  if (!r.ok) {
    r.verdict = Verdict::kFailed;
    return;
  }
  // Each frame's own best registration (lowest score on that frame): where that frame alone puts the lidar.
  // Once a frame was registered on its source re-deskewed with the best extrinsic, only those runs count:
  // the earlier ones saw the scan bent by the guess's deskew, and their scores are of another cloud.
  std::set<int> redeskewed_frames;
  for (const auto& run : r.runs)
    if (run.redeskewed && run.frame >= 0 && run.frame_score >= 0 && run.result < r.candidates.size())
      redeskewed_frames.insert(run.frame);
  std::map<int, std::vector<const RegistratorRun*>> frame_runs;  // the runs each frame is judged by
  std::set<std::string> agreeing;
  for (const auto& run : r.runs) {
    if (run.result >= r.candidates.size()) continue;
    if (agrees(r.candidates[run.result], r.T_mapping_calib, opt)) agreeing.insert(run.registrator);
    if (run.frame < 0 || run.frame_score < 0) continue;
    if (redeskewed_frames.count(run.frame) != 0 && !run.redeskewed) continue;
    frame_runs[run.frame].push_back(&run);
  }
  std::map<int, const RegistratorRun*> frame_best;
  for (const auto& [frame, runs] : frame_runs)
    frame_best[frame] = *std::min_element(runs.begin(), runs.end(), [](const auto* a, const auto* b) {
      return a->frame_score < b->frame_score;
    });
  e.registrators_agreeing.assign(agreeing.begin(), agreeing.end());
  e.frames_registered = frame_best.size();
  double sum_sq_m = 0.0, sum_sq_deg = 0.0;
  std::vector<FrameEvidence> weighed;
  bool every_frame_weighted = true;
  for (const auto& [frame, run] : frame_best) {
    const Distance d = distance(r.candidates[run->result], r.T_mapping_calib);
    e.frame_spread_m = std::max(e.frame_spread_m, d.m);
    e.frame_spread_deg = std::max(e.frame_spread_deg, d.deg);
    if (!near(d, opt)) continue;  // an outlier frame is judged by the majority rule below, not as scatter
    ++e.frames_agreeing;
    sum_sq_m += d.m * d.m;
    sum_sq_deg += d.deg * d.deg;
    const auto info = r.frame_information.find(frame);
    if (info == r.frame_information.end()) {
      every_frame_weighted = false;
      continue;
    }
    weighed.push_back(frameEvidence(r, frame_runs.at(frame), run->frame_score * (1.0 + opt.equal_score_share),
                                    info->second));
  }
  if (const double n = double(e.frames_agreeing); n >= 2) {
    // rms / sqrt(n) = sqrt(sum / n²): the standard error of the frames' mean about the final result.
    e.frame_uncertainty_m = 2.0 * std::sqrt(sum_sq_m) / n;
    e.frame_uncertainty_deg = 2.0 * std::sqrt(sum_sq_deg) / n;
    if (every_frame_weighted) {
      const Distance w = weightedUncertainty(weighed);
      if (w.m >= 0) {
        e.frame_uncertainty_m = w.m;
        e.frame_uncertainty_deg = w.deg;
        e.frame_uncertainty_weighted = true;
      }
    }
  }

  std::ostringstream why;
  why.setf(std::ios::fixed);
  why.precision(2);
  const auto clause = [&why]() -> std::ostringstream& {
    if (why.tellp() > 0) why << "; ";
    return why;
  };
  const std::size_t disagreeing = e.frames_registered - e.frames_agreeing;
  bool short_of_evidence = false;
  if (e.frames_agreeing < opt.min_frames) {
    clause() << "confirmed by " << e.frames_agreeing << " frame(s) of " << frames_selected << " (needs "
             << opt.min_frames << ")";
    short_of_evidence = true;
  }
  if (disagreeing > e.frames_agreeing)
    clause() << disagreeing << " of " << e.frames_registered << " frames disagree (spread " << 100.0 * e.frame_spread_m
             << " cm, " << e.frame_spread_deg << " deg)";
  if (e.frame_uncertainty_m > opt.goal_m || e.frame_uncertainty_deg > opt.goal_deg) {
    clause() << "its " << e.frames_agreeing << " agreeing frames scatter about it by ± " << 100.0 * e.frame_uncertainty_m
             << " cm, " << std::setprecision(3) << e.frame_uncertainty_deg << std::setprecision(2)
             << " deg (two standard errors; the goal is " << 100.0 * opt.goal_m << " cm, " << opt.goal_deg
             << " deg)";
    // More frames narrow it: the deadline's when it cut the plan short of the selected ones, else the budget's.
    // A plan cut after every frame's first registration still lacked the re-deskewed confirmations (the rear
    // lidar of yard-corners, cut at load 10: ± 0.077 deg from guess-deskewed frames; with them ± 0.005 deg).
    if (e.frames_registered < frames_selected || r.deadline_reached)
      short_of_evidence = true;
    else
      why << "; more frames would narrow it (lidar_calibration_max_frames, a longer drive)";
  }
  if (agreeing.size() < opt.min_registrators) {
    clause() << "reached by " << agreeing.size() << " registrator(s) (needs " << opt.min_registrators << ")";
    short_of_evidence = true;
  }
  if (e.inlier_ratio < opt.min_inlier_ratio) {
    clause() << "inlier ratio " << e.inlier_ratio << " < " << opt.min_inlier_ratio << " (little overlap or a wrong pose)";
    // A plan the deadline cut scores fewer frames, the first against a target thinned to fit: yard-corners'
    // corner lidars beside a busy build had 0.49-0.53 on 2-4 of their 6-7 frames, 0.59-0.62 with every frame.
    // Time is then what would tell; with every frame registered nothing but the rig's overlap or pose would.
    if (r.deadline_reached && e.frames_registered < frames_selected) short_of_evidence = true;
  }
  if (why.tellp() == 0) {
    r.verdict = Verdict::kOk;
    r.doubt.clear();
    return;
  }
  r.verdict = Verdict::kUnverified;
  if (r.deadline_reached && short_of_evidence) {
    e.suggested_deadline_s = suggestDeadline(deadline_s, frames_selected, e.frames_registered);
    why << "; the deadline cut the plan after " << e.frames_registered << " of " << frames_selected
        << " frames: try --deadline " << std::setprecision(0) << e.suggested_deadline_s;
  }
  r.doubt = why.str();
}

void doubtClockOffset(LidarLidarResult& r, double offset_ms, double limit_ms, double uncertainty_ms) {
  r.evidence.clock_offset_ms = offset_ms;
  r.evidence.clock_offset_uncertainty_ms = uncertainty_ms;
  r.evidence.clock_measured = true;
  if (std::abs(offset_ms) <= limit_ms || r.verdict == Verdict::kFailed) return;
  std::ostringstream why;
  why.setf(std::ios::fixed);
  why.precision(1);
  // The correction adds to what the rig already subtracts.
  const double total_ms = r.evidence.time_offset_applied_ms + offset_ms;
  why << "clock: " << r.calibration_sensor << "'s packet clock is " << std::showpos << offset_ms << std::noshowpos
      << " ms off " << r.mapping_sensor << "'s (± " << uncertainty_ms
      << " ms; each against the capture time; more than " << limit_ms
      << " ms pairs it with the wrong mapping pose): fix the sensor's time sync, or set its time_offset_ns: "
      << std::llround(total_ms * 1e6) << " (or estimate) in the rig";
  r.doubt = r.verdict == Verdict::kUnverified ? why.str() + "; " + r.doubt : why.str();
  r.verdict = Verdict::kUnverified;
}

void doubtTrajectoryClockOffset(LidarLidarResult& r, double limit_ms, double deadline_s) {
  const TrajectoryClockEstimate& c = r.trajectory_clock;
  if (r.verdict == Verdict::kFailed) return;
  std::ostringstream why;
  why.setf(std::ios::fixed);
  why.precision(1);
  if (c.status == TrajectoryClockEstimate::Status::kDeadline && !r.evidence.clock_measured) {
    // The one check of its clock was cut: a lidar 35 ms late came out 5 cm off with agreeing frames.
    why << "clock: not checked, the deadline cut the estimate of " << r.calibration_sensor
        << "'s clock against the trajectory after " << c.profile.size()
        << " trial offsets (a late clock puts the lidar off by what the vehicle moves meanwhile)";
    if (deadline_s > 0) why << ": try --deadline " << std::setprecision(0) << suggestDeadline(deadline_s, 2, 1);
  } else {
    if (c.status != TrajectoryClockEstimate::Status::kEstimated) return;
    if (std::abs(c.offset_ms) <= limit_ms || std::abs(c.offset_ms) <= 2.0 * c.uncertainty_ms) return;
    const double total_ms = r.evidence.time_offset_applied_ms + c.offset_ms;
    why << "clock: " << r.calibration_sensor << "'s stamps are " << std::showpos << c.offset_ms << std::noshowpos
        << " ms (± " << c.uncertainty_ms << ") off " << r.mapping_sensor
        << "'s trajectory (registration over trial offsets; more than " << limit_ms
        << " ms pairs it with the wrong mapping pose): fix the sensor's time sync, or set its time_offset_ns: "
        << std::llround(total_ms * 1e6) << " in the rig";
  }
  r.doubt = r.verdict == Verdict::kUnverified ? why.str() + "; " + r.doubt : why.str();
  r.verdict = Verdict::kUnverified;
}

}  // namespace rigcal::calib
