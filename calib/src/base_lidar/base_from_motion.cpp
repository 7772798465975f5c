#include "rigcal/calib/base_lidar/base_from_motion.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>

#include <Eigen/Dense>

namespace rigcal::calib {

BaseFromMotionMode parseBaseFromMotionMode(const std::string& text) {
  if (text == "off") return BaseFromMotionMode::kOff;
  if (text == "yaw") return BaseFromMotionMode::kYaw;
  if (text == "yaw_x") return BaseFromMotionMode::kYawX;
  throw std::invalid_argument("base_link_from_motion: '" + text + "' is not one of off, yaw, yaw_x");
}

namespace {

// One chord in the levelled lidar frame: displacement (a, b) and c = 2·sin(Δθ/2), so that for a
// vehicle without side slip a·sinψ + b·cosψ = c·x (the lateral part in base_link axes).
struct Chord {
  double a = 0, b = 0, c = 0;
  double length = 0;     // |(a, b)|
  double turn = 0;       // Δθ (rad), positive = counter-clockwise
  double curvature = 0;  // steering curvature (1/m): positive = turning left, whichever way it drives
  bool reversing = false;
};

// The upper of the two middle values for an even count (robust scale: no averaging needed).
double upperMedian(std::vector<double> v) {
  if (v.empty()) return 0.0;
  const std::size_t mid = v.size() / 2;
  std::nth_element(v.begin(), v.begin() + std::ptrdiff_t(mid), v.end());
  return v[mid];
}

std::vector<Chord> chordsOf(const std::vector<TimeNs>& stamps, const std::vector<Pose>& T, const std::vector<bool>& usable,
                            const Eigen::Matrix3d& R_tilt, double yaw_guess, const BaseFromMotionSettings& s) {
  std::vector<Chord> chords;
  const std::size_t n = T.size();
  const auto ok = [&](std::size_t k) { return usable.empty() || usable[k]; };
  std::size_t i = 0;
  while (i + 1 < n) {
    if (!ok(i)) {
      ++i;
      continue;
    }
    // Walk forward until chord_m of travel, never across a lost frame, nor longer than max_chord_s (a
    // long stop then costs O(frames in max_chord_s) per frame, not O(frames of the stop)).
    double path = 0.0;
    std::size_t j = i;
    bool broken = false;
    while (j + 1 < n && path < s.chord_m && toSeconds(stamps[j + 1] - stamps[i]) <= s.max_chord_s) {
      if (!ok(j + 1)) {
        broken = true;
        break;
      }
      path += (T[j + 1].translation() - T[j].translation()).norm();
      ++j;
    }
    if (broken) {
      i = j + 1;
      continue;
    }
    if (path < s.chord_m && j + 1 >= n) break;  // the end of the drive
    const double dt = toSeconds(stamps[j] - stamps[i]);
    if (path < s.chord_m || dt <= 0 || path / dt < s.min_speed_mps) {
      ++i;  // a stop or slow creep at the start: try from the next frame
      continue;
    }
    const Eigen::Matrix3d Ri = T[i].linear(), Rj = T[j].linear();
    const Eigen::Vector3d rel = logSO3(Ri.transpose() * Rj);
    const Eigen::Matrix3d R_mid = Ri * expSO3(0.5 * rel);
    const Eigen::Vector3d d = R_tilt * (R_mid.transpose() * (T[j].translation() - T[i].translation()));
    Chord c;
    c.a = d.x();
    c.b = d.y();
    c.length = std::hypot(c.a, c.b);
    // A chord through a direction change (cusp) is much shorter than the path it spans: not an arc.
    if (c.length < 0.95 * path) {
      ++i;
      continue;
    }
    c.turn = (R_tilt * rel).z();
    c.c = 2.0 * std::sin(0.5 * c.turn);
    c.reversing = std::cos(yaw_guess) * c.a - std::sin(yaw_guess) * c.b < 0;
    c.curvature = c.c / ((c.reversing ? -1.0 : 1.0) * c.length);
    chords.push_back(c);
    i = j;
  }
  return chords;
}

struct Fit {
  double yaw = 0, x = 0, yaw_std = 0, x_std = 0, rms = 0;
  std::size_t used = 0, outliers = 0;
};

// Weighted least squares of r = a·sinψ + b·cosψ − c·x (x fixed when !with_x), Gauss–Newton inside an
// iteratively reweighted loop: Huber weights beyond 1.345 robust σ, rejection beyond outlier_sigmas σ.
// Every chord has the same noise model (two positions and a heading of the mapper), so the weights are
// the robust ones alone.
Fit robustFit(const std::vector<const Chord*>& chords, double yaw0, double x0, bool with_x, double outlier_sigmas) {
  Fit f;
  f.yaw = yaw0;
  f.x = x0;
  const std::size_t n = chords.size();
  std::vector<double> w(n, 1.0), r(n, 0.0);
  const auto residuals = [&] {
    for (std::size_t k = 0; k < n; ++k)
      r[k] = chords[k]->a * std::sin(f.yaw) + chords[k]->b * std::cos(f.yaw) - chords[k]->c * f.x;
  };
  Eigen::Matrix2d H = Eigen::Matrix2d::Identity();
  double sigma = 0.0;
  for (int round = 0; round < 12; ++round) {
    for (int gn = 0; gn < 10; ++gn) {
      residuals();
      H.setZero();
      Eigen::Vector2d g = Eigen::Vector2d::Zero();
      for (std::size_t k = 0; k < n; ++k) {
        if (w[k] == 0) continue;
        const Eigen::Vector2d J(chords[k]->a * std::cos(f.yaw) - chords[k]->b * std::sin(f.yaw), -chords[k]->c);
        H += w[k] * J * J.transpose();
        g += w[k] * J * r[k];
      }
      Eigen::Vector2d step = Eigen::Vector2d::Zero();
      if (with_x) {
        step = -H.ldlt().solve(g);
      } else if (H(0, 0) > 0) {
        step.x() = -g.x() / H(0, 0);
      }
      f.yaw += step.x();
      f.x += step.y();
      if (step.norm() < 1e-12) break;
    }
    residuals();
    std::vector<double> inlier_abs;
    for (std::size_t k = 0; k < n; ++k)
      if (w[k] > 0) inlier_abs.push_back(std::abs(r[k]));
    // A floor of 0.1 mm: below the mapper's noise, rejecting would only cut the exact model's rounding.
    sigma = std::max(1.4826 * upperMedian(inlier_abs), 1e-4);
    std::vector<double> next(n);
    for (std::size_t k = 0; k < n; ++k) {
      const double z = std::abs(r[k]) / sigma;
      next[k] = z > outlier_sigmas ? 0.0 : z > 1.345 ? 1.345 / z : 1.0;
    }
    const bool settled = std::equal(next.begin(), next.end(), w.begin(),
                                    [](double p, double q) { return std::abs(p - q) < 1e-9; });
    w.swap(next);
    if (settled) break;
  }
  // Standard deviation from the data: the weighted residual variance propagated through (JᵀWJ)⁻¹, with
  // the final weights.
  double wrr = 0.0, sum_r2 = 0.0;
  H.setZero();
  for (std::size_t k = 0; k < n; ++k) {
    if (w[k] == 0) {
      ++f.outliers;
      continue;
    }
    const Eigen::Vector2d J(chords[k]->a * std::cos(f.yaw) - chords[k]->b * std::sin(f.yaw), -chords[k]->c);
    H += w[k] * J * J.transpose();
    ++f.used;
    wrr += w[k] * r[k] * r[k];
    sum_r2 += r[k] * r[k];
  }
  const std::size_t params = with_x ? 2 : 1;
  const double variance = f.used > params ? wrr / double(f.used - params) : 0.0;
  f.rms = f.used > 0 ? std::sqrt(sum_r2 / double(f.used)) : 0.0;
  if (with_x) {
    const Eigen::Matrix2d cov = variance * H.inverse();
    f.yaw_std = std::sqrt(std::max(cov(0, 0), 0.0));
    f.x_std = std::sqrt(std::max(cov(1, 1), 0.0));
  } else if (H(0, 0) > 0) {
    f.yaw_std = std::sqrt(variance / H(0, 0));
  }
  return f;
}

std::string fixed(const char* format, double a, double b = 0.0, double c = 0.0) {
  char buf[160];
  std::snprintf(buf, sizeof buf, format, a, b, c);
  return buf;
}

}  // namespace

BaseFromMotionResult estimateBaseFromMotion(const std::vector<TimeNs>& stamps, const std::vector<Pose>& T_map_lidar,
                                            const std::vector<bool>& usable, const Pose& guess,
                                            BaseFromMotionMode mode, const BaseFromMotionSettings& s) {
  if (stamps.size() != T_map_lidar.size() || (!usable.empty() && usable.size() != stamps.size()))
    throw std::invalid_argument("base from motion: stamps, poses and usable flags differ in length");
  BaseFromMotionResult out;
  out.T_base_lidar = guess;
  const XyzRpy g = toXyzRpy(guess);
  out.yaw.value = g.yaw;
  out.x.value = g.x;
  if (mode == BaseFromMotionMode::kOff) {
    out.yaw.note = out.x.note = "off; kept the guess";
    return out;
  }
  // Levelled lidar frame: the lidar's axes turned by the ground's roll and pitch (R = Rz·Ry·Rx), so that
  // only base_link's yaw separates it from base_link.
  const Eigen::Matrix3d R_tilt = fromXyzRpy({0, 0, 0, g.roll, g.pitch, 0}).linear();
  const std::vector<Chord> chords = chordsOf(stamps, T_map_lidar, usable, R_tilt, g.yaw, s);
  out.chords = chords.size();
  std::vector<const Chord*> all, straight;
  for (const Chord& c : chords) {
    out.moving_m += c.length;
    if (c.reversing) out.reversing_m += c.length;
    if (std::abs(c.curvature) <= s.straight_max_curvature) {
      out.straight_m += c.length;
      straight.push_back(&c);
    } else if (c.curvature >= s.turn_min_curvature) {
      out.left_turn_deg += rad2deg(std::abs(c.turn));
    } else if (c.curvature <= -s.turn_min_curvature) {
      out.right_turn_deg += rad2deg(std::abs(c.turn));
    }
    all.push_back(&c);
  }
  const bool both_ways = out.left_turn_deg >= s.min_turn_deg && out.right_turn_deg >= s.min_turn_deg;
  const bool x_observable = mode == BaseFromMotionMode::kYawX && both_ways;
  const bool yaw_observable = out.straight_m >= s.min_straight_m || x_observable;

  if (!yaw_observable) {
    out.yaw.note = fixed("not observable: %.1f m of straight driving above %.1f m/s (need %.1f m); kept the guess",
                         out.straight_m, s.min_speed_mps, s.min_straight_m);
  }
  if (mode == BaseFromMotionMode::kYaw) {
    out.x.note = "not estimated (base_link_from_motion: yaw); kept the guess";
  } else if (!both_ways) {
    out.x.note = fixed("not observable: turns %.0f deg left, %.0f deg right (need %.0f deg each way); kept the guess",
                       out.left_turn_deg, out.right_turn_deg, s.min_turn_deg);
  }
  if (!yaw_observable) return out;

  // With turns both ways every moving chord takes part (x and yaw together); otherwise yaw alone from
  // the straight chords, where the guess's x hardly matters (lateral ω·x vanishes).
  const Fit f = x_observable ? robustFit(all, g.yaw, g.x, true, s.outlier_sigmas)
                             : robustFit(straight, g.yaw, g.x, false, s.outlier_sigmas);
  out.chords_used = f.used;
  out.outliers = f.outliers;
  out.residual_rms_m = f.rms;
  out.yaw = {true, std::atan2(std::sin(f.yaw), std::cos(f.yaw)), f.yaw_std, ""};
  if (x_observable) out.x = {true, f.x, f.x_std, ""};
  XyzRpy r = g;
  r.yaw = out.yaw.value;
  r.x = out.x.value;
  out.T_base_lidar = fromXyzRpy(r);
  return out;
}

std::string describeBaseFromMotion(const BaseFromMotionResult& r) {
  std::string text;
  if (r.yaw.estimated)
    text += fixed("yaw %.3f deg ± %.3f from motion (%.1f m straight)", rad2deg(r.yaw.value), rad2deg(r.yaw.stddev),
                  r.straight_m);
  else
    text += "yaw from the guess (" + r.yaw.note + ")";
  text += "; ";
  if (r.x.estimated)
    text += fixed("x %.3f m ± %.3f from motion (turns %.0f deg left, ", r.x.value, r.x.stddev, r.left_turn_deg) +
            fixed("%.0f deg right)", r.right_turn_deg);
  else
    text += "x from the guess (" + r.x.note + ")";
  text += "; y from the guess (not observable from motion)";
  return text;
}

}  // namespace rigcal::calib
