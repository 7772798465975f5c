#include "rigcal/calib/lidar_pose/lidar_pose_calibration.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <exception>
#include <stdexcept>

#include <nlopt.hpp>

#include "rigcal/calib/lidar_pose/lidar_pose_objective.hpp"

namespace rigcal::calib {
namespace {

using Clock = std::chrono::steady_clock;
double secondsSince(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

// Full parameter vector: x, y, z (translation of T_pose_lidar), δ (rotation vector of the rotation
// applied on the left of the stage's base rotation: R = exp(δ)·R_base), time offset.
using Params = std::array<double, kLidarPoseParams>;
constexpr std::size_t kTime = 6;

Pose toPose(const Params& p, const Eigen::Matrix3d& R_base) {
  Pose T = Pose::Identity();
  T.linear() = expSO3(Eigen::Vector3d(p[3], p[4], p[5])) * R_base;
  T.translation() = Eigen::Vector3d(p[0], p[1], p[2]);
  return T;
}

// One NLopt run over the free subset of the parameters; the others stay at `base`.
struct Stage {
  LidarPoseObjective* objective = nullptr;
  Params base{};
  Eigen::Matrix3d R_base = Eigen::Matrix3d::Identity();
  std::vector<std::size_t> free;
  double max_dist_sq = 1.0;
  nlopt::opt* opt = nullptr;
  std::exception_ptr error;
  std::size_t evaluations = 0;

  [[nodiscard]] Params full(const double* x) const {
    Params p = base;
    for (std::size_t k = 0; k < free.size(); ++k) p[free[k]] = x[k];
    return p;
  }

  static double cost(unsigned, const double* x, double*, void* data) {
    auto* s = static_cast<Stage*>(data);
    try {
      ++s->evaluations;
      const Params p = s->full(x);
      return s->objective->evaluate(toPose(p, s->R_base), p[kTime], s->max_dist_sq);
    } catch (...) {  // NLopt's wrapper would replace the message with "nlopt failure"
      s->error = std::current_exception();
      s->opt->force_stop();
      return HUGE_VAL;
    }
  }

  // Minimises from `base` within [lower, upper] (full vectors); returns the best full vector.
  Params run(nlopt::algorithm algorithm, const Params& lower, const Params& upper, int max_evals,
             double xtol, double* best_cost, std::string* status) {
    nlopt::opt o(algorithm, static_cast<unsigned>(free.size()));
    opt = &o;
    std::vector<double> lb, ub, x;
    for (std::size_t i : free) {
      lb.push_back(lower[i]);
      ub.push_back(upper[i]);
      x.push_back(std::clamp(base[i], lower[i], upper[i]));
    }
    o.set_lower_bounds(lb);
    o.set_upper_bounds(ub);
    o.set_maxeval(max_evals);
    o.set_xtol_abs(xtol);
    o.set_min_objective(&Stage::cost, this);
    double f = HUGE_VAL;
    try {
      *status = nlopt_result_to_string(static_cast<nlopt_result>(o.optimize(x, f)));
    } catch (const nlopt::roundoff_limited&) {  // x still holds the best point found
      *status = "ROUNDOFF_LIMITED";
    } catch (const nlopt::forced_stop&) {
      if (error) std::rethrow_exception(error);
      throw;
    }
    *best_cost = f;
    return full(x.data());
  }
};

}  // namespace

LidarPoseResult calibrateLidarPose(LidarPoints points, const PoseTrajectory& trajectory,
                                   const LidarPoseSettings& settings) {
  const auto t_start = Clock::now();
  LidarPoseResult result;
  const double max_offset = std::abs(settings.max_time_offset);
  const double initial_offset = settings.time_cal
                                    ? std::clamp(settings.initial_time_offset_s, -max_offset, max_offset)
                                    : settings.initial_time_offset_s;
  const double margin = settings.time_cal ? max_offset : std::abs(initial_offset);
  restrictToTrajectory(points, trajectory, margin, std::max<std::size_t>(2, settings.min_points));
  const auto [t_first, t_last] = std::minmax_element(points.time_ns.begin(), points.time_ns.end());
  result.observability = assessObservability(trajectory, *t_first, *t_last, settings.observability);
  for (std::size_t i = 0; i < kLidarPoseParams; ++i)
    result.held[i] = settings.hold_poorly_constrained && result.observability.poorly_constrained[i];
  if (!settings.time_cal) result.held[kTime] = true;
  result.select_seconds = secondsSince(t_start);

  LidarPoseObjective objective(points, trajectory, settings.threads);
  Params initial{};
  const Eigen::Vector3d t0 = settings.initial_T_pose_lidar.translation();
  initial = {t0.x(), t0.y(), t0.z(), 0.0, 0.0, 0.0, initial_offset};
  const Eigen::Matrix3d R0 = settings.initial_T_pose_lidar.linear();
  result.initial_cost = objective.evaluate(toPose(initial, R0), initial_offset, settings.local_knn_max_dist);

  // Stage 1: rotation only, ±π around the initial rotation.
  Eigen::Matrix3d R_global = R0;
  const auto t_global = Clock::now();
  Stage global;
  global.objective = &objective;
  global.base = initial;
  global.R_base = R0;
  global.max_dist_sq = settings.global_knn_max_dist;
  for (std::size_t i = 3; i < 6; ++i)
    if (!result.held[i]) global.free.push_back(i);
  if (!settings.local && !global.free.empty()) {
    Params lower = initial, upper = initial;
    for (std::size_t i = 3; i < 6; ++i) {
      lower[i] = -M_PI;
      upper[i] = M_PI;
    }
    const Params best = global.run(nlopt::GN_DIRECT_L, lower, upper, settings.max_evals, settings.xtol,
                                   &result.global_cost, &result.global_status);
    R_global = toPose(best, R0).linear();
    result.global_evaluations = global.evaluations;
  }
  result.global_seconds = secondsSince(t_global);
  result.global_T_pose_lidar = toPose(initial, R_global);

  // Stage 2: everything not held, around the global result.
  const auto t_local = Clock::now();
  Stage local;
  local.objective = &objective;
  local.base = initial;
  local.R_base = R_global;
  local.max_dist_sq = settings.local_knn_max_dist;
  for (std::size_t i = 0; i < kLidarPoseParams; ++i)
    if (!result.held[i]) local.free.push_back(i);
  Params best = initial;
  if (local.free.empty()) {  // everything held: report the cost of the guess
    result.final_cost = objective.evaluate(toPose(initial, R_global), initial_offset,
                                           settings.local_knn_max_dist);
  } else {
    Params lower = initial, upper = initial;
    for (std::size_t i = 0; i < 3; ++i) {
      lower[i] = initial[i] - settings.translation_range;
      upper[i] = initial[i] + settings.translation_range;
      lower[i + 3] = -settings.angular_range;
      upper[i + 3] = settings.angular_range;
    }
    lower[kTime] = -max_offset;
    upper[kTime] = max_offset;
    // BOBYQA needs at least 2 variables; a single free one is searched with COBYLA.
    const auto algorithm = local.free.size() >= 2 ? nlopt::LN_BOBYQA : nlopt::LN_COBYLA;
    double cost = 0.0;
    if (settings.coarse_local_stage) {
      local.max_dist_sq = settings.global_knn_max_dist;
      local.base = local.run(algorithm, lower, upper, settings.max_evals, settings.xtol, &cost,
                             &result.coarse_status);
      result.coarse_evaluations = local.evaluations;
      local.max_dist_sq = settings.local_knn_max_dist;
    }
    best = local.run(algorithm, lower, upper, settings.max_evals, settings.xtol, &cost,
                     &result.local_status);
    result.final_cost = cost;
    result.local_evaluations = local.evaluations;
  }
  result.local_seconds = secondsSince(t_local);
  result.T_pose_lidar = toPose(best, R_global);
  result.time_offset_s = best[kTime];
  result.points = std::move(points);
  result.total_seconds = secondsSince(t_start);
  return result;
}

LidarPoseResult calibrateLidarPose(const std::vector<Scan>& scans, const PoseTrajectory& trajectory,
                                   const LidarPoseSettings& settings) {
  const auto t0 = Clock::now();
  LidarPoseResult r = calibrateLidarPose(selectLidarPoints(scans, settings.selection), trajectory, settings);
  const double select = secondsSince(t0) - r.total_seconds;
  r.select_seconds += select;
  r.total_seconds += select;
  return r;
}

}  // namespace rigcal::calib
