#include "rigcal/sim/firing_scheduler.hpp"

#include <cmath>
#include <stdexcept>

namespace rigcal::sim {
namespace {

TimeNs floorDiv(TimeNs a, TimeNs b) { return a / b - ((a % b != 0) && ((a < 0) != (b < 0))); }
TimeNs floorMod(TimeNs a, TimeNs b) { return a - floorDiv(a, b) * b; }

}  // namespace

FiringScheduler::FiringScheduler(const LidarModel& model, double scan_phase_deg, TimeNs clock_offset_ns,
                                 TimeNs start_true_ns)
    : model_(&model), phase_deg_(scan_phase_deg), offset_(clock_offset_ns), frame_ns_(model.framePeriodNs()) {
  if (std::abs(1e9 / model.rotation_hz - double(frame_ns_)) > 1e-6)
    throw std::invalid_argument(model.name + ": the rotation period must be a whole number of ns");
  if (model.period_num_ns <= 0 || model.period_den <= 0)
    throw std::invalid_argument(model.name + ": bad firing period");
  // The rotor reaches the frame-start azimuth this far into every frame period.
  const double frac = std::fmod(model.frame_start_azimuth_deg - scan_phase_deg, 360.0) / 360.0;
  frame_start_offset_ns_ = TimeNs(std::llround((frac < 0 ? frac + 1 : frac) * double(frame_ns_))) % frame_ns_;
  // Sequence 0 starts at a frame start one frame before the first scheduled instant; for Ouster that
  // keeps sequence mod 1024 equal to the measurement id.
  const TimeNs first = start_true_ns + offset_;
  anchor_ns_ = floorDiv(first - frame_start_offset_ns_, frame_ns_) * frame_ns_ + frame_start_offset_ns_ - frame_ns_;
}

double FiringScheduler::rotorAzimuthDeg(TimeNs sensor_time) const {
  const double a = phase_deg_ + 360.0 * double(floorMod(sensor_time, frame_ns_)) / double(frame_ns_);
  const double m = std::fmod(a, 360.0);
  return m < 0 ? m + 360.0 : m;
}

std::int64_t FiringScheduler::frameIndex(TimeNs sensor_time) const {
  return floorDiv(sensor_time - frame_start_offset_ns_, frame_ns_);
}

TimeNs FiringScheduler::sensorTime(std::int64_t sequence) const {
  // Exact rational arithmetic: sequence·num fits easily in 128 bits.
  const __int128 num = __int128(sequence) * model_->period_num_ns;
  return anchor_ns_ + TimeNs(num / model_->period_den);
}

std::int64_t FiringScheduler::firstSequenceAtOrAfter(TimeNs sensor_time) const {
  const double approx = double(sensor_time - anchor_ns_) / model_->firingPeriodNs();
  std::int64_t k = std::max<std::int64_t>(0, std::int64_t(std::floor(approx)) - 1);
  while (sensorTime(k) < sensor_time) ++k;
  while (k > 0 && sensorTime(k - 1) >= sensor_time) --k;
  return k;
}

void FiringScheduler::schedule(TimeNs from_true, TimeNs to_true, std::vector<SimFiring>& out) const {
  const TimeNs from = from_true + offset_, to = to_true + offset_;
  for (std::int64_t k = firstSequenceAtOrAfter(from);; ++k) {
    const TimeNs t = sensorTime(k);
    if (t >= to) break;
    SimFiring f;
    f.sensor_time_ns = t;
    f.true_time_ns = t - offset_;
    f.rotor_azimuth_deg = rotorAzimuthDeg(t);
    f.sequence = k;
    f.frame = frameIndex(t);
    if (model_->columns_per_frame > 0) f.column = std::int32_t(k % model_->columns_per_frame);
    out.push_back(f);
  }
}

}  // namespace rigcal::sim
