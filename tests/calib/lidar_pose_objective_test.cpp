// Point selection, trajectory restriction, the objective (against brute force, across thread counts)
// and the output files of lidar-pose calibration.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <random>
#include <sstream>

#include "rigcal/calib/lidar_pose/lidar_pose_objective.hpp"
#include "rigcal/calib/outputs/calibration_yaml_writer.hpp"
#include "rigcal/calib/lidar_pose/lidar_pose_output.hpp"
#include "rigcal/core/ply_io.hpp"
#include "test_data.hpp"

namespace rigcal::calib {
namespace {

// A trajectory turning and climbing over 2 s, poses at 50 Hz.
PoseTrajectory turningTrajectory() {
  std::vector<TimeNs> stamps;
  std::vector<Pose> poses;
  for (int k = 0; k <= 100; ++k) {
    const double t = 0.02 * k;
    stamps.push_back(5 * kNsPerSec + k * 20 * kNsPerMs);
    poses.push_back(fromXyzRpy({2.0 * t, std::sin(t), 0.1 * t, 0.1 * std::sin(3 * t), 0.05 * t, 0.8 * t}));
  }
  return PoseTrajectory(stamps, poses);
}

// Points clustered on a few planes so that neighbours exist at every cap, times inside the trajectory.
LidarPoints randomPoints(std::size_t n, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-6.0, 6.0), t(0.2, 1.8);
  LidarPoints p;
  for (std::size_t i = 0; i < n; ++i) {
    const int plane = static_cast<int>(i % 3);
    const double a = u(rng), b = u(rng), c = 0.02 * u(rng);
    p.x.push_back(static_cast<float>(plane == 0 ? 4.0 + c : a));
    p.y.push_back(static_cast<float>(plane == 1 ? -3.0 + c : b));
    p.z.push_back(static_cast<float>(plane == 2 ? -1.5 + c : (plane == 0 ? b : a) * 0.3));
    p.intensity.push_back(static_cast<float>(i % 100));
    p.time_ns.push_back(5 * kNsPerSec + fromSeconds(t(rng)));
  }
  return p;
}

double bruteForce(const LidarPoseObjective& o, float max_sq) {
  const auto &x = o.fusedX(), &y = o.fusedY(), &z = o.fusedZ();
  double sum = 0.0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    float best = max_sq;
    for (std::size_t j = 0; j < x.size(); ++j) {
      const float dx = x[j] - x[i], dy = y[j] - y[i], dz = z[j] - z[i];
      const float d2 = dx * dx + dy * dy + dz * dz;
      if (j != i && d2 < best) best = d2;
    }
    sum += best;
  }
  return sum;
}

TEST(LidarPoseObjective, EqualsBruteForceNearestNeighboursAtEveryCap) {
  const PoseTrajectory traj = turningTrajectory();
  const LidarPoints pts = randomPoints(3000, 1);
  LidarPoseObjective objective(pts, traj, 2);
  const Pose T = fromXyzRpy({0.4, -0.1, 0.2, 0.05, -0.1, 0.3});
  for (const double cap : {0.01, 0.1, 1.0, 4.0}) {
    const double ours = objective.evaluate(T, 0.013, cap);
    EXPECT_NEAR(ours, bruteForce(objective, static_cast<float>(cap)), 1e-9 * ours) << cap;
    EXPECT_GT(ours, 0.0);
    EXPECT_LT(ours, cap * pts.size());
  }
}

TEST(LidarPoseObjective, IsBitIdenticalForOneAndTwoThreadsAndAcrossCalls) {
  const PoseTrajectory traj = turningTrajectory();
  const LidarPoints pts = randomPoints(20000, 2);
  LidarPoseObjective one(pts, traj, 1), two(pts, traj, 2);
  EXPECT_EQ(two.threads(), 2);
  for (int k = 0; k < 6; ++k) {
    const Pose T = fromXyzRpy({0.1 * k, -0.05 * k, 0.3, 0.02 * k, -0.03 * k, 0.5 - 0.1 * k});
    const double offset = -0.05 + 0.02 * k, cap = k % 2 ? 0.1 : 1.0;
    const double a = one.evaluate(T, offset, cap), b = two.evaluate(T, offset, cap);
    EXPECT_EQ(a, b) << k;  // exact: fixed-order reduction
    EXPECT_EQ(one.fusedX(), two.fusedX());
    EXPECT_EQ(two.evaluate(T, offset, cap), b) << "cached poses give the same value";
  }
  EXPECT_EQ(one.evaluations(), 6u);
  EXPECT_THROW(one.evaluate(Pose::Identity(), 0.5, 0.1), std::out_of_range) << "no pose: never extrapolate";
}

