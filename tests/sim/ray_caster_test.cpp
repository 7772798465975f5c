#include <gtest/gtest.h>

#include <cmath>
#include <map>

#include "rigcal/sim/scene.hpp"
#include "rigcal/sim/simulation.hpp"
#include "sim_test_util.hpp"

namespace rigcal::sim {
namespace {

Ray ray(Eigen::Vector3d o, Eigen::Vector3d d) { return {o, d.normalized()}; }

Scene sceneWith(std::vector<Box> boxes, std::vector<Cylinder> cylinders = {}, std::vector<Ellipsoid> ellipsoids = {}) {
  SceneContent c;
  c.boxes = std::move(boxes);
  c.cylinders = std::move(cylinders);
  c.ellipsoids = std::move(ellipsoids);
  return Scene(std::move(c));
}

TEST(RayCaster, FlatGroundAtKnownDistance) {
  const Scene scene(SceneContent{});
  Hit hit;
  // From 2 m up, 30° below the horizon: the ground is 4 m away along the ray.
  ASSERT_TRUE(scene.cast(ray({0, 0, 2}, {std::cos(M_PI / 6), 0, -std::sin(M_PI / 6)}), 0, 100, hit));
  EXPECT_NEAR(hit.t, 4.0, 1e-9);
  EXPECT_NEAR(hit.normal.z(), 1.0, 1e-12);
  EXPECT_EQ(hit.material, Material::kAsphalt);
  EXPECT_FALSE(scene.cast(ray({0, 0, 2}, {1, 0, 0.01}), 0, 100, hit)) << "rising rays never meet the ground";
  EXPECT_FALSE(scene.cast(ray({0, 0, 2}, {1, 0, -0.01}), 0, 150, hit)) << "the ground is 200 m away";
  EXPECT_TRUE(scene.cast(ray({0, 0, 2}, {1, 0, -0.01}), 0, 250, hit));
  EXPECT_NEAR(hit.t, 2.0 * std::sqrt(1.0001) / 0.01, 1e-6);
}

TEST(RayCaster, SlopedBumpyGroundHitLiesOnTheSurface) {
  SceneContent c;
  c.ground = Ground(GroundSpec{0.3, {0.02, -0.01}, 0.05, 4.0}, 5);
  const Scene scene(std::move(c));
  Rng rng(1);
  int hits = 0;
  for (int i = 0; i < 2000; ++i) {
    const double el = rng.uniform(-0.6, -0.005), az = rng.uniform(0, 2 * M_PI);
    const Ray r = ray({rng.uniform(-20, 20), rng.uniform(-20, 20), 2.5},
                      {std::cos(el) * std::cos(az), std::cos(el) * std::sin(az), std::sin(el)});
    Hit hit;
    if (!scene.cast(r, 0, 400, hit)) continue;
    ++hits;
    const Eigen::Vector3d p = r.origin + hit.t * r.dir;
    EXPECT_NEAR(p.z(), scene.ground().height(p.x(), p.y()), 1e-7);
    // And it is the first crossing: halfway there the ray is still above the ground.
    const Eigen::Vector3d q = r.origin + 0.5 * hit.t * r.dir;
    EXPECT_GT(q.z(), scene.ground().height(q.x(), q.y()));
  }
  EXPECT_GT(hits, 1900);
}

TEST(RayCaster, BoxFaceAtKnownDistanceWithItsNormal) {
  // A 2 m cube centred 10 m ahead, rotated 30° about z: the ray along +x enters its −x-ish face.
  const Box b = Box::make(10, 0, M_PI / 6, 2, 2, 0, 2, Material::kBrick);
  const Scene scene = sceneWith({b});
  Hit hit;
  ASSERT_TRUE(scene.cast(ray({0, 0, 1}, {1, 0, 0}), 0, 100, hit));
  // The face is a plane 1 m from the centre with normal (−cos30°, −sin30°): x = 10 − 1/cos30°.
  EXPECT_NEAR(hit.t, 10 - 1 / std::cos(M_PI / 6), 1e-9);
  EXPECT_NEAR(hit.normal.x(), -std::cos(M_PI / 6), 1e-12);
  EXPECT_NEAR(hit.normal.y(), -std::sin(M_PI / 6), 1e-12);
  EXPECT_EQ(hit.material, Material::kBrick);
  // From above: the top face.
  ASSERT_TRUE(scene.cast(ray({10, 0, 5}, {0, 0, -1}), 0, 100, hit));
  EXPECT_NEAR(hit.t, 3.0, 1e-12);
  EXPECT_NEAR(hit.normal.z(), 1.0, 1e-12);
  // Passing beside it: the ground beyond.
  ASSERT_TRUE(scene.cast(ray({0, 3, 1}, {1, 0, -0.1}), 0, 100, hit));
  EXPECT_EQ(hit.material, Material::kAsphalt);
}

TEST(RayCaster, VerticalCylinderSideAndTop) {
  const Scene scene = sceneWith({}, {Cylinder{5, 1, 0.5, 0, 3, Material::kMetal}});
  Hit hit;
  // Aimed through the axis: hits at distance (centre − radius).
  const Eigen::Vector3d o(0, 1, 1);
  ASSERT_TRUE(scene.cast(ray(o, {1, 0, 0}), 0, 100, hit));
  EXPECT_NEAR(hit.t, 4.5, 1e-9);
  EXPECT_NEAR(hit.normal.x(), -1, 1e-9);
  // Off-axis by 0.3 m: chord geometry, t = 5 − sqrt(0.25 − 0.09).
  ASSERT_TRUE(scene.cast(ray({0, 1.3, 1}, {1, 0, 0}), 0, 100, hit));
  EXPECT_NEAR(hit.t, 5 - std::sqrt(0.25 - 0.09), 1e-9);
  // Over the top cap.
  ASSERT_TRUE(scene.cast(ray({5, 1.2, 10}, {0, 0, -1}), 0, 100, hit));
  EXPECT_NEAR(hit.t, 7.0, 1e-12);
  EXPECT_NEAR(hit.normal.z(), 1.0, 1e-12);
  // Above the top: misses the cylinder.
  EXPECT_FALSE(scene.cast(ray({0, 1, 3.5}, {1, 0, 0}), 0, 100, hit));
}

TEST(RayCaster, EllipsoidCrown) {
  const Scene scene = sceneWith({}, {}, {Ellipsoid{0, 10, 5, 2, 3, Material::kFoliage}});
  Hit hit;
  ASSERT_TRUE(scene.cast(ray({0, 0, 5}, {0, 1, 0}), 0, 100, hit));
  EXPECT_NEAR(hit.t, 8.0, 1e-9);
  ASSERT_TRUE(scene.cast(ray({0, 10, 20}, {0, 0, -1}), 0, 100, hit));
  EXPECT_NEAR(hit.t, 12.0, 1e-9);  // top of the crown at z = 8
  EXPECT_NEAR(hit.normal.z(), 1.0, 1e-9);
}

TEST(RayCaster, OcclusionReturnsTheNearestHit) {
  // Three objects on one line, listed far to near, spanning many grid cells: the nearest wins.
  const Scene scene = sceneWith({Box::make(30, 0, 0, 1, 6, 0, 3, Material::kConcrete),
                                 Box::make(12, 0, 0.2, 1, 1, 0, 3, Material::kMetal)},
                                {Cylinder{20, 0, 0.3, 0, 3, Material::kBark}});
  Hit hit;
  ASSERT_TRUE(scene.cast(ray({0, 0, 1.5}, {1, 0, 0}), 0, 100, hit));
  EXPECT_EQ(hit.material, Material::kMetal);
  EXPECT_LT(hit.t, 12.0);
  ASSERT_TRUE(scene.cast(ray({15, 0, 1.5}, {1, 0, 0}), 0, 100, hit));
  EXPECT_EQ(hit.material, Material::kBark);
  EXPECT_NEAR(hit.t, 4.7, 1e-9);
}

TEST(RayCaster, GridAgreesWithBruteForceOnTheGeneratedScene) {
  // The acceleration structure must not change any answer: compare with testing every primitive.
  const Simulation sim(test::movingLidar("VLP-16", 5, 0, 0, 0));
  const Scene& scene = sim.scene();
  const SceneContent& c = scene.content();
  Rng rng(2);
  int disagreements = 0, object_hits = 0;
  for (int i = 0; i < 4000; ++i) {
    const double el = rng.uniform(-0.4, 0.3), az = rng.uniform(0, 2 * M_PI);
    const Ray r = ray({rng.uniform(-50, 50), rng.uniform(-40, 40), rng.uniform(0.5, 3.0)},
                      {std::cos(el) * std::cos(az), std::cos(el) * std::sin(az), std::sin(el)});
    Hit fast;
    const bool got = scene.cast(r, 0, 150, fast);
    Hit brute;
    brute.t = 150;
    bool any = c.ground.intersect(r, 0, brute);
    for (const auto& b : c.boxes) any |= intersect(b, r, 0, brute);
    for (const auto& cy : c.cylinders) any |= intersect(cy, r, 0, brute);
    for (const auto& e : c.ellipsoids) any |= intersect(e, r, 0, brute);
    if (got != any || (got && std::abs(fast.t - brute.t) > 1e-9)) ++disagreements;
    object_hits += got && fast.normal.z() < 0.9;
  }
  EXPECT_EQ(disagreements, 0);
  EXPECT_GT(object_hits, 400) << "the scene should be feature-rich";
}

}  // namespace
}  // namespace rigcal::sim

