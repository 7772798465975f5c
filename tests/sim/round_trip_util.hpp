#pragma once
// The round trip the vendor encoders are judged by: simulate → recording.pcap → rigcal's own decoders
// (makeDecoder + ScanAssembler through pumpScans) → compare every decoded point with the simulated
// one it came from (matched by beam and firing time).
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include "rigcal/drivers/packet_decoder.hpp"
#include "rigcal/drivers/pcap_source.hpp"
#include "rigcal/drivers/scan_assembler.hpp"
#include "rigcal/drivers/scan_pump.hpp"
#include "rigcal/sim/outputs.hpp"
#include "rigcal/sim/recording.hpp"

namespace rigcal::sim::test {

/// Keeps every firing, return and simulated point of every sensor.
class FiringRecorder : public SimulationSink {
 public:
  struct Sensor {
    std::size_t beams = 0;
    std::vector<SimFiring> firings;
    std::vector<LaserReturn> returns;
    std::vector<Eigen::Vector3f> points;
  };
  explicit FiringRecorder(std::size_t sensors) : sensors(sensors) {}
  void onFirings(std::size_t sensor, const FiringBatch& b) override {
    Sensor& s = sensors[sensor];
    s.beams = b.beams;
    s.firings.insert(s.firings.end(), b.firings.begin(), b.firings.end());
    s.returns.insert(s.returns.end(), b.returns.begin(), b.returns.end());
    s.points.insert(s.points.end(), b.points.begin(), b.points.end());
  }
  std::vector<Sensor> sensors;
};

struct SensorRoundTrip {
  std::size_t decoded = 0;    // points out of the decoder
  std::size_t matched = 0;    // decoded points that match a simulated valid return
  std::size_t expected = 0;   // simulated valid returns within the decoded time span
  double max_error_m = 0;     // largest |decoded − simulated| over matched points
  double max_excess_m = 0;    // largest error beyond the model's quantisation bound
  TimeNs max_time_error_ns = 0;
  double mean_azimuth_error_deg = 0;  // signed, over matched points: a bias would be a format error
  std::uint64_t malformed = 0, lost = 0, scans = 0;
  std::string last_error;
};

/// The position error a decoder may make: half the range unit radially, and the azimuth resolution of
/// the format tangentially (0.01° block/point azimuth for Velodyne and Hesai; Ouster's azimuth is the
/// column's, exact).
inline double quantisationBound(const LidarModel& m, double range_m, double azimuth_resolution_deg) {
  return 0.5 * m.distance_unit_m + range_m * azimuth_resolution_deg * M_PI / 180.0 + 2e-4;
}

/// Decodes sensor `index` of `sim` from `pcap` with the calibration/metadata file rig.yaml names in
/// `dir`, and compares with what `rec` recorded.
inline SensorRoundTrip decodeAndCompare(const Simulation& sim, std::size_t index, const std::filesystem::path& dir,
                                        const std::filesystem::path& pcap, const FiringRecorder::Sensor& rec,
                                        double azimuth_resolution_deg) {
  const SensorSpec& spec = sim.scenario().sensors[index];
  const LidarModel& model = sim.model(index);
  drivers::DecoderConfig config;
  config.model = spec.model;
  const std::string vendor_file = vendorFile(spec, model).first;
  if (model.vendor == LidarVendor::kOuster) config.metadata = dir / vendor_file;
  else if (!vendor_file.empty()) config.calibration = dir / vendor_file;  // RoboSense: angles from DIFOP
  config.time_source = TimeSource::kSensorClock;
  auto decoder = drivers::makeDecoder(config);
  drivers::PacketFilter filter;
  filter.destination_port = spec.port;
  filter.source_address = ipv4FromText(spec.address);
  if (const std::uint16_t info = infoPort(spec, model)) filter.info_port = info;
  drivers::PcapSource source(pcap, filter);
  std::vector<Scan> scans;
  drivers::ScanAssembler assembler(spec.name, {}, [&](Scan&& s) { scans.push_back(std::move(s)); });
  drivers::pumpScans(source, *decoder, assembler);

  SensorRoundTrip r;
  r.malformed = assembler.stats().malformed;
  r.lost = assembler.stats().lost_packets;
  r.scans = scans.size();
  r.last_error = assembler.stats().last_error;
  const auto& firings = rec.firings;
  // The decoders number rings by laser; RS-Helios-16P fires each of its 16 lasers twice per sequence.
  const std::size_t rings = model.vendor == LidarVendor::kRobosense ? rec.beams / 2 : rec.beams;
  TimeNs first = std::numeric_limits<TimeNs>::max(), last = std::numeric_limits<TimeNs>::min();
  std::vector<char> seen(rec.returns.size(), 0);
  double azimuth_error_sum = 0;
  std::size_t azimuth_errors = 0;
  for (const Scan& scan : scans) {
    for (std::size_t i = 0; i < scan.size(); ++i) {
      ++r.decoded;
      // For each beam on this ring, the firing sequence nearest in time; of those that fired then (a
      // laser fired twice per sequence can coincide with its next sequence's first firing), the nearest
      // simulated point.
      const Eigen::Vector3f p(scan.x[i], scan.y[i], scan.z[i]);
      std::size_t k = rec.returns.size();
      double e = std::numeric_limits<double>::max();
      TimeNs dt = 0;
      std::vector<SimFiring>::const_iterator it;
      for (std::size_t beam = scan.ring[i]; beam < rec.beams; beam += rings) {
        const TimeNs t = scan.pointTime(i) - model.beams[beam].time_offset_ns;
        auto at = std::lower_bound(firings.begin(), firings.end(), t,
                                   [](const SimFiring& f, TimeNs v) { return f.sensor_time_ns < v; });
        if (at == firings.end() || (at != firings.begin() && t - (at - 1)->sensor_time_ns < at->sensor_time_ns - t)) --at;
        const std::size_t candidate = std::size_t(at - firings.begin()) * rec.beams + beam;
        const TimeNs candidate_dt = std::abs(t - at->sensor_time_ns);
        if (candidate_dt > 2'000 || !rec.returns[candidate].valid || seen[candidate]) continue;
        const double candidate_e = (p - rec.points[candidate]).cast<double>().norm();
        if (candidate_e >= e) continue;
        k = candidate, e = candidate_e, dt = candidate_dt, it = at;
      }
      if (k == rec.returns.size()) continue;
      seen[k] = 1;
      r.max_error_m = std::max(r.max_error_m, e);
      r.max_excess_m = std::max(r.max_excess_m, e - quantisationBound(model, rec.returns[k].range_m, azimuth_resolution_deg));
      r.max_time_error_ns = std::max(r.max_time_error_ns, dt);
      const Eigen::Vector3f& q = rec.points[k];
      if (std::hypot(q.x(), q.y()) > 2.0f) {
        double d = std::atan2(-double(p.y()), double(p.x())) - std::atan2(-double(q.y()), double(q.x()));
        d = std::remainder(d, 2 * M_PI);
        azimuth_error_sum += d * 180.0 / M_PI;
        ++azimuth_errors;
      }
      first = std::min(first, it->sensor_time_ns);
      last = std::max(last, it->sensor_time_ns);
      ++r.matched;
    }
  }
  if (azimuth_errors) r.mean_azimuth_error_deg = azimuth_error_sum / double(azimuth_errors);
  for (std::size_t f = 0; f < firings.size(); ++f) {
    if (firings[f].sensor_time_ns < first || firings[f].sensor_time_ns > last) continue;
    for (std::size_t b = 0; b < rec.beams; ++b) r.expected += rec.returns[f * rec.beams + b].valid;
  }
  return r;
}

}  // namespace rigcal::sim::test