TEST(LidarPointSelection, KeepsADeterministicSubsetAndAppliesLidarAlignFilters) {
  Scan scan;
  scan.sequence = 42;
  scan.stamp_ns = 1000;
  for (int i = 0; i < 20000; ++i)
    scan.push_back(Point{static_cast<float>(1 + i % 150), 0.0f, 0.0f, static_cast<float>(i % 10), 0,
                         1000 + i, 0});
  scan.x[5] = std::numeric_limits<float>::quiet_NaN();
  LidarPointSelection sel;
  sel.keep_points_ratio = 1.0;
  sel.min_return_intensity = 2.0;  // kept when intensity > 2: 7 of every 10
  sel.min_point_distance = 10.0;   // kept when 10 < range < 100
  const LidarPoints all = selectLidarPoints({scan}, sel);
  EXPECT_EQ(all.counts.input, 20000u);
  EXPECT_EQ(all.counts.low_intensity, 6000u);
  EXPECT_EQ(all.counts.not_sampled, 0u);
  EXPECT_EQ(all.counts.kept + all.counts.out_of_range + all.counts.low_intensity, 20000u);
  for (std::size_t i = 0; i < all.size(); ++i) {
    EXPECT_GT(all.x[i], 10.0f);
    EXPECT_LT(all.x[i], 100.0f);
    EXPECT_GT(all.intensity[i], 2.0f);
    EXPECT_EQ(all.x[i], static_cast<float>(1 + (all.time_ns[i] - 1000) % 150)) << "absolute time";
    if (::testing::Test::HasFailure()) break;
  }

  sel = LidarPointSelection{};  // lidar_align defaults: 1 %, intensity > −1, range in (0, 100)
  const LidarPoints a = selectLidarPoints({scan}, sel), b = selectLidarPoints({scan}, sel);
  EXPECT_EQ(a.time_ns, b.time_ns);
  EXPECT_NEAR(static_cast<double>(a.counts.input - a.counts.not_sampled), 200.0, 45.0);
  sel.seed = 1;
  EXPECT_NE(selectLidarPoints({scan}, sel).time_ns, a.time_ns) << "the seed changes the subset";
}

TEST(LidarPointSelection, PointsOutsideThePoseRangeAreDroppedAndCounted) {
  const PoseTrajectory traj = turningTrajectory();  // [5.0, 7.0] s
  LidarPoints pts;
  for (int i = 0; i < 100; ++i) {  // 4.5 s .. 7.475 s
    pts.x.push_back(1.0f);
    pts.y.push_back(0.0f);
    pts.z.push_back(0.0f);
    pts.intensity.push_back(static_cast<float>(i));
    pts.time_ns.push_back(4500 * kNsPerMs + i * 30 * kNsPerMs);
  }
  pts.counts.kept = 100;
  LidarPoints copy = pts;
  restrictToTrajectory(copy, traj, 0.1);  // needs a pose within ±0.1 s: [5.1, 6.9] s
  std::size_t expected = 0;
  for (const TimeNs t : pts.time_ns) expected += (t >= 5100 * kNsPerMs && t <= 6900 * kNsPerMs);
  EXPECT_EQ(copy.size(), expected);
  EXPECT_EQ(copy.counts.outside_poses, 100 - expected);
  EXPECT_EQ(copy.counts.kept, expected);
  for (std::size_t i = 0; i < copy.size(); ++i)
    EXPECT_EQ(copy.intensity[i], static_cast<float>((copy.time_ns[i] - 4500 * kNsPerMs) / (30 * kNsPerMs)));

  LidarPoints late = pts;
  for (auto& t : late.time_ns) t += 60 * kNsPerSec;
  try {
    restrictToTrajectory(late, traj, 0.1);
    FAIL() << "expected an error";
  } catch (const std::runtime_error& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("poses span [5.000000000, 7.000000000] s (2.000 s)"), std::string::npos) << what;
    EXPECT_NE(what.find("lidar points span [64.500000000, 67.470000000] s"), std::string::npos) << what;
  }
}

