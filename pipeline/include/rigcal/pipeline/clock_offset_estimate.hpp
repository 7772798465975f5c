#pragma once
// How far a sensor's clock is off the mapping lidar's, from what every driver already measures: the lag
// of each sweep (capture / receive time of its last packet − the sensor's time of that packet's last firing).
// Two sensors on one network see the same lag within a few tenths of a ms, so the difference of their median
// lags is the offset of their clocks; the lags' spread gives its uncertainty. (Measured against the packet
// that completed the sweep instead, the lag grew with the packets a sweep waits for in the reorder window:
// an OS1-64 and a VLS-128 with agreeing clocks differed by 13 ms.) A calibration lidar paired with the
// wrong mapping pose by 50 ms came out 7 cm off at walking speed with a normal score (issue 18).
#include <cstddef>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "rigcal/config/rig_config.hpp"

namespace rigcal::pipeline {

/// One sensor's lag: the median over sweeps and its standard error.
struct ClockLag {
  double median_ms = 0.0;
  double sigma_ms = 0.0;  // robust standard error of the median (1.25 · 1.4826 · MAD / √n)
  std::size_t sweeps = 0;
};

ClockLag clockLagOf(std::vector<double> lags_ms);

/// A sensor's clock against the mapping lidar's: + = it runs ahead (its stamps are too late).
struct ClockOffset {
  double offset_ms = 0.0;
  double uncertainty_ms = 0.0;  // one standard error
  std::size_t sweeps = 0;       // the fewer of the two sensors' sweeps
};

ClockOffset clockOffsetBetween(const ClockLag& mapping, const ClockLag& sensor);

/// Measures `sensor`'s clock against `mapping`'s over the first `max_sweeps` sweeps of each in a pcap
/// (decoded as the pipeline's drivers do, with neither's time_offset_ns applied). nullopt when either
/// sensor has no sweep in the capture. Throws what SensorDriver throws.
std::optional<ClockOffset> estimateClockOffset(const config::SensorConfig& mapping, const config::SensorConfig& sensor,
                                               const std::filesystem::path& pcap, std::size_t max_sweeps = 100);

}  // namespace rigcal::pipeline
