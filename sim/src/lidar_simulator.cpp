#include "rigcal/sim/lidar_simulator.hpp"

#include <algorithm>
#include <cmath>

#include "rigcal/sim/random.hpp"

namespace rigcal::sim {

LidarSimulator::LidarSimulator(const LidarModel& model, const Scene& scene, const Trajectory& trajectory,
                               TimeNs trajectory_start_ns, const Pose& T_base_sensor, const NoiseSpec& noise,
                               std::uint64_t noise_key)
    : model_(&model),
      scene_(&scene),
      trajectory_(&trajectory),
      start_ns_(trajectory_start_ns),
      T_base_sensor_(T_base_sensor),
      noise_(noise),
      key_(noise_key),
      period_ns_(TimeNs(std::llround(model.firingPeriodNs()))) {
  for (std::size_t b = 0; b < model.beamCount(); ++b) {
    // Azimuth of the beam relative to the sequence-start rotor azimuth.
    const double az = deg2rad(model.beamAzimuthDeg(b, 0.0)), el = deg2rad(model.beams[b].elevation_deg);
    const double origin_az = deg2rad(model.beams[b].origin_azimuth_deg);
    beams_.push_back({std::cos(el), std::sin(el), std::cos(az), std::sin(az),
                      double(model.beams[b].time_offset_ns) / double(period_ns_), std::cos(origin_az), std::sin(origin_az)});
    origin_per_beam_ = origin_per_beam_ || (origin_az != 0.0 && model.beam_origin_radius_m != 0.0);
  }
}

Pose LidarSimulator::sensorPose(TimeNs true_time) const {
  return trajectory_->pose(true_time - start_ns_) * T_base_sensor_;
}

void LidarSimulator::cast(FiringBatch& batch, std::size_t begin, std::size_t end, CastStats& stats) const {
  const LidarModel& m = *model_;
  const std::size_t nb = beams_.size();
  // Reported range = travel from the beam origin + this (Ouster: from the lidar origin; RoboSense: 0).
  const double n_radius = m.range_from_beam_origin ? 0.0 : m.beam_origin_radius_m;
  const double unit = m.distance_unit_m;
  // Poses at each sequence's start and end; each beam's pose is interpolated at its own firing time
  // (exact to second order over ~50 µs: far below a micrometre). A sequence's end is the next one's
  // start, so each pose is computed once.
  Pose T1 = Pose::Identity();
  TimeNs t1 = -1;
  for (std::size_t f = begin; f < end; ++f) {
    const SimFiring& firing = batch.firings[f];
    const Pose T0 = t1 == firing.true_time_ns ? T1 : sensorPose(firing.true_time_ns);
    const bool next_adjacent = f + 1 < batch.size() && batch.firings[f + 1].sequence == firing.sequence + 1;
    t1 = next_adjacent ? batch.firings[f + 1].true_time_ns : firing.true_time_ns + period_ns_;
    T1 = sensorPose(t1);
    const double inv_span = double(period_ns_) / double(t1 - firing.true_time_ns);
    const double a = deg2rad(firing.rotor_azimuth_deg), ca = std::cos(a), sa = std::sin(a);
    const Eigen::Vector3d origin_s = m.beamOrigin(firing.rotor_azimuth_deg);
    const Eigen::Vector3d o0 = T0 * origin_s, o1 = T1 * origin_s;
    for (std::size_t b = 0; b < nb; ++b) {
      const BeamTerms& bt = beams_[b];
      LaserReturn& ret = batch.returns[f * nb + b];
      ret = LaserReturn{};
      batch.points[f * nb + b] = Eigen::Vector3f::Zero();
      // Sensor-frame direction: rotor azimuth plus the beam's offset (angle addition), elevation.
      const double cos_a = ca * bt.cos_az - sa * bt.sin_az, sin_a = sa * bt.cos_az + ca * bt.sin_az;
      const Eigen::Vector3d d_s(bt.cos_el * cos_a, -bt.cos_el * sin_a, bt.sin_el);
      const double u = bt.time_fraction * inv_span;
      Ray ray;
      Eigen::Vector3d origin_b = origin_s;
      if (origin_per_beam_) {  // the origin turned on by the beam's origin azimuth (clockwise)
        origin_b.x() = origin_s.x() * bt.cos_origin + origin_s.y() * bt.sin_origin;
        origin_b.y() = origin_s.y() * bt.cos_origin - origin_s.x() * bt.sin_origin;
        ray.origin = (1 - u) * (T0 * origin_b) + u * (T1 * origin_b);
      } else {
        ray.origin = o0 + u * (o1 - o0);
      }
      ray.dir = ((1 - u) * (T0.linear() * d_s) + u * (T1.linear() * d_s)).normalized();
      ++stats.rays;
      Hit hit;
      const double t_max = m.max_range_m - n_radius;
      if (!scene_->cast(ray, 0.0, t_max, hit)) continue;

      const MaterialProperties& mat = properties(hit.material);
      const std::uint64_t h = hashKeys(key_, std::uint64_t(firing.sequence), b);
      const double incidence = std::abs(hit.normal.dot(ray.dir));
      // Dark surfaces fade before the rated range (rated for ~80 % reflectivity); grazing hits too.
      const double rho = mat.retro ? 1.0 : mat.reflectivity * (0.5 + 0.5 * incidence);
      const double reach = m.max_range_m * std::clamp(std::sqrt(rho / 0.5), 0.35, 1.0);
      double range = hit.t + n_radius;
      if (range > reach) continue;
      // Random losses and the material's own (glass, foliage) are independent causes.
      if (unitFromBits(mix64(h ^ 0x1)) < noise_.dropout || unitFromBits(mix64(h ^ 0x4)) < mat.dropout) continue;
      // One Box–Muller pair: cosine branch for range, sine branch for intensity.
      const double u1 = 1.0 - unitFromBits(mix64(h ^ 0x2)), u2 = unitFromBits(mix64(h ^ 0x3));
      const double radius = std::sqrt(-2.0 * std::log(u1));
      range += noise_.range_sigma_m * radius * std::cos(2 * M_PI * u2);
      const double q = std::round(range / unit) * unit;
      if (q < m.min_range_m || q > m.max_range_m) continue;
      const double shade = mat.retro ? 1.0 : 0.3 + 0.7 * incidence;
      const double intensity = 255.0 * mat.reflectivity * shade + noise_.intensity_sigma * radius * std::sin(2 * M_PI * u2);
      ret.valid = true;
      ret.range_m = float(q);
      ret.intensity = float(std::clamp(std::round(intensity), 1.0, 255.0));
      // The point a decoder reconstructs: beam origin plus the range along the beam direction.
      batch.points[f * nb + b] = (origin_b + (q - n_radius) * d_s).cast<float>();
      ++stats.returns;
    }
  }
}

}  // namespace rigcal::sim
