#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "rigcal/sim/simulation.hpp"
#include "sim_test_util.hpp"

namespace rigcal::sim {
namespace {

struct Collect : SimulationSink {
  std::vector<FiringBatch> batches;
  std::vector<SimulatedScan> scans;
  void onFirings(std::size_t, const FiringBatch& b) override { batches.push_back(b); }
  void onScan(SimulatedScan&& s) override { scans.push_back(std::move(s)); }
  [[nodiscard]] std::vector<LaserReturn> returns() const {
    std::vector<LaserReturn> r;
    for (const auto& b : batches) r.insert(r.end(), b.returns.begin(), b.returns.end());
    return r;
  }
};

Collect run(const Simulation& sim, double seconds, int threads = 2, bool truth = false, TimeNs chunk = 50 * kNsPerMs) {
  Collect c;
  SimulationOptions o;
  o.threads = threads;
  o.keep_truth_poses = truth;
  o.chunk_ns = chunk;
  o.max_duration_ns = fromSeconds(seconds);
  sim.run(c, o);
  return c;
}

TEST(Physics, SkewIsRealAndExactlyExplainedByPerPointPoses) {
  // 36 km/h while turning: within one 100 ms sweep the sensor moves a metre and turns ~4.5°.
  const Simulation sim(test::movingLidar("VLP-16", 36, 90, 0.0, 0.0));
  const Collect c = run(sim, 0.35, 2, true);
  ASSERT_GE(c.scans.size(), 3u);
  const SimulatedScan& s = c.scans[1];  // a complete sweep
  ASSERT_GT(s.scan.size(), 15000u);
  ASSERT_EQ(s.T_world_sensor.size(), s.scan.size());
  std::size_t off_surface = 0, objects = 0, skewed = 0;
  const Pose& start = s.T_world_sensor.front();
  for (std::size_t i = 0; i < s.scan.size(); ++i) {
    const Eigen::Vector3d p(s.scan.x[i], s.scan.y[i], s.scan.z[i]);
    const Eigen::Vector3d w = s.T_world_sensor[i] * p;
    // Without noise a point is off its surface only by the 2 mm range quantum (±1 mm) and float.
    if (sim.scene().surfaceDistance(w) > 0.0015) ++off_surface;
    const Ground& g = sim.scene().ground();
    if (w.z() - g.height(w.x(), w.y()) < 0.3) continue;  // ground points stay on the ground anyway
    ++objects;
    if (sim.scene().surfaceDistance(start * p) > 0.05) ++skewed;
    EXPECT_EQ(s.T_world_sensor[i].matrix(), sim.T_world_sensor(0, s.true_time_ns[i]).matrix());
  }
  EXPECT_EQ(off_surface, 0u);
  ASSERT_GT(objects, 2000u);
  EXPECT_GT(double(skewed) / double(objects), 0.5) << "one pose for the whole sweep misplaces most object points";
}

TEST(Physics, EveryModelsPointsLieOnTheSceneWithTheirTruthPoses) {
  // The geometry conventions of each model (angles, azimuth direction, Ouster beam origin and
  // sensor frame) agree with the ray casting: noise-free points land on surfaces.
  for (const std::string model : {"VLP-16", "VLP-32C", "VLS-128", "OS1-64", "OS1-128", "PandarXT32"}) {
    const Simulation sim(test::movingLidar(model, 20, 45, 0.0, 0.0));
    const LidarModel& m = sim.model(0);
    const Collect c = run(sim, 0.06, 2, true);
    std::size_t n = 0, off = 0;
    for (const auto& s : c.scans)
      for (std::size_t i = 0; i < s.scan.size(); ++i, ++n)
        off += sim.scene().surfaceDistance(s.T_world_sensor[i] * Eigen::Vector3d(s.scan.x[i], s.scan.y[i], s.scan.z[i])) >
               0.5 * m.distance_unit_m + 5e-4;
    EXPECT_GT(n, 1000u) << model;
    EXPECT_EQ(off, 0u) << model << ": of " << n;
  }
}

TEST(Physics, SweepsAreWellFormed) {
  const Simulation sim(test::movingLidar("OS1-64", 5, 0, 0.02, 0.003));
  const Collect c = run(sim, 0.25);
  ASSERT_GE(c.scans.size(), 2u);
  const SimulatedScan& s = c.scans[1];
  EXPECT_EQ(s.scan.sensor_id, "lidar");
  EXPECT_EQ(s.scan.offset_ns.front(), 0u) << "stamp_ns is the earliest point";
  EXPECT_TRUE(std::is_sorted(s.scan.offset_ns.begin(), s.scan.offset_ns.end()));
  EXPECT_NEAR(double(s.scan.offset_ns.back()), 1e8, 2e5) << "a sweep lasts one rotation";
  EXPECT_GT(s.scan.size(), 30000u);
  for (std::size_t i = 0; i < s.scan.size(); ++i) {
    ASSERT_LT(s.scan.ring[i], 64);
    ASSERT_GE(s.scan.intensity[i], 1.0f);
    ASSERT_LE(s.scan.intensity[i], 255.0f);
    ASSERT_EQ(s.true_time_ns[i], s.scan.pointTime(i)) << "no clock offset in this scenario";
  }
}

TEST(Physics, RangesAreQuantisedAndWithinLimits) {
  for (const std::string model : {"VLP-16", "OS1-64", "PandarXT32", "VLS-128"}) {
    const Simulation sim(test::movingLidar(model, 5, 0, 0.02, 0.003, 0.5));
    const LidarModel& m = sim.model(0);
    const Collect c = run(sim, 0.03);
    std::size_t valid = 0;
    for (const LaserReturn& r : c.returns()) {
      if (!r.valid) {
        ASSERT_EQ(r.range_m, 0.0f);
        continue;
      }
      ++valid;
      // A whole number of distance units, up to float precision (1.5e-5 m at 245 m).
      const double units = std::round(r.range_m / m.distance_unit_m);
      ASSERT_NEAR(r.range_m, units * m.distance_unit_m, 2e-5) << model;
      ASSERT_GE(r.range_m, m.min_range_m) << model;
      ASSERT_LE(r.range_m, m.max_range_m) << model;
      ASSERT_EQ(r.intensity, std::round(r.intensity));
    }
    EXPECT_GT(valid, 1000u) << model;
  }
}

TEST(Physics, RangeNoiseAndDropoutsHaveTheConfiguredSize) {
  // Same seed and scene: only the noise differs, so ranges can be compared beam by beam.
  const Simulation clean(test::movingLidar("VLP-16", 5, 0, 0.0, 0.0, 0.5));
  const Simulation noisy(test::movingLidar("VLP-16", 5, 0, 0.02, 0.0, 0.5));
  const Simulation lossy(test::movingLidar("VLP-16", 5, 0, 0.0, 0.1, 0.5));
  const auto a = run(clean, 0.2).returns(), b = run(noisy, 0.2).returns(), d = run(lossy, 0.2).returns();
  ASSERT_EQ(a.size(), b.size());
  ASSERT_EQ(a.size(), d.size());
  double sum = 0, sum2 = 0;
  std::size_t n = 0, kept = 0, base = 0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    if (a[i].valid && b[i].valid && a[i].range_m < 90) {
      const double e = double(b[i].range_m) - double(a[i].range_m);
      sum += e;
      sum2 += e * e;
      ++n;
    }
    base += a[i].valid;
    kept += a[i].valid && d[i].valid;
  }
  ASSERT_GT(n, 10000u);
  EXPECT_NEAR(sum / double(n), 0.0, 0.001);
  EXPECT_NEAR(std::sqrt(sum2 / double(n)), 0.02, 0.001);
  EXPECT_NEAR(1.0 - double(kept) / double(base), 0.1, 0.01);
}

TEST(Physics, OutputDoesNotDependOnThreadsOrChunks) {
  const Simulation sim(test::movingLidar("OS1-64", 10, 30, 0.02, 0.01));
  const Collect one = run(sim, 0.25, 1, false, 50 * kNsPerMs);
  const Collect two = run(sim, 0.25, 2, false, 30 * kNsPerMs);
  const auto a = one.returns(), b = two.returns();
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i) {
    ASSERT_EQ(a[i].valid, b[i].valid) << i;
    ASSERT_EQ(a[i].range_m, b[i].range_m) << i;
    ASSERT_EQ(a[i].intensity, b[i].intensity) << i;
  }
  ASSERT_EQ(one.scans.size(), two.scans.size());
  for (std::size_t k = 0; k < one.scans.size(); ++k) {
    EXPECT_EQ(one.scans[k].scan.x, two.scans[k].scan.x);
    EXPECT_EQ(one.scans[k].scan.stamp_ns, two.scans[k].scan.stamp_ns);
  }
}

