#include "rigcal/calib/lidar_lidar/trajectory_time_offset.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <map>
#include <numeric>
#include <stdexcept>
#include <sstream>
#include <utility>

#include <Eigen/Cholesky>
#include <Eigen/Geometry>

#include "rigcal/calib/lidar_lidar/calibration_deskew.hpp"
#include "rigcal/core/parallel.hpp"

namespace rigcal::calib {
namespace {

using Matrix6d = Eigen::Matrix<double, 6, 6>;

struct FrameData {
  const registration::Target* target = nullptr;
  std::vector<Eigen::Vector4d> points;  // every k-th source point
  std::vector<std::uint32_t> hints;     // last match per point: speeds the next search up
  Pose T_at_stamp_inv = Pose::Identity();  // mapping pose at the stamp, inverted (the target's frame)
  TimeNs stamp_ns = 0;
};

struct Pass {
  Matrix6d H = Matrix6d::Zero();
  Vector6d g = Vector6d::Zero();
  std::vector<double> frame_cost;  // Σ min(r², c²) per frame

  Pass& operator+=(const Pass& o) {
    H += o.H;
    g += o.g;
    frame_cost.resize(std::max(frame_cost.size(), o.frame_cost.size()), 0.0);
    for (std::size_t k = 0; k < o.frame_cost.size(); ++k) frame_cost[k] += o.frame_cost[k];
    return *this;
  }
};

/// Point-to-plane residuals of every frame's points under D_k·T (D_k: the frame's mapping pose moved by
/// the trial offset), their Gauss-Newton system in T's own tangent (ω, v) and the truncated costs. Pieces
/// of `kPiece` points of a frame are the parallel tasks, added in order: the same sums for any thread count.
Pass linearise(std::vector<FrameData>& frames, const std::vector<Pose>& D, const Pose& T, double max_distance,
               int num_threads) {
  constexpr std::size_t kPiece = 512;
  struct Piece {
    std::size_t frame = 0, begin = 0, end = 0;
  };
  std::vector<Piece> pieces;
  for (std::size_t k = 0; k < frames.size(); ++k)
    for (std::size_t b = 0; b < frames[k].points.size(); b += kPiece)
      pieces.push_back({k, b, std::min(frames[k].points.size(), b + kPiece)});
  const double c2 = max_distance * max_distance;
  Pass init;
  init.frame_cost.assign(frames.size(), 0.0);
  return parallelReduce(pieces.size(), num_threads, std::move(init), [&](std::size_t t) {
    const Piece& piece = pieces[t];
    FrameData& f = frames[piece.frame];
    Pass pass;
    pass.frame_cost.assign(piece.frame + 1, 0.0);
    double& cost = pass.frame_cost[piece.frame];
    const Pose A = D[piece.frame] * T;
    const Eigen::Matrix3d At = A.linear().transpose();
    const auto& cloud = f.target->cloud();
    for (std::size_t i = piece.begin; i < piece.end; ++i) {
      const Eigen::Vector3d p = f.points[i].head<3>();
      Eigen::Vector4d q;
      q << A * p, 1.0;
      registration::Neighbor nb;
      if (!f.target->tree().nearest(q, c2, &nb, f.hints[i])) {
        cost += c2;
        continue;
      }
      f.hints[i] = nb.index;
      const Eigen::Vector3d n = f.target->normal(nb.index);
      const Eigen::Vector3d d = q.head<3>() - cloud.points[nb.index].head<3>();
      if (n.squaredNorm() < 0.5) {  // no normal there: the point distance, not fitted
        cost += std::min(d.squaredNorm(), c2);
        continue;
      }
      const double r = n.dot(d);
      cost += std::min(r * r, c2);
      const Eigen::Vector3d nl = At * n;
      Vector6d J;
      J << p.cross(nl), nl;
      pass.H.noalias() += J * J.transpose();
      pass.g.noalias() += J * r;
    }
    return pass;
  });
}

/// T moved by the Gauss-Newton step of `pass` (damped: the system is near-singular along what the frames
/// do not constrain).
Pose step(const Pose& T, const Pass& pass) {
  Matrix6d H = pass.H;
  const double damping = 1e-6 * std::max(1.0, H.trace());
  H.diagonal().array() += damping;
  const Vector6d xi = -H.ldlt().solve(pass.g);
  if (!xi.allFinite()) return T;
  Pose delta = Pose::Identity();
  const double angle = xi.head<3>().norm();
  if (angle > 0) delta.linear() = Eigen::AngleAxisd(angle, xi.head<3>() / angle).toRotationMatrix();
  delta.translation() = xi.tail<3>();
  return T * delta;
}

double sum(const std::vector<double>& v) { return std::accumulate(v.begin(), v.end(), 0.0); }

/// The offset that minimises `cost` (indexed like `shifts`, sorted): the parabola's vertex through the
/// best trial and its neighbours, or the edge trial when the best is at an edge (`at_edge`).
struct Minimum {
  double offset_ms = 0.0, curvature = 0.0;
  bool at_edge = false;
};

Minimum minimumOf(const std::vector<double>& shifts, const std::vector<double>& cost) {
  const auto best = std::size_t(std::min_element(cost.begin(), cost.end()) - cost.begin());
  Minimum m;
  if (best == 0 || best + 1 == cost.size()) {
    m.offset_ms = shifts[best];
    m.at_edge = true;
    return m;
  }
  const auto [x, a] = parabolaVertex({shifts[best - 1], cost[best - 1]}, {shifts[best], cost[best]},
                                     {shifts[best + 1], cost[best + 1]});
  m.offset_ms = std::clamp(x, shifts[best - 1], shifts[best + 1]);
  m.curvature = a;
  return m;
}

}  // namespace

const char* toString(TrajectoryClockEstimate::Status s) {
  switch (s) {
    case TrajectoryClockEstimate::Status::kNotRun: return "not run";
    case TrajectoryClockEstimate::Status::kEstimated: return "estimated";
    case TrajectoryClockEstimate::Status::kUnobservable: return "unobservable";
    case TrajectoryClockEstimate::Status::kDeadline: return "not estimated (deadline)";
  }
  return "?";
}

double farthestDip(const std::vector<double>& shifts_ms, const std::vector<double>& cost, double offset_ms) {
  double farthest = 0.0;
  for (std::size_t s = 1; s + 1 < cost.size() && s + 1 < shifts_ms.size(); ++s)
    if (cost[s] < cost[s - 1] && cost[s] < cost[s + 1]) farthest = std::max(farthest, std::abs(shifts_ms[s] - offset_ms));
  return farthest;
}

std::pair<double, double> parabolaVertex(const std::pair<double, double>& p0, const std::pair<double, double>& p1,
                                         const std::pair<double, double>& p2) {
  const auto [x0, y0] = p0;
  const auto [x1, y1] = p1;
  const auto [x2, y2] = p2;
  // Divided differences: y = y0 + b·(x − x0) + a·(x − x0)(x − x1).
  const double d01 = (y1 - y0) / (x1 - x0), d12 = (y2 - y1) / (x2 - x1);
  const double a = (d12 - d01) / (x2 - x0);
  if (!(a > 0)) return {x1, a};
  // dy/dx = d01 + a·(2x − x0 − x1) = 0
  return {0.5 * (x0 + x1) - d01 / (2.0 * a), a};
}

TrajectoryClockEstimate estimateTrajectoryClockOffset(const std::vector<TrajectoryClockFrame>& input,
                                                      const std::vector<pipeline::MappingFrame>& trajectory,
                                                      const Pose& T_mapping_calib,
                                                      const registration::Deadline& deadline,
                                                      const TrajectoryClockOptions& options) {
  const auto t0 = std::chrono::steady_clock::now();
  TrajectoryClockEstimate out;
  const auto finish = [&]() -> TrajectoryClockEstimate {
    out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    return out;
  };
  std::size_t total = 0;
  for (const auto& f : input)
    if (f.source != nullptr && f.target != nullptr && f.target->hasNormals()) total += f.source->size();
  std::vector<FrameData> frames;
  const std::size_t stride = std::max<std::size_t>(1, total / std::max<std::size_t>(1, options.max_points));
  for (const auto& f : input) {
    if (f.source == nullptr || f.target == nullptr || !f.target->hasNormals() || f.target->empty()) continue;
    FrameData d;
    d.target = f.target;
    d.stamp_ns = f.stamp_ns;
    d.T_at_stamp_inv = mappingPoseAt(trajectory, f.stamp_ns).inverse();
    for (std::size_t i = 0; i < f.source->size(); i += stride) d.points.push_back(f.source->points[i]);
    d.hints.assign(d.points.size(), registration::KdTree::kNoHint);
    out.points += d.points.size();
    frames.push_back(std::move(d));
  }
  out.frames = frames.size();
  out.status = TrajectoryClockEstimate::Status::kUnobservable;
  if (frames.size() < 2) {
    out.note = "one frame: the extrinsic absorbs any clock offset (needs two or more)";
    return finish();
  }
  struct Trial {
    std::vector<double> frame_cost;
    Pose fitted;
  };
  std::map<double, Trial> trials;  // by trial offset (ms)
  const auto trial = [&](double ms, const Pose& start) {
    std::vector<Pose> D;
    const auto shift_ns = TimeNs(std::llround(ms * 1e6));
    for (const auto& f : frames) D.push_back(f.T_at_stamp_inv * mappingPoseAt(trajectory, f.stamp_ns - shift_ns));
    for (auto& f : frames) std::fill(f.hints.begin(), f.hints.end(), registration::KdTree::kNoHint);
    Trial t{{}, start};
    for (int it = 0;; ++it) {
      const Pass pass = linearise(frames, D, t.fitted, options.max_distance, options.num_threads);
      if (it == options.iterations) {
        t.frame_cost = pass.frame_cost;
        break;
      }
      t.fitted = step(t.fitted, pass);
    }
    trials[ms] = std::move(t);
  };
  const auto out_of_time = [&] {
    if (!deadline.expired()) return false;
    out.status = TrajectoryClockEstimate::Status::kDeadline;
    out.note = "the deadline left no time for every trial offset";
    for (const auto& [ms, t] : trials) out.profile.emplace_back(ms, sum(t.frame_cost) / double(out.points));
    return true;
  };
  std::vector<double> grid = options.shifts_ms;
  std::sort(grid.begin(), grid.end());
  grid.erase(std::unique(grid.begin(), grid.end()), grid.end());
  if (grid.size() < 3) throw std::invalid_argument("trajectory clock: fewer than three trial offsets");
  // From the trial nearest 0 outwards, each from its inner neighbour's fit.
  const auto centre = std::size_t(
      std::min_element(grid.begin(), grid.end(), [](double a, double b) { return std::abs(a) < std::abs(b); }) -
      grid.begin());
  if (out_of_time()) return finish();
  trial(grid[centre], T_mapping_calib);
  for (std::size_t s = centre + 1; s < grid.size(); ++s) {
    if (out_of_time()) return finish();
    trial(grid[s], trials.at(grid[s - 1]).fitted);
  }
  for (std::size_t s = centre; s-- > 0;) {
    if (out_of_time()) return finish();
    trial(grid[s], trials.at(grid[s + 1]).fitted);
  }
  std::vector<double> shifts;
  std::vector<std::vector<double>> frame_cost;
  const auto collect = [&] {
    shifts.clear();
    frame_cost.clear();
    for (const auto& [ms, t] : trials) {
      shifts.push_back(ms);
      frame_cost.push_back(t.frame_cost);
    }
  };
  // A minimum at the last trial: further out (doubling) until the cost rises or max_shift_ms.
  for (;;) {
    collect();
    std::vector<double> c;
    for (const auto& fc : frame_cost) c.push_back(sum(fc));
    const auto best = std::size_t(std::min_element(c.begin(), c.end()) - c.begin());
    if (best != 0 && best + 1 != c.size()) break;
    const double edge = shifts[best];
    if (std::abs(edge) >= options.max_shift_ms || edge == 0.0) break;
    if (out_of_time()) return finish();
    trial(std::clamp(2.0 * edge, -options.max_shift_ms, options.max_shift_ms), trials.at(edge).fitted);
  }
  const double zero_cost = sum(trials.at(grid[centre]).frame_cost);
  // One more trial at the parabola's vertex, so that the final parabola rests on close samples (the
  // doubling leaves 20 / 50 / 100 ms, and the cost is not a parabola that far out).
  {
    std::vector<double> c;
    for (const auto& fc : frame_cost) c.push_back(sum(fc));
    const Minimum m = minimumOf(shifts, c);
    const auto nearest = std::min_element(shifts.begin(), shifts.end(), [&](double a, double b) {
      return std::abs(a - m.offset_ms) < std::abs(b - m.offset_ms);
    });
    if (!m.at_edge && m.curvature > 0 && std::abs(*nearest - m.offset_ms) > 2.0) {
      if (out_of_time()) return finish();
      const double at = std::round(m.offset_ms);
      trial(at, trials.at(*nearest).fitted);
      collect();
    }
  }
  std::vector<double> cost(shifts.size());
  for (std::size_t s = 0; s < shifts.size(); ++s) {
    cost[s] = sum(frame_cost[s]);
    out.profile.emplace_back(shifts[s], cost[s] / double(out.points));
  }
  const Minimum all = minimumOf(shifts, cost);
  // Leave one frame out: how much the estimate rests on single frames.
  std::vector<double> jack;
  bool jack_edge = false;
  if (frames.size() >= 3)
    for (std::size_t k = 0; k < frames.size(); ++k) {
      std::vector<double> c(shifts.size());
      for (std::size_t s = 0; s < shifts.size(); ++s) c[s] = cost[s] - frame_cost[s][k];
      const Minimum m = minimumOf(shifts, c);
      jack_edge = jack_edge || m.at_edge != all.at_edge || (m.at_edge && m.offset_ms != all.offset_ms);
      jack.push_back(m.offset_ms);
    }
  double sigma_jack = 0.0;
  if (!jack.empty()) {
    const double n = double(jack.size());
    const double mean = std::accumulate(jack.begin(), jack.end(), 0.0) / n;
    double ss = 0.0;
    for (const double d : jack) ss += (d - mean) * (d - mean);
    sigma_jack = std::sqrt((n - 1.0) / n * ss);
  }
  std::ostringstream note;
  note.setf(std::ios::fixed);
  note.precision(1);
  if (all.at_edge) {
    // Beyond the trials: a number only when every frame subset agrees and the fit is clearly better there.
    const double gain = 1.0 - cost[all.offset_ms < 0 ? 0 : shifts.size() - 1] / zero_cost;
    if (jack_edge || frames.size() < 3 || gain < 0.02) {
      note << "the cost falls towards the last trial (" << std::showpos << all.offset_ms << std::noshowpos
           << " ms) but not in every subset of frames";
      out.note = note.str();
      return finish();
    }
    out.status = TrajectoryClockEstimate::Status::kEstimated;
    out.offset_ms = all.offset_ms;
    out.uncertainty_ms = 0.0;
    note << "at least " << std::abs(all.offset_ms) << " ms (the last trial; every frame subset agrees, cost "
         << 100.0 * gain << " % below 0 ms)";
    out.note = note.str();
    return finish();
  }
  if (!(all.curvature > 0)) {
    out.note = "the cost is flat in the offset: frames without turning or speed change";
    return finish();
  }
  const double residual = cost[std::size_t(std::min_element(cost.begin(), cost.end()) - cost.begin())] /
                          double(out.points);
  // Least squares: var(δ) = 2σ²/S'' with σ² the residual per point. Neighbouring points share the map's
  // errors, so only so many residuals per frame count as independent (a flat profile on two frames gave
  // −35 ± 7.7 ms with every point counted).
  const double independent =
      std::min(double(out.points), options.independent_points_per_frame * double(frames.size()));
  const double sigma_curvature = std::sqrt(residual * double(out.points) / (independent * all.curvature));
  // A second dip among the trials (the cost falling again further out) is noise as large as the signal: the
  // estimate is no better than the distance between the dips. yard-corners' corner_right, 3 frames, a profile
  // within 0.2 % over ±20 ms with dips at +5 and +20 ms, gave +18.9 ± 8.9 ms from the sharp one, and a
  // result 0.11 cm / 0.007° off the truth was doubted as a late clock.
  const double sigma_dips = farthestDip(shifts, cost, all.offset_ms);
  out.offset_ms = all.offset_ms;
  out.uncertainty_ms = std::max({sigma_jack, sigma_curvature, sigma_dips});
  if (jack_edge) out.uncertainty_ms = std::max(out.uncertainty_ms, options.max_uncertainty_ms + 1.0);
  if (out.uncertainty_ms > options.max_uncertainty_ms) {
    note << "too uncertain (" << std::showpos << out.offset_ms << std::noshowpos << " ± " << out.uncertainty_ms
         << " ms): the frames' motions hardly differ (turning or speed changes make it observable)";
    out.note = note.str();
    return finish();
  }
  out.status = TrajectoryClockEstimate::Status::kEstimated;
  note << "from " << frames.size() << " frames, " << out.points << " points";
  out.note = note.str();
  return finish();
}

}  // namespace rigcal::calib
