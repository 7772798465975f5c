#include "rigcal/pipeline/clock_offset_estimate.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>

#include "rigcal/pipeline/sensor_driver.hpp"

namespace rigcal::pipeline {
namespace {

double medianOf(std::vector<double> v) {
  std::nth_element(v.begin(), v.begin() + long(v.size() / 2), v.end());
  return v[v.size() / 2];
}

/// The sensor's own per-sweep lags from the start of a pcap, as fast as it can be read.
std::vector<double> lagsInPcap(config::SensorConfig sensor, const std::filesystem::path& pcap, std::size_t max_sweeps) {
  sensor.time_offset_ns = 0;
  std::atomic<bool> stop{false};
  std::size_t sweeps = 0;
  DriverInput input;
  input.pcap = pcap;
  SensorDriver driver(sensor, input, stop, [&](Scan&&) {
    if (++sweeps >= max_sweeps) stop = true;
  });
  driver.run();
  return driver.clockLagSamplesMs();
}

}  // namespace

ClockLag clockLagOf(std::vector<double> lags_ms) {
  ClockLag lag;
  lag.sweeps = lags_ms.size();
  if (lags_ms.empty()) return lag;
  lag.median_ms = medianOf(lags_ms);
  std::vector<double> deviations;
  deviations.reserve(lags_ms.size());
  for (const double l : lags_ms) deviations.push_back(std::abs(l - lag.median_ms));
  lag.sigma_ms = 1.2533 * 1.4826 * medianOf(std::move(deviations)) / std::sqrt(double(lags_ms.size()));
  return lag;
}

ClockOffset clockOffsetBetween(const ClockLag& mapping, const ClockLag& sensor) {
  ClockOffset o;
  o.offset_ms = mapping.median_ms - sensor.median_ms;
  o.uncertainty_ms = std::hypot(mapping.sigma_ms, sensor.sigma_ms);
  o.sweeps = std::min(mapping.sweeps, sensor.sweeps);
  return o;
}

std::optional<ClockOffset> estimateClockOffset(const config::SensorConfig& mapping, const config::SensorConfig& sensor,
                                               const std::filesystem::path& pcap, std::size_t max_sweeps) {
  const ClockLag m = clockLagOf(lagsInPcap(mapping, pcap, max_sweeps));
  const ClockLag s = clockLagOf(lagsInPcap(sensor, pcap, max_sweeps));
  if (m.sweeps == 0 || s.sweeps == 0) return std::nullopt;
  return clockOffsetBetween(m, s);
}

}  // namespace rigcal::pipeline
