// The lidar-lidar quality gate on results whose evidence is laid out by hand: ok needs frames and
// registrators that agree and a sane inlier ratio; a deadline that cut the plan is named with the
// --deadline that would do.
#include <gtest/gtest.h>

#include <cmath>

#include "rigcal/calib/lidar_lidar/lidar_lidar_verdict.hpp"

namespace rigcal::calib {
namespace {

Pose at(double x, double yaw_deg = 0.0) {
  Pose T = Pose::Identity();
  T.translate(Eigen::Vector3d(x, 0, 0));
  T.rotate(Eigen::AngleAxisd(deg2rad(yaw_deg), Eigen::Vector3d::UnitZ()));
  return T;
}

/// A result that beat its guess (x = 0) at x = 1 m, with per-frame runs landing where `frame_x` says.
LidarLidarResult resultWithFrames(const std::vector<double>& frame_x, double inliers = 0.8) {
  LidarLidarResult r;
  r.ok = true;
  r.T_mapping_calib_guess = at(0);
  r.T_mapping_calib = at(1.0);
  r.initial_score.value = 0.01;
  r.final_score.value = 0.002;
  r.final_score.inlier_ratio = inliers;
  r.candidates = {r.T_mapping_calib_guess};
  for (std::size_t f = 0; f < frame_x.size(); ++f) {
    for (const char* reg : {"ndt", "icp_fine"}) {
      RegistratorRun run;
      run.frame = int(f);
      run.registrator = reg;
      run.frame_score = std::string(reg) == "icp_fine" ? 0.001 : 0.003;
      r.candidates.push_back(at(std::string(reg) == "icp_fine" ? frame_x[f] : frame_x[f] + 0.02));
      run.result = r.candidates.size() - 1;
      r.runs.push_back(run);
    }
  }
  return r;
}

TEST(LidarLidarVerdict, AgreeingFramesAndRegistratorsAreOk) {
  auto r = resultWithFrames({1.0, 1.01, 0.99});
  judgeLidarLidar(r, 3, 10.0);
  EXPECT_EQ(r.verdict, Verdict::kOk) << r.doubt;
  EXPECT_EQ(r.evidence.frames_agreeing, 3u);
  EXPECT_NEAR(r.evidence.frame_spread_m, 0.01, 1e-9);
  EXPECT_NEAR(r.evidence.improvement, 0.8, 1e-9);
}

TEST(LidarLidarVerdict, OneConfirmingFrameCutByTheDeadlineIsUnverifiedWithTheDeadlineThatWouldDo) {
  auto r = resultWithFrames({1.0});
  r.deadline_reached = true;
  judgeLidarLidar(r, 7, 10.0);
  EXPECT_EQ(r.verdict, Verdict::kUnverified);
  EXPECT_NE(r.doubt.find("confirmed by 1 frame"), std::string::npos) << r.doubt;
  EXPECT_NE(r.doubt.find("--deadline 70"), std::string::npos) << r.doubt;
  EXPECT_DOUBLE_EQ(r.evidence.suggested_deadline_s, 70.0);
}

TEST(LidarLidarVerdict, DisagreeingFramesAreUnverified) {
  auto r = resultWithFrames({1.0, 1.0, 1.4, 0.6, 1.3});
  judgeLidarLidar(r, 5, 10.0);
  EXPECT_EQ(r.verdict, Verdict::kUnverified);
  EXPECT_NE(r.doubt.find("3 of 5 frames disagree"), std::string::npos) << r.doubt;
  EXPECT_NEAR(r.evidence.frame_spread_m, 0.4, 1e-9);
}

// Every frame "agrees" (within 5 cm) yet they scatter 2-3 cm about the result: four frames cannot put it within
// the 1 cm goal (two standard errors 2.06 cm), and the deadline that cut the plan is named.
TEST(LidarLidarVerdict, FramesScatteringBeyondTheGoalAreUnverified) {
  auto r = resultWithFrames({1.0, 1.02, 0.98, 1.03});
  r.deadline_reached = true;
  judgeLidarLidar(r, 8, 10.0);
  EXPECT_EQ(r.verdict, Verdict::kUnverified);
  EXPECT_EQ(r.evidence.frames_agreeing, 4u);
  EXPECT_NEAR(r.evidence.frame_uncertainty_m, 2.0 * std::sqrt(0.0017) / 4.0, 1e-9);
  EXPECT_NE(r.doubt.find("its 4 agreeing frames scatter about it by ± 2.06 cm"), std::string::npos) << r.doubt;
  EXPECT_NE(r.doubt.find("--deadline 20"), std::string::npos) << r.doubt;
}

// One frame 30 cm off among five that agree within 2 mm: an outlier the majority outvotes, not scatter.
TEST(LidarLidarVerdict, AnOutlierFrameIsOutvotedNotCountedAsScatter) {
  auto r = resultWithFrames({1.0, 1.002, 0.998, 1.001, 0.999, 1.3});
  judgeLidarLidar(r, 6, 10.0);
  EXPECT_EQ(r.verdict, Verdict::kOk) << r.doubt;
  EXPECT_EQ(r.evidence.frames_agreeing, 5u);
  EXPECT_LT(r.evidence.frame_uncertainty_m, 0.002);
  EXPECT_NEAR(r.evidence.frame_spread_m, 0.3, 1e-9);
}

// The same 1.5 cm scatter over sixteen frames narrows to ± 0.75 cm: within the goal, ok.
TEST(LidarLidarVerdict, TheSameScatterOverMoreFramesIsOk) {
  std::vector<double> xs;
  for (int f = 0; f < 16; ++f) xs.push_back(f % 2 == 0 ? 1.015 : 0.985);
  auto r = resultWithFrames(xs);
  judgeLidarLidar(r, 16, 10.0);
  EXPECT_EQ(r.verdict, Verdict::kOk) << r.doubt;
  EXPECT_NEAR(r.evidence.frame_uncertainty_m, 0.0075, 1e-9);
}

// Rotation counts as translation does: frames 0.1-0.14° apart from a result make ± 0.1° over four frames.
TEST(LidarLidarVerdict, FramesScatteringInRotationBeyondTheGoalAreUnverified) {
  auto r = resultWithFrames({1.0, 1.0, 1.0, 1.0});
  const double yaws[] = {0.1, -0.12, 0.14, -0.1};
  for (auto& run : r.runs) r.candidates[run.result].rotate(Eigen::AngleAxisd(deg2rad(yaws[run.frame]), Eigen::Vector3d::UnitZ()));
  judgeLidarLidar(r, 4, 10.0);
  EXPECT_EQ(r.verdict, Verdict::kUnverified);
  EXPECT_GT(r.evidence.frame_uncertainty_deg, 0.05);
  EXPECT_NE(r.doubt.find("more frames would narrow it"), std::string::npos) << r.doubt;
  EXPECT_EQ(r.doubt.find("--deadline"), std::string::npos) << r.doubt;  // the plan ran to its end
  EXPECT_NE(r.doubt.find("deg (two standard errors; the goal is 1.00 cm, 0.05 deg)"), std::string::npos) << r.doubt;
  // The same frames, every one registered, but the deadline cut the plan before their re-deskewed
  // confirmations: the deadline is what is missing.
  r.deadline_reached = true;
  judgeLidarLidar(r, 4, 10.0);
  EXPECT_EQ(r.verdict, Verdict::kUnverified);
  EXPECT_EQ(r.doubt.find("more frames would narrow it"), std::string::npos) << r.doubt;
  EXPECT_NE(r.doubt.find("--deadline 20"), std::string::npos) << r.doubt;
}

/// Each frame's confirmation on its source re-deskewed with the result (finalStep), landing at `frame_x`. Its
/// score is of another cloud than the earlier runs': here higher, as measured on yard-corners' rear lidar
/// (0.00507 m² against 0.00488 m² for the same frame deskewed with the guess).
void addRedeskewedConfirmations(LidarLidarResult& r, const std::vector<double>& frame_x) {
  for (std::size_t f = 0; f < frame_x.size(); ++f) {
    RegistratorRun run;
    run.frame = int(f);
    run.registrator = "icp_fine";
    run.redeskewed = true;
    run.frame_score = 0.002;
    r.candidates.push_back(at(frame_x[f]));
    run.result = r.candidates.size() - 1;
    r.runs.push_back(run);
  }
}

// yard-corners' rear lidar: its frames in the two turns, deskewed with the guess 5° off, put it 0.1° either side
// of a result 0.005° from the truth; re-deskewed with the result they agree within 0.01°. The frames are judged
// on the clouds the result was refined on, whatever their earlier (lower, incomparable) scores.
TEST(LidarLidarVerdict, FramesAreJudgedOnTheirSourcesRedeskewedWithTheResult) {
  auto r = resultWithFrames({1.0, 1.03, 0.97, 1.03});  // scattering ± 2.6 cm about 1 m as the guess bent them
  judgeLidarLidar(r, 4, 10.0);
  ASSERT_EQ(r.verdict, Verdict::kUnverified) << "the guess-deskewed frames alone scatter beyond the goal";
  addRedeskewedConfirmations(r, {1.001, 0.999, 1.002, 0.998});
  judgeLidarLidar(r, 4, 10.0);
  EXPECT_EQ(r.verdict, Verdict::kOk) << r.doubt;
  EXPECT_EQ(r.evidence.frames_registered, 4u);
  EXPECT_NEAR(r.evidence.frame_spread_m, 0.002, 1e-9);
}

// And the other way: frames that agreed under the guess's deskew but scatter once re-deskewed do not confirm it.
TEST(LidarLidarVerdict, RedeskewedFramesThatScatterAreNotHiddenByEarlierAgreement) {
  auto r = resultWithFrames({1.0, 1.001, 0.999, 1.0});
  judgeLidarLidar(r, 4, 10.0);
  ASSERT_EQ(r.verdict, Verdict::kOk) << r.doubt;
  addRedeskewedConfirmations(r, {1.0, 1.03, 0.97, 1.03});
  judgeLidarLidar(r, 4, 10.0);
  EXPECT_EQ(r.verdict, Verdict::kUnverified);
  EXPECT_NEAR(r.evidence.frame_spread_m, 0.03, 1e-9);
  EXPECT_NE(r.doubt.find("its 4 agreeing frames scatter about it"), std::string::npos) << r.doubt;
}

// A frame the deadline cut before its re-deskewed confirmation still counts with its earlier runs.
TEST(LidarLidarVerdict, AFrameWithoutARedeskewedRunKeepsItsEarlierOnes) {
  auto r = resultWithFrames({1.0, 1.001, 1.3});
  addRedeskewedConfirmations(r, {0.999, 1.0});  // frame 2 has none: its 30 cm still disagree
  judgeLidarLidar(r, 3, 10.0);
  EXPECT_EQ(r.evidence.frames_registered, 3u);
  EXPECT_EQ(r.evidence.frames_agreeing, 2u);
  EXPECT_NEAR(r.evidence.frame_spread_m, 0.3, 1e-9);
}

/// Frame `f`'s runs moved by `offset` (mapping frame, which is the lidar's here: the result has no rotation).
void moveFrame(LidarLidarResult& r, int f, const Eigen::Vector3d& offset) {
  for (const auto& run : r.runs)
    if (run.frame == f) r.candidates[run.result].pretranslate(offset);
}

PoseInformation diagonalInformation(double x, double y, double z) {
  PoseInformation H = PoseInformation::Identity() * 100.0;
  H(0, 0) = x;
  H(1, 1) = y;
  H(2, 2) = z;
  return H;
}

// yard-side's side_left (a VLP-32C rolled 90°): one frame on a straight stretch saw nothing along the lidar's
// spin axis and its own result drifted 4.1 cm that way, while the other four agreed within 2 mm. The result,
// refined over all frames, hardly follows a frame where it does not see: weighted by each frame's information,
// the four frames' agreement decides (ok); counted alike, the one frame's 4 cm made it unverified.
TEST(LidarLidarVerdict, AFramesScatterAlongADirectionItDoesNotSeeCountsAsLittleAsItPullsTheResult) {
  auto r = resultWithFrames({1.0, 1.0, 1.0, 1.0});
  moveFrame(r, 2, {0, 0, 0.04});
  judgeLidarLidar(r, 4, 10.0);
  ASSERT_EQ(r.verdict, Verdict::kUnverified) << "counted alike: ± 2 cm";
  EXPECT_FALSE(r.evidence.frame_uncertainty_weighted);
  for (int f = 0; f < 4; ++f) r.frame_information[f] = diagonalInformation(100, 100, f == 2 ? 1.0 : 100.0);
  judgeLidarLidar(r, 4, 10.0);
  EXPECT_EQ(r.verdict, Verdict::kOk) << r.doubt;
  EXPECT_TRUE(r.evidence.frame_uncertainty_weighted);
  EXPECT_NEAR(r.evidence.frame_uncertainty_m, 2.0 * 0.04 / 301.0, 1e-9);
  EXPECT_NEAR(r.evidence.frame_spread_m, 0.04, 1e-9);  // the spread still says where the frame went
}

// The weights never hide scatter that moves the result: the frame that sees best along z decides z, so its
// 4 cm count in full; and frames that see alike give the plain standard error (± 2.06 cm as unweighted).
TEST(LidarLidarVerdict, AFramesScatterAlongWhatItSeesBestCountsInFull) {
  auto r = resultWithFrames({1.0, 1.0, 1.0, 1.0});
  moveFrame(r, 2, {0, 0, 0.04});
  for (int f = 0; f < 4; ++f) r.frame_information[f] = diagonalInformation(100, 100, f == 2 ? 100.0 : 1.0);
  judgeLidarLidar(r, 4, 10.0);
  EXPECT_EQ(r.verdict, Verdict::kUnverified);
  EXPECT_NEAR(r.evidence.frame_uncertainty_m, 2.0 * 100.0 * 0.04 / 103.0, 1e-9);

  auto same = resultWithFrames({1.0, 1.02, 0.98, 1.03});
  for (int f = 0; f < 4; ++f) same.frame_information[f] = diagonalInformation(50, 50, 50);
  judgeLidarLidar(same, 4, 10.0);
  EXPECT_EQ(same.verdict, Verdict::kUnverified);
  EXPECT_TRUE(same.evidence.frame_uncertainty_weighted);
  EXPECT_NEAR(same.evidence.frame_uncertainty_m, 2.0 * std::sqrt(0.0017) / 4.0, 1e-9);
}

/// Another run on frame `f`, landing `offset` from the result at `score_share` above the frame's best score.
void addTiedRun(LidarLidarResult& r, int f, const Eigen::Vector3d& offset, double score_share) {
  RegistratorRun run;
  run.frame = f;
  run.registrator = "gicp";
  run.frame_score = 0.001 * (1.0 + score_share);
  Pose T = r.T_mapping_calib;
  T.pretranslate(offset);
  r.candidates.push_back(T);
  run.result = r.candidates.size() - 1;
  r.runs.push_back(run);
}

// yard-side's side_left (a VLP-32C rolled 90°, d60): one frame's best run slid 3.2 cm along the spin axis while
// its icp_fine runs, at a score 0.5 % higher, lay 3.7 cm the other way; another frame's runs all lay within
// 0.4 cm. Every frame's information is alike here, so only the frame's own runs can say that it does not know
// where along z the result is: their spread at an equal score discounts it there, and the others decide (ok).
TEST(LidarLidarVerdict, AFrameWhoseRunsTieAlongADirectionCountsLittleThere) {
  auto r = resultWithFrames({1.0, 1.0, 1.0, 1.0});
  moveFrame(r, 2, {0, 0, 0.04});
  for (int f = 0; f < 4; ++f) r.frame_information[f] = diagonalInformation(100, 100, 100);
  judgeLidarLidar(r, 4, 10.0);
  ASSERT_EQ(r.verdict, Verdict::kUnverified) << "a frame that knows where it is and disagrees by 4 cm";
  EXPECT_NEAR(r.evidence.frame_uncertainty_m, 0.02, 1e-9);

  addTiedRun(r, 2, {0, 0, -0.02}, 0.01);  // its own other answer, 6 cm away at a score 1 % higher
  judgeLidarLidar(r, 4, 10.0);
  EXPECT_EQ(r.verdict, Verdict::kOk) << r.doubt;
  EXPECT_LT(r.evidence.frame_uncertainty_m, 0.001);
  EXPECT_NEAR(r.evidence.frame_spread_m, 0.04, 1e-9);  // its best still says where it went
}

// A run clearly worse than the frame's best (10 %: the frame does tell them apart) does not discount it.
TEST(LidarLidarVerdict, ARunTheFramesScoreTellsApartDoesNotDiscountIt) {
  auto r = resultWithFrames({1.0, 1.0, 1.0, 1.0});
  moveFrame(r, 2, {0, 0, 0.04});
  for (int f = 0; f < 4; ++f) r.frame_information[f] = diagonalInformation(100, 100, 100);
  addTiedRun(r, 2, {0, 0, -0.02}, 0.10);
  judgeLidarLidar(r, 4, 10.0);
  EXPECT_EQ(r.verdict, Verdict::kUnverified);
  EXPECT_NEAR(r.evidence.frame_uncertainty_m, 0.02, 1e-9);
}

// Frames' scores weigh them too: the points' noise left in a frame is its score over its information, so of
// two frames that see alike the one whose points fit four times worse counts a quarter as much.
TEST(LidarLidarVerdict, AFrameWhosePointsFitWorseCountsLess) {
  auto r = resultWithFrames({1.0, 1.0});
  moveFrame(r, 1, {0, 0, 0.04});
  for (int f = 0; f < 2; ++f) r.frame_information[f] = diagonalInformation(100, 100, 100);
  for (auto& run : r.runs)
    if (run.frame == 1) run.frame_score *= 4.0;
  judgeLidarLidar(r, 2, 10.0);
  // W = 1 and 1/4 (relative): 2 · sqrt((0.25 · 0.04)²) / 1.25.
  EXPECT_NEAR(r.evidence.frame_uncertainty_m, 2.0 * 0.25 * 0.04 / 1.25, 1e-9);
}

// A frame without information (cut before the result was reached): every frame counts alike, as before.
TEST(LidarLidarVerdict, WithoutEveryFramesInformationFramesCountAlike) {
  auto r = resultWithFrames({1.0, 1.0, 1.0, 1.0});
  moveFrame(r, 2, {0, 0, 0.04});
  for (int f = 0; f < 3; ++f) r.frame_information[f] = diagonalInformation(100, 100, f == 2 ? 1.0 : 100.0);
  judgeLidarLidar(r, 4, 10.0);
  EXPECT_EQ(r.verdict, Verdict::kUnverified);
  EXPECT_FALSE(r.evidence.frame_uncertainty_weighted);
  EXPECT_NEAR(r.evidence.frame_uncertainty_m, 0.02, 1e-9);
}

TEST(LidarLidarVerdict, LowInlierRatioIsUnverified) {
  auto r = resultWithFrames({1.0, 1.0, 1.0}, 0.49);
  judgeLidarLidar(r, 3, 10.0);
  EXPECT_EQ(r.verdict, Verdict::kUnverified);
  EXPECT_NE(r.doubt.find("inlier ratio 0.49"), std::string::npos) << r.doubt;
}

// A low inlier ratio on a plan the deadline cut: more time is what would tell (yard-corners' corner lidars
// under load: 0.49 on 2 of 7 frames, 0.61 with all of them); on a complete plan nothing the user can give would.
TEST(LidarLidarVerdict, ALowInlierRatioOnAPlanTheDeadlineCutSuggestsTheDeadlineThatWouldDo) {
  auto cut = resultWithFrames({1.0, 1.0}, 0.49);
  cut.deadline_reached = true;
  judgeLidarLidar(cut, 7, 10.0);
  EXPECT_EQ(cut.verdict, Verdict::kUnverified);
  EXPECT_NE(cut.doubt.find("inlier ratio 0.49"), std::string::npos) << cut.doubt;
  EXPECT_NE(cut.doubt.find("the deadline cut the plan after 2 of 7 frames: try --deadline"), std::string::npos)
      << cut.doubt;
  EXPECT_GT(cut.evidence.suggested_deadline_s, 10.0);

  auto complete = resultWithFrames({1.0, 1.0}, 0.49);
  complete.deadline_reached = true;  // only the searches after a complete plan ran into it
  judgeLidarLidar(complete, 2, 10.0);
  EXPECT_EQ(complete.verdict, Verdict::kUnverified);
  EXPECT_EQ(complete.doubt.find("--deadline"), std::string::npos) << complete.doubt;
  EXPECT_EQ(complete.evidence.suggested_deadline_s, 0.0);
}

TEST(LidarLidarVerdict, OneRegistratorAloneIsUnverified) {
  auto r = resultWithFrames({1.0, 1.0});
  for (auto& run : r.runs)
    if (run.registrator == "icp_fine") run.registrator = "ndt";
  for (std::size_t c = 1; c < r.candidates.size(); ++c) r.candidates[c] = at(1.0);
  judgeLidarLidar(r, 2, 10.0);
  EXPECT_EQ(r.verdict, Verdict::kUnverified);
  EXPECT_NE(r.doubt.find("reached by 1 registrator"), std::string::npos) << r.doubt;
}

TEST(LidarLidarVerdict, AResultThatDoesNotBeatTheGuessFails) {
  auto r = resultWithFrames({1.0, 1.0});
  r.ok = false;
  judgeLidarLidar(r, 2, 10.0);
  EXPECT_EQ(r.verdict, Verdict::kFailed);
}

TEST(LidarLidarVerdict, AClockOffsetAboveTheLimitIsUnverifiedNamingTheSensorAndTheOffset) {
  auto r = resultWithFrames({1.0, 1.0, 1.0});
  r.calibration_sensor = "front_left";
  r.mapping_sensor = "top";
  judgeLidarLidar(r, 3, 10.0);
  ASSERT_EQ(r.verdict, Verdict::kOk) << r.doubt;
  doubtClockOffset(r, 4.0, 10.0);
  EXPECT_EQ(r.verdict, Verdict::kOk) << "within the limit: " << r.doubt;
  doubtClockOffset(r, -50.0, 10.0);
  EXPECT_EQ(r.verdict, Verdict::kUnverified);
  EXPECT_DOUBLE_EQ(r.evidence.clock_offset_ms, -50.0);
  EXPECT_NE(r.doubt.find("front_left's packet clock is -50.0 ms off top's"), std::string::npos) << r.doubt;
  EXPECT_NE(r.doubt.find("time_offset_ns: -50000000"), std::string::npos) << "the correction named: " << r.doubt;
}

// After a time_offset_ns the rig applied, what is left is doubted against the limit, and the correction
// suggested is the total (what was applied plus what is left), with its uncertainty.
TEST(LidarLidarVerdict, AResidualClockOffsetAfterTheRigsCorrectionSuggestsTheTotal) {
  auto r = resultWithFrames({1.0, 1.0, 1.0});
  r.calibration_sensor = "front_left";
  r.mapping_sensor = "top";
  judgeLidarLidar(r, 3, 10.0);
  r.evidence.time_offset_applied_ms = 35.0;
  doubtClockOffset(r, 15.0, 10.0, 0.4);
  EXPECT_EQ(r.verdict, Verdict::kUnverified);
  EXPECT_TRUE(r.evidence.clock_measured);
  EXPECT_DOUBLE_EQ(r.evidence.clock_offset_uncertainty_ms, 0.4);
  EXPECT_NE(r.doubt.find("(± 0.4 ms"), std::string::npos) << r.doubt;
  EXPECT_NE(r.doubt.find("time_offset_ns: 50000000"), std::string::npos) << r.doubt;
}

}  // namespace
}  // namespace rigcal::calib
