#include <gtest/gtest.h>

#include "rigcal/pipeline/frame_selector.hpp"

namespace rigcal::pipeline {
namespace {

Scan grid(double sx, double sy, double sz) {
  Scan s;
  for (int i = 0; i < 10; ++i)
    for (int j = 0; j < 10; ++j)
      for (int k = 0; k < 10; ++k)
        s.push_back(Point{float(sx * i / 9), float(sy * j / 9), float(sz * k / 9), 0, 0, 0, 0});
  return s;
}

TEST(FrameSelector, PcaInformationIsSmallForPlanesAndLargeForVolumes) {
  EXPECT_NEAR(pcaInformation(grid(10, 10, 0)), 0.0, 1e-6);
  const double box = pcaInformation(grid(10, 10, 3));
  EXPECT_GT(box, 0.9);  // uniform grid over 3 m: σ ≈ 1.05 m
  EXPECT_LT(box, 1.2);
  EXPECT_EQ(pcaInformation(Scan{}), 0.0);
}

TEST(FrameSelector, ExcludesLostNeighbourhoodFlatFramesSpacingAndBudget) {
  config::Parameters p;
  p.lidar_calibration_max_frames = 3;
  std::vector<SelectionCandidate> c;
  for (int k = 0; k < 40; ++k) c.push_back({std::size_t(k), k, 1.0 * k, 0.3 + 0.01 * (k % 7), {}});
  c[25].information = 0.1;  // too flat
  const Selection s = selectFrames(c, {5}, p);
  ASSERT_EQ(s.selected.size(), 3u);
  EXPECT_TRUE(s.budgetFull(p));
  for (std::size_t a = 0; a < s.selected.size(); ++a) {
    EXPECT_GT(int(s.selected[a]), 15) << "keyframes 0..15 are within 10 of lost keyframe 5";
    EXPECT_NE(s.selected[a], 25u);
    for (std::size_t b = a + 1; b < s.selected.size(); ++b)
      EXPECT_GE(std::abs(c[s.selected[a]].path_length - c[s.selected[b]].path_length), 5.0);
  }
  EXPECT_EQ(s.selected.size() + s.rejected.size(), c.size()) << "every candidate is accounted for";
  for (const auto& r : s.rejected) EXPECT_FALSE(r.reason.empty());
  // The most informative frame (k % 7 == 6) after keyframe 15 is chosen first.
  EXPECT_EQ(s.selected[0], 20u);
}

TEST(FrameSelector, DeterministicAndReportsShortfall) {
  config::Parameters p;
  std::vector<SelectionCandidate> c = {{0, 0, 0.0, 0.5, {}}, {1, 1, 1.0, 0.5, {}}};
  const Selection a = selectFrames(c, {}, p), b = selectFrames(c, {}, p);
  EXPECT_EQ(a.selected, b.selected);
  EXPECT_EQ(a.selected, std::vector<std::size_t>{0});  // tie broken by id, 1 is too close
  EXPECT_FALSE(a.enough(p));
}

}  // namespace
}  // namespace rigcal::pipeline