TEST(LidarPoseOutput, WritesLidarAlignSectionsYamlAndACloudWithIntensityAndTime) {
  const PoseTrajectory traj = turningTrajectory();
  LidarPoseResult r;
  r.T_pose_lidar = fromXyzRpy({0.5, -0.2, 0.3, deg2rad(3), deg2rad(-4), deg2rad(10)});
  r.time_offset_s = 0.015;
  r.points = randomPoints(50, 3);
  r.observability.poorly_constrained[static_cast<std::size_t>(LidarPoseParam::kZ)] = true;
  r.observability.reason[static_cast<std::size_t>(LidarPoseParam::kZ)] = "test";
  r.held[static_cast<std::size_t>(LidarPoseParam::kZ)] = true;
  const std::string text = lidarPoseCalibrationText(r, Eigen::Vector3d(500000, 5400000, 0));
  for (const char* section :
       {"Active Transformation Vector (x,y,z,rx,ry,rz) from the Pose Sensor Frame to  the Lidar Frame:\n[0.5, "
        "-0.2, 0.3, ",
        "Active Transformation Matrix from the Pose Sensor Frame to  the Lidar Frame:\n",
        "Active Translation Vector (x,y,z) from the Pose Sensor Frame to  the Lidar Frame:\n[0.5, -0.2, 0.3]",
        "Active Hamiltonen Quaternion (w,x,y,z) the Pose Sensor Frame to  the Lidar Frame:\n[0.99",
        "Time offset that must be added to lidar timestamps in seconds:\n0.015\n",
        "Roll, pitch, yaw (degrees, R = Rz·Ry·Rx):\n[3, -4, 10]", "re-centred by subtracting [500000, 5400000, 0]",
        "poorly constrained: z (test)", "held at the initial guess: z"})
    EXPECT_NE(text.find(section), std::string::npos) << section << "\n---\n" << text;

  test::TempDir dir;
  writeLidarPoseYaml(dir / "calibration.yaml", r, "ins", "top_lidar");
  std::ifstream yaml(dir / "calibration.yaml");
  std::stringstream ys;
  ys << yaml.rdbuf();
  EXPECT_NE(ys.str().find("ins:\n  top_lidar:\n    x: 0.500000\n    y: -0.200000\n    z: 0.300000\n    roll: "
                          "0.052360\n    pitch: -0.069813\n    yaw: 0.174533\n    time_offset_s: 0.015000000\n"),
            std::string::npos)
      << ys.str();
  EXPECT_NE(ys.str().find("# poorly constrained by the motion (held at the initial guess unless disabled): z"),
            std::string::npos);

  writeLidarPoseCloud(dir / "cloud.ply", r.points, traj, r.T_pose_lidar, r.time_offset_s);
  const PointTable cloud = readPly(dir / "cloud.ply");
  ASSERT_EQ(cloud.size(), r.points.size());
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    EXPECT_EQ(cloud.column("intensity")[i], r.points.intensity[i]);
    EXPECT_DOUBLE_EQ(cloud.column("time")[i], toSeconds(r.points.time_ns[i]) + 0.015);
    const Eigen::Vector3d want = *traj.at(r.points.time_ns[i], 0.015) *
                                 (r.T_pose_lidar * Eigen::Vector3d(r.points.x[i], r.points.y[i], r.points.z[i]));
    EXPECT_NEAR(cloud.column("x")[i], want.x(), 1e-5);
    EXPECT_NEAR(cloud.column("z")[i], want.z(), 1e-5);
  }
  EXPECT_EQ(cloud.fields()[4].type, FieldType::kF64);
}

}  // namespace
}  // namespace rigcal::calib