TEST(Physics, SameSeedSamePointsAnotherSeedOthers) {
  // Two independent simulations of one scenario and seed: identical sweeps, bit for bit.
  const Scenario sc = test::movingLidar("PandarXT32", 8, 20, 0.02, 0.01);
  const Collect a = run(Simulation(sc), 0.25), b = run(Simulation(sc), 0.25, 1);
  ASSERT_EQ(a.scans.size(), b.scans.size());
  for (std::size_t k = 0; k < a.scans.size(); ++k) {
    EXPECT_EQ(a.scans[k].scan.x, b.scans[k].scan.x);
    EXPECT_EQ(a.scans[k].scan.y, b.scans[k].scan.y);
    EXPECT_EQ(a.scans[k].scan.z, b.scans[k].scan.z);
    EXPECT_EQ(a.scans[k].scan.intensity, b.scans[k].scan.intensity);
    EXPECT_EQ(a.scans[k].scan.offset_ns, b.scans[k].scan.offset_ns);
  }
  Scenario other = sc;
  other.seed = sc.seed + 1;
  const Collect c = run(Simulation(other), 0.25);
  ASSERT_FALSE(c.scans.empty());
  EXPECT_NE(a.scans[1].scan.x, c.scans[1].scan.x);
}

TEST(Physics, ScanPhaseSetsWhereSweepsStart) {
  // Phase 33°: the rotor passes 0° (the sweep cut) (360 − 33)/3600 s after every tenth of a second.
  const Simulation sim(test::movingLidar("VLP-16", 5, 0, 0.02, 0.0));
  const Collect c = run(sim, 0.35);
  ASSERT_GE(c.scans.size(), 3u);
  for (std::size_t k = 1; k < c.scans.size(); ++k) {
    // The first point comes from the first firing after the crossing: within a firing period plus
    // the delay of the first beam with a return.
    const double after_tenth = double(c.scans[k].scan.stamp_ns % (100 * kNsPerMs)) * 1e-9;
    EXPECT_GE(after_tenth, (360.0 - 33.0) / 3600.0) << "sweep " << k;
    EXPECT_LE(after_tenth, (360.0 - 33.0) / 3600.0 + 100e-6) << "sweep " << k;
  }
}

TEST(Physics, OutageSilencesTheSensorAndEndsTheSweep) {
  Scenario sc = test::movingLidar("VLP-16", 5, 0, 0.02, 0.0);
  sc.sensors[0].outages = {{0.15, 0.32}};
  const Simulation sim(sc);
  const Collect c = run(sim, 0.6);
  for (const auto& b : c.batches)
    for (const auto& f : b.firings) {
      const double rel = toSeconds(f.true_time_ns - sim.startTime());
      ASSERT_FALSE(rel >= 0.15 && rel < 0.32) << rel;
    }
  bool gap = false;
  for (const auto& s : c.scans) {
    const double begin = toSeconds(s.true_time_ns.front() - sim.startTime());
    const double end = toSeconds(s.true_time_ns.back() - sim.startTime());
    EXPECT_FALSE(begin < 0.15 && end >= 0.32) << "no sweep spans the outage";
    gap |= std::abs(end - 0.15) < 0.001;
  }
  EXPECT_TRUE(gap) << "a sweep ends where the outage starts";
}

}  // namespace
}  // namespace rigcal::sim
