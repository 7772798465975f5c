// The solver stops when its iterates go round a cycle (private: registration/src/solver.hpp and
// iterate_cycle.hpp). The objective here is scripted: its "matches" at each of a few positions along x
// send the pose to the next position, as two or three sets of ICP matches can take turns near an optimum.
#include <gtest/gtest.h>

#include <cmath>
#include <cstddef>
#include <vector>

#include "iterate_cycle.hpp"
#include "solver.hpp"

namespace rigcal::registration::detail {
namespace {

class TakingTurns final : public Objective {
 public:
  /// At positions[k] (x, metres) the matches lead to positions[k + 1] (cyclically) and cost costs[k].
  TakingTurns(std::vector<double> positions, std::vector<double> costs)
      : positions_(std::move(positions)), costs_(std::move(costs)) {}

  std::optional<LinearSystem> linearize(const Pose& T, const Deadline&) override {
    const std::size_t k = nearest(T.translation().x());
    const Eigen::Vector3d goal(positions_[(k + 1) % positions_.size()], 0.0, 0.0);
    LinearSystem sys;
    sys.H.setIdentity();
    sys.b.head<3>() = T.translation() - goal;  // cost ½|t − goal|² for these matches
    sys.cost = costs_[k];
    sys.inliers = 1000;
    ++linearizations;
    return sys;
  }
  std::optional<double> cost(const Pose&, const Deadline&, bool) override { return 0.0; }  // lands on the goal

  std::size_t linearizations = 0;

 private:
  std::size_t nearest(double x) const {
    std::size_t best = 0;
    for (std::size_t k = 1; k < positions_.size(); ++k) {
      if (std::abs(positions_[k] - x) < std::abs(positions_[best] - x)) best = k;
    }
    return best;
  }
  std::vector<double> positions_;
  std::vector<double> costs_;
};

SolverParams calibrationEnsembleSettings() {
  SolverParams p;
  p.max_iterations = 200;
  p.transformation_epsilon = 1e-5;
  p.rotation_epsilon = 1e-6;
  return p;
}

TEST(IterateCycle, TwoSetsOfMatchesTakingTurnsEndTheSolveAsSoonAsThePoseIsBack) {
  TakingTurns objective({0.0, 2e-4}, {1.0, 1.0});  // steps 20x the epsilon, back and forth
  const SolveOutcome out = solve(objective, Pose::Identity(), calibrationEnsembleSettings(), Deadline{});
  EXPECT_EQ(out.status, Status::kConverged);
  EXPECT_TRUE(out.converged);
  EXPECT_EQ(objective.linearizations, 3U);  // at 0, at 2e-4, and at 0 again: a cycle
  EXPECT_NEAR(out.T.translation().x(), 0.0, 1e-9);
}

TEST(IterateCycle, ACycleEndsAtItsCheapestPose) {
  // Three positions visited in turn, the middle one cheapest: the result is there, whichever pose closed it.
  TakingTurns objective({0.0, 1e-3, 2e-3}, {3.0, 1.0, 2.0});
  const SolveOutcome out = solve(objective, Pose::Identity(), calibrationEnsembleSettings(), Deadline{});
  EXPECT_EQ(out.status, Status::kConverged);
  EXPECT_EQ(objective.linearizations, 4U);
  EXPECT_NEAR(out.T.translation().x(), 1e-3, 1e-9);
}

TEST(IterateCycle, ACycleLongerThanItWatchesRunsToTheIterationLimit) {
  std::vector<double> positions;
  for (std::size_t k = 0; k <= IterateCycle::kMaxPeriod; ++k) positions.push_back(1e-3 * static_cast<double>(k));
  TakingTurns objective(positions, std::vector<double>(positions.size(), 1.0));
  SolverParams p = calibrationEnsembleSettings();
  p.max_iterations = 40;
  const SolveOutcome out = solve(objective, Pose::Identity(), p, Deadline{});
  EXPECT_EQ(out.status, Status::kMaxIterations);
  EXPECT_EQ(out.iterations, 40);
}

TEST(IterateCycle, AnIterateCloseToAnEarlierOneButNotWithinTheEpsilonsIsNoCycle) {
  IterateCycle cycle;
  const SolverParams p = calibrationEnsembleSettings();
  const auto at = [](double x) { return Pose(Eigen::Translation3d(x, 0.0, 0.0)); };
  EXPECT_FALSE(cycle.closes(at(0.0), 1.0, p));
  EXPECT_FALSE(cycle.closes(at(1e-3), 1.0, p));
  EXPECT_FALSE(cycle.closes(at(2e-5), 1.0, p));  // 2e-5 m from the first: still moving
  EXPECT_TRUE(cycle.closes(at(1e-3 + 5e-6), 0.5, p));  // 5e-6 m from the second: round
  EXPECT_NEAR(cycle.best().translation().x(), 1e-3 + 5e-6, 1e-12);  // the newest is the cheapest
}

}  // namespace
}  // namespace rigcal::registration::detail
