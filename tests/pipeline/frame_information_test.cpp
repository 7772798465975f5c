// Frame ranking by registration information (issue 19): a frame whose planes leave a translation free is
// ranked below a frame that constrains it, however much more PCA spread it has.
#include <gtest/gtest.h>

#include "rigcal/pipeline/frame_information.hpp"
#include "rigcal/pipeline/frame_selector.hpp"

namespace rigcal::pipeline {
namespace {

constexpr double kStep = 0.3;  // m between synthetic points: above the 0.25 m thinning, so all are kept

void addPlane(Scan& s, const Eigen::Vector3d& origin, const Eigen::Vector3d& u, const Eigen::Vector3d& v, double lu,
              double lv) {
  for (double a = 0; a <= lu; a += kStep)
    for (double b = 0; b <= lv; b += kStep) {
      const Eigen::Vector3d p = origin + a * u + b * v;
      s.push_back(Point{float(p.x()), float(p.y()), float(p.z()), 0, 0, 0, 0});
    }
}

/// Ground and two long walls facing along x: nothing stops a slide along y. The walls' height sets the spread.
Scan corridor(double half_width, double wall_height = 6) {
  Scan s;
  const Eigen::Vector3d X = Eigen::Vector3d::UnitX(), Y = Eigen::Vector3d::UnitY(), Z = Eigen::Vector3d::UnitZ();
  addPlane(s, {-half_width, -20, -2}, X, Y, 2 * half_width, 40);
  addPlane(s, {-half_width, -20, -2}, Y, Z, 40, wall_height);
  addPlane(s, {half_width, -20, -2}, Y, Z, 40, wall_height);
  return s;
}

/// Ground, a wall facing x and a wall facing y: every direction held, over a smaller extent.
Scan corner() {
  Scan s;
  const Eigen::Vector3d X = Eigen::Vector3d::UnitX(), Y = Eigen::Vector3d::UnitY(), Z = Eigen::Vector3d::UnitZ();
  addPlane(s, {-6, -6, -2}, X, Y, 14, 14);
  addPlane(s, {8, -6, -2}, Y, Z, 14, 4);
  addPlane(s, {-6, 8, -2}, X, Z, 14, 4);
  return s;
}

TEST(FrameInformation, ACorridorLeavesTheTranslationAlongItFree) {
  const auto free_y = frameInformation(corridor(10));
  const auto held = frameInformation(corner());
  ASSERT_GT(free_y.correspondences, 1000u);
  EXPECT_LT(free_y.weakestTranslationShare(), 0.01) << "no plane faces y";
  EXPECT_GT(held.weakestTranslationShare(), 0.05);
  EXPECT_GT(held.weakestRelative(), 10 * free_y.weakestRelative());
  EXPECT_EQ(frameInformation(Scan{}).correspondences, 0u);
}

TEST(FrameInformation, GreedySelectionPrefersTheFrameThatHoldsTheWeakDirectionOverMorePcaSpread) {
  const Scan wide = corridor(10, 8), narrower = corridor(10, 6), small = corner();
  ASSERT_GT(pcaInformation(wide), pcaInformation(narrower));
  ASSERT_GT(pcaInformation(narrower), pcaInformation(small)) << "the corner has the least PCA spread";
  std::vector<SelectionCandidate> c = {
      {0, 0, 0.0, pcaInformation(wide), frameInformation(wide)},
      {1, 10, 10.0, pcaInformation(narrower), frameInformation(narrower)},
      {2, 20, 20.0, pcaInformation(small), frameInformation(small)},
  };
  config::Parameters p;
  p.calibration_min_pca_eigenvalue = 0.0;
  p.lidar_calibration_max_frames = 2;

  p.calibration_frame_ranking = "pca";
  const Selection by_pca = selectFrames(c, {}, p);
  EXPECT_EQ(by_pca.selected, (std::vector<std::size_t>{0, 1})) << "PCA takes both corridors";

  p.calibration_frame_ranking = "information";
  const Selection by_information = selectFrames(c, {}, p);
  ASSERT_EQ(by_information.selected.size(), 2u);
  EXPECT_EQ(by_information.selected[0], 2u) << "the corner alone holds all six directions";
  EXPECT_EQ(by_information.rejected.size(), 1u);
}

TEST(FrameInformation, GreedySelectionComplementsTheFramesAlreadyChosen) {
  // Two corridors at right angles each leave one translation free; together they hold both. A third corridor
  // like the first has more PCA spread but adds nothing the first lacks.
  const Scan along_y = corridor(10, 6), along_y_wider = corridor(10, 8);
  Scan along_x = corridor(10);
  for (std::size_t i = 0; i < along_x.size(); ++i) std::swap(along_x.x[i], along_x.y[i]);
  std::vector<SelectionCandidate> c = {
      {0, 0, 0.0, pcaInformation(along_y_wider), frameInformation(along_y_wider)},
      {1, 10, 10.0, pcaInformation(along_y), frameInformation(along_y)},
      {2, 20, 20.0, pcaInformation(along_x), frameInformation(along_x)},
  };
  config::Parameters p;
  p.calibration_min_pca_eigenvalue = 0.0;
  p.lidar_calibration_max_frames = 2;
  const Selection s = selectFrames(c, {}, p);
  ASSERT_EQ(s.selected.size(), 2u);
  EXPECT_TRUE(s.selected[0] == 2u || s.selected[1] == 2u) << "the crossing corridor completes the other";
}

}  // namespace
}  // namespace rigcal::pipeline
