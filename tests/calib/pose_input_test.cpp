// Pose CSV reader and pose trajectory: the inputs of lidar-pose calibration.
#include <gtest/gtest.h>

#include <fstream>
#include <sstream>

#include "rigcal/calib/lidar_pose/pose_csv.hpp"
#include "rigcal/calib/lidar_pose/pose_trajectory.hpp"
#include "test_data.hpp"

namespace rigcal::calib {
namespace {

PoseCsv parse(const std::string& text, const PoseCsvOptions& options = {}) {
  std::istringstream in(text);
  return parsePoseCsv(in, "poses.csv", options);
}

std::string errorOf(const std::string& text) {
  try {
    parse(text);
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  return "no error";
}

TEST(PoseCsv, ParsesTheLidarAlignLayoutSkippingCommentsAndBlankLines) {
  const PoseCsv csv = parse(
      "# timestamp_ns, index, px, py, pz, qw, qx, qy, qz\n"
      "\n"
      "1000, 0, 1.5, -2.0, 0.25, 1, 0, 0, 0\r\n"
      "   # indented comment\n"
      "2000 ,1 , 1.6 , -2.0, 0.25, 0.7071067811865476, 0, 0, 0.7071067811865476\n"
      "3000,2,+1.7,-2e0,.25,1,0,0,0\n");
  ASSERT_EQ(csv.stamps, (std::vector<TimeNs>{1000, 2000, 3000}));
  EXPECT_EQ(csv.skipped_lines, 3u);
  EXPECT_TRUE(csv.origin.isZero()) << "small coordinates are not re-centred";
  EXPECT_TRUE(csv.poses[0].translation().isApprox(Eigen::Vector3d(1.5, -2.0, 0.25)));
  EXPECT_NEAR(rad2deg(toXyzRpy(csv.poses[1]).yaw), 90.0, 1e-9);
  EXPECT_TRUE(csv.poses[2].translation().isApprox(Eigen::Vector3d(1.7, -2.0, 0.25)));
}

TEST(PoseCsv, RecentresUtmSizedCoordinatesAndReturnsTheOffset) {
  const PoseCsv csv = parse(
      "1000,0,512345.678901,5412345.123456,312.5,1,0,0,0\n"
      "2000,1,512346.678901,5412344.123456,313.0,1,0,0,0\n");
  EXPECT_EQ(csv.origin, Eigen::Vector3d(512346.0, 5412345.0, 313.0)) << "first position, whole metres";
  EXPECT_NEAR(csv.poses[0].translation().x(), -0.321099, 1e-9);
  EXPECT_NEAR(csv.poses[0].translation().y(), 0.123456, 1e-9);
  EXPECT_NEAR(csv.poses[0].translation().z(), -0.5, 1e-12);
  EXPECT_NEAR(csv.poses[1].translation().x(), 0.678901, 1e-9);
  EXPECT_NEAR(csv.poses[1].translation().y(), -0.876544, 1e-9);
  // Disabled re-centring keeps the absolute values.
  PoseCsvOptions keep;
  keep.recentre_above_m = -1.0;
  EXPECT_NEAR(parse("1000,0,512345.5,5412345.25,0,1,0,0,0\n", keep).poses[0].translation().y(), 5412345.25,
              1e-9);
}

TEST(PoseCsv, MalformedLinesAreReportedWithTheirLineNumber) {
  const std::string good = "1000,0,0,0,0,1,0,0,0\n";
  EXPECT_EQ(errorOf("# c\n" + good + "2000,1,0,0,0,1,0,0\n"),
            "poses.csv:3: expected 9 comma-separated columns (timestamp_ns, index, px, py, pz, qw, qx, "
            "qy, qz), found 8");
  EXPECT_EQ(errorOf(good + "2000,1,0,0,0,1,0,0,0,7\n").substr(0, 14), "poses.csv:2: e");
  EXPECT_EQ(errorOf(good + "\n2000,1,0,abc,0,1,0,0,0\n"),
            "poses.csv:3: column 4 (py): 'abc' is not a finite number");
  EXPECT_EQ(errorOf("12.5e3,0,0,0,0,1,0,0,0\n"),
            "poses.csv:1: column 1 (timestamp_ns): '12.5e3' is not an integer nanosecond timestamp");
  EXPECT_EQ(errorOf(good + "2000,1,0,0,nan,1,0,0,0\n"),
            "poses.csv:2: column 5 (pz): 'nan' is not a finite number");
  EXPECT_EQ(errorOf(good + "2000,1,0,0,0,1,,0,0\n"), "poses.csv:2: column 7 (qx): '' is not a finite number");
  EXPECT_EQ(errorOf(good + "2000,1,0,0,0,0.9,0,0,0\n"),
            "poses.csv:2: quaternion (qw, qx, qy, qz) has norm 0.9, not 1 (tolerance 0.001)");
  EXPECT_EQ(errorOf(good + "# gap\n1000,1,0,0,0,1,0,0,0\n"),
            "poses.csv:3: timestamp 1000 is not after the previous pose's 1000 (line 1)");
  EXPECT_EQ(errorOf(good + "999,1,0,0,0,1,0,0,0\n"),
            "poses.csv:2: timestamp 999 is not after the previous pose's 1000 (line 1)");
  EXPECT_EQ(errorOf("# only comments\n\n"), "poses.csv: no pose (every line is blank or a comment)");
}

TEST(PoseCsv, ReadsAFileAndNamesItInErrors) {
  test::TempDir dir;
  std::ofstream(dir / "p.csv") << "1000,0,0,0,0,1,0,0,0\n2000,1,0,0,0,1,0,0,0\nbad\n";
  try {
    readPoseCsv(dir / "p.csv");
    FAIL() << "expected an error";
  } catch (const std::runtime_error& e) {
    EXPECT_EQ(std::string(e.what()).rfind((dir / "p.csv").string() + ":3: expected 9", 0), 0u) << e.what();
  }
  EXPECT_THROW(readPoseCsv(dir / "missing.csv"), std::runtime_error);
}

PoseTrajectory threePoses() {
  const Pose a = fromXyzRpy({0, 0, 0, 0, 0, 0});
  const Pose b = fromXyzRpy({1.0, 0.5, 0.1, deg2rad(10), deg2rad(-5), deg2rad(40)});
  const Pose c = fromXyzRpy({1.5, 2.0, 0.0, deg2rad(-3), deg2rad(2), deg2rad(100)});
  return PoseTrajectory({1'000'000'000, 1'010'000'000, 1'030'000'000}, {a, b, c});
}

TEST(PoseTrajectory, InterpolatesOnTheSe3GeodesicBetweenTheBracketingPoses) {
  const PoseTrajectory traj = threePoses();
  for (int k = 0; k <= 20; ++k) {
    const TimeNs t = 1'000'000'000 + k * 500'000;  // first segment
    const Pose want = interpolateGeodesic(traj.pose(0), traj.pose(1), k / 20.0);
    const auto got = traj.at(t);
    ASSERT_TRUE(got);
    EXPECT_TRUE(got->matrix().isApprox(want.matrix(), 1e-12)) << k;
  }
  const Pose mid = *traj.at(1'020'000'000);
  EXPECT_TRUE(mid.matrix().isApprox(interpolateGeodesic(traj.pose(1), traj.pose(2), 0.5).matrix(), 1e-12));
  EXPECT_TRUE(traj.at(traj.begin())->matrix().isApprox(traj.pose(0).matrix(), 1e-15));
  EXPECT_TRUE(traj.at(traj.end())->matrix().isApprox(traj.pose(2).matrix(), 1e-12));
  // A sub-nanosecond offset moves the pose (the optimiser varies it continuously).
  const Pose a = *traj.at(1'005'000'000, 0.0), b = *traj.at(1'005'000'000, 0.4e-9);
  EXPECT_GT((a.translation() - b.translation()).norm(), 1e-9);
  EXPECT_TRUE(b.matrix().isApprox(
      interpolateGeodesic(traj.pose(0), traj.pose(1), 5'000'000.4 / 10'000'000.0).matrix(), 1e-12));
}

TEST(PoseTrajectory, NeverExtrapolates) {
  const PoseTrajectory traj = threePoses();
  EXPECT_FALSE(traj.at(traj.begin() - 1));
  EXPECT_FALSE(traj.at(traj.end() + 1));
  EXPECT_FALSE(traj.at(traj.end(), 1e-9));
  EXPECT_FALSE(traj.at(traj.begin(), -0.5));
  EXPECT_FALSE(traj.at(0));
  EXPECT_TRUE(traj.at(traj.end() - 10'000'000, 0.01));
}

TEST(PoseTrajectory, HintedLookupsMatchBinarySearch) {
  const PoseTrajectory traj = threePoses();
  std::size_t hint = 0;
  for (TimeNs t = traj.begin(); t <= traj.end(); t += 777'777) {
    const auto hinted = traj.at(t, 0.0, &hint), plain = traj.at(t);
    ASSERT_TRUE(hinted && plain);
    EXPECT_EQ(hinted->matrix(), plain->matrix());
  }
  hint = 1;  // a stale hint ahead of the query still finds the right segment
  EXPECT_EQ(traj.at(traj.begin() + 1000, 0.0, &hint)->matrix(), traj.at(traj.begin() + 1000)->matrix());
  EXPECT_EQ(hint, 0u);
}

TEST(PoseTrajectory, RejectsUnsortedOrTooShortInput) {
  EXPECT_THROW(PoseTrajectory({1}, {Pose::Identity()}), std::invalid_argument);
  EXPECT_THROW(PoseTrajectory({2, 2}, {Pose::Identity(), Pose::Identity()}), std::invalid_argument);
  EXPECT_THROW(PoseTrajectory({1, 2}, {Pose::Identity()}), std::invalid_argument);
  const PoseCsv csv = parse("1000,0,0,0,0,1,0,0,0\n2000,1,1,0,0,1,0,0,0\n");
  EXPECT_NEAR(PoseTrajectory(csv).at(1500)->translation().x(), 0.5, 1e-12);
}

}  // namespace
}  // namespace rigcal::calib
