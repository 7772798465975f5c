#include "rigcal/sim/simulated_scan.hpp"

namespace rigcal::sim {

SweepBuilder::SweepBuilder(std::size_t sensor, std::string sensor_id, const LidarModel& model, PoseAt truth,
                           Emit emit)
    : sensor_(sensor), sensor_id_(std::move(sensor_id)), model_(&model), truth_(std::move(truth)), emit_(std::move(emit)) {}

void SweepBuilder::startSweep(const SimFiring& f) {
  current_.emplace();
  current_->sensor = sensor_;
  current_->frame = f.frame;
  current_->scan.sensor_id = sensor_id_;
  current_->scan.sequence = next_seq_++;
  current_->scan.stamp_ns = f.sensor_time_ns;  // earliest possible point time of the sweep
}

void SweepBuilder::add(const FiringBatch& batch) {
  const std::size_t nb = batch.beams;
  for (std::size_t f = 0; f < batch.size(); ++f) {
    const SimFiring& firing = batch.firings[f];
    if (current_ && (firing.frame != current_->frame || firing.sequence != last_sequence_ + 1)) flush();
    if (!current_) startSweep(firing);
    last_sequence_ = firing.sequence;
    SimulatedScan& s = *current_;
    for (std::size_t b = 0; b < nb; ++b) {
      const LaserReturn& r = batch.returns[f * nb + b];
      if (!r.valid) continue;
      const Eigen::Vector3f& p = batch.points[f * nb + b];
      const TimeNs dt = model_->beams[b].time_offset_ns;
      Point pt;
      pt.x = p.x();
      pt.y = p.y();
      pt.z = p.z();
      pt.intensity = r.intensity;
      pt.ring = std::uint16_t(b);
      pt.time_ns = firing.sensor_time_ns + dt;
      s.scan.push_back(pt);
      s.true_time_ns.push_back(firing.true_time_ns + dt);
      if (truth_) s.T_world_sensor.push_back(truth_(firing.true_time_ns + dt));
    }
  }
}

void SweepBuilder::flush() {
  if (!current_) return;
  Scan& scan = current_->scan;
  if (!scan.empty()) {
    // stamp_ns is the earliest point: points are appended in time order, so that is the first one.
    const std::uint32_t first = scan.offset_ns.front();
    scan.stamp_ns += first;
    for (auto& o : scan.offset_ns) o -= first;
    emit_(std::move(*current_));
  }
  current_.reset();
}

}  // namespace rigcal::sim