namespace rigcal::sim {
namespace {

TEST(SceneGenerator, LayoutsHoldEveryKindOfObject) {
  for (const std::string name : {"parking-lot", "street"}) {
    const Simulation sim(loadScenario(name));
    const SceneContent& c = sim.scene().content();
    std::map<Material, int> boxes, cylinders, patches;
    for (const auto& b : c.boxes) ++boxes[b.material];
    for (const auto& y : c.cylinders) ++cylinders[y.material];
    for (const auto& p : c.patches) ++patches[p.material];
    EXPECT_GT(boxes[Material::kGlass], 2) << name << ": buildings (glass cores behind window recesses)";
    EXPECT_GT(boxes[Material::kBrick] + boxes[Material::kPlaster], 50) << name << ": facade pillars and bands";
    EXPECT_GT(boxes[Material::kTyre], 20) << name << ": parked cars";
    EXPECT_GT(boxes[Material::kCurbStone], 5) << name << ": curbs";
    EXPECT_GT(boxes[Material::kRetroReflector], 0) << name << ": signs";
    EXPECT_GT(int(c.ellipsoids.size()), 5) << name << ": trees";
    EXPECT_GT(cylinders[Material::kMetal] + cylinders[Material::kConcrete], 5) << name << ": poles and bollards";
    EXPECT_GT(patches[Material::kRoadPaint], 5) << name << ": road paint";
    // The ground is sloped and bumpy.
    const Ground& g = c.ground;
    EXPECT_GT(g.spec().slope.norm(), 0.005) << name;
    double lo = 1e9, hi = -1e9;
    for (double x = -20; x <= 20; x += 0.5) {
      const double r = g.height(x, 3.0) - (g.spec().base_height + g.spec().slope.x() * x + g.spec().slope.y() * 3.0);
      lo = std::min(lo, r);
      hi = std::max(hi, r);
    }
    EXPECT_GT(hi - lo, 0.02) << name << ": bumps";
  }
}

// The container yard (issue 19's unusual-mount presets): stacks up to four containers high, stepped ramps
// rising to docks, and a sloped ground, so a tilted or sideways lidar sees walls above and below itself.
TEST(SceneGenerator, ContainerYardHasStacksRampsAndSlope) {
  const Simulation sim(loadScenario("yard-corners"));
  const SceneContent& c = sim.scene().content();
  const Ground& g = c.ground;
  int containers = 0, high_tiers = 0, ramp_steps = 0;
  for (const auto& b : c.boxes) {
    const double ground = g.height(b.cx, b.cy);
    if (b.material == Material::kMetal && b.z1 - b.z0 > 2.5) {
      ++containers;
      if (b.z0 - ground > 5.0) ++high_tiers;  // third tier or above
    }
    if (b.material == Material::kConcrete && b.hx == 0.25 && b.z1 - ground > 0.3) ++ramp_steps;
  }
  EXPECT_GT(containers, 60);
  EXPECT_GT(high_tiers, 5) << "stacks three or four high";
  EXPECT_GT(ramp_steps, 16) << "at least two ramps";
  EXPECT_GT(g.spec().slope.norm(), 0.025) << "3 % slope";
}

TEST(SceneGenerator, NothingStandsOnThePath) {
  const Simulation sim(loadScenario("parking-lot"));
  const double clearance = sim.scenario().scene.clearance_m;
  for (const auto& p : sim.trajectory().path(0.5)) {
    for (const auto& b : sim.scene().content().boxes) {
      const Rect2 r = footprint(b);
      const double dx = std::max({r.x0 - p.x(), 0.0, p.x() - r.x1}), dy = std::max({r.y0 - p.y(), 0.0, p.y() - r.y1});
      ASSERT_GE(std::hypot(dx, dy), clearance - 1e-9);
    }
  }
}

}  // namespace
}  // namespace rigcal::sim
