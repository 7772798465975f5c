#include "rigcal/pipeline/sensor_driver.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "rigcal/bag/bag_packet_source.hpp"
#include "rigcal/bag/lidar_topic.hpp"
#include "rigcal/drivers/info_port_source.hpp"
#include "rigcal/drivers/paced_source.hpp"
#include "rigcal/drivers/packet_family.hpp"
#include "rigcal/drivers/pacing.hpp"
#include "rigcal/drivers/pcap_source.hpp"
#include "rigcal/drivers/scan_pump.hpp"
#include "rigcal/drivers/udp_source.hpp"

namespace rigcal::pipeline {

drivers::DecoderConfig decoderConfigFor(const config::SensorConfig& sensor) {
  drivers::DecoderConfig c;
  c.model = sensor.model;
  c.calibration = sensor.calibration;
  c.metadata = sensor.metadata;
  c.time_source = sensor.time_source;
  return c;
}

namespace {
drivers::PacketFilter filterFor(const config::SensorConfig& sensor, bool live) {
  drivers::PacketFilter f;
  f.destination_port = sensor.source.port;
  f.info_port = sensor.source.info_port;
  // Bound to loopback, only this host can send (a replay, from 127.0.0.1): the sensor's address cannot match.
  if (sensor.source.address && !(live && sensor.source.bindsLoopback()))
    f.source_address = drivers::parseIpv4(*sensor.source.address);
  return f;
}
constexpr std::size_t kMaxLags = 4096;  // sweeps kept for the clock-lag median (7 min at 10 Hz)
}  // namespace

/// Passes this sensor's packets through (driver thread only). Packets of another vendor's model
/// (drivers::recognizePacket) are held back and counted as foreign: decoded with this sensor's layout they
/// would be malformed at best.
class SensorDriver::ForeignPacketFilter : public drivers::PacketSource {
 public:
  ForeignPacketFilter(drivers::PacketSource& inner, drivers::PacketFamily own) : inner_(inner), own_(own) {}
  std::optional<drivers::UdpPacket> next() override {
    auto p = inner_.next();
    while (p && own_ != drivers::PacketFamily::kUnknown) {
      const drivers::PacketFamily family = drivers::recognizePacket(p->payload);
      if (family == drivers::PacketFamily::kUnknown || family == own_) break;
      ++foreign.packets;
      foreign.family = family;
      foreign.bytes = p->payload.size();
      foreign.last_source = p->source;
      p = inner_.next();
    }
    return p;
  }
  [[nodiscard]] const drivers::SourceStats& stats() const override { return inner_.stats(); }
  [[nodiscard]] std::string warning() const override { return inner_.warning(); }
  ForeignPackets foreign;

 private:
  drivers::PacketSource& inner_;
  drivers::PacketFamily own_;
};

SensorDriver::SensorDriver(const config::SensorConfig& sensor, const DriverInput& input,
                           const std::atomic<bool>& stop, drivers::ScanAssembler::ScanCallback on_scan)
    : sensor_(sensor),
      on_scan_(std::move(on_scan)),
      assembler_(sensor.name, drivers::AssemblerConfig{sensor.cut_angle_deg},
                 [this](Scan&& scan) {
                   // The rig's time_offset_ns puts this sensor's stamps on the rig's clock (before the lag
                   // check, which then measures what is left).
                   scan.stamp_ns -= sensor_.time_offset_ns;
                   if (const auto lag = assembler_.lastPacketLagNs())
                     recordLagMs(double(*lag + sensor_.time_offset_ns) * 1e-6);
                   on_scan_(std::move(scan));
                 }),
      stop_(stop),
      live_(!input.pcap && !input.bag),
      rate_(input.rate) {
  try {
    const bool cloud_model = sensor.model == kPointCloud2Model;
    if (!cloud_model) decoder_ = drivers::makeDecoder(decoderConfigFor(sensor));
    if (cloud_model && !input.bag)
      throw std::runtime_error(std::string("model ") + kPointCloud2Model + " reads a bag's PointCloud2 topic (--bag)");
    if (input.bag) {
      // The topic and its form from a first look at the bag; each source then streams its own copy.
      const std::string wanted = !input.topic.empty() ? input.topic : sensor.source.topic.value_or("");
      const bag::LidarTopic topic = bag::chooseLidarTopic(bag::Bag(*input.bag), wanted);
      bag_topic_ = topic.name + " (" + topic.type + ")";
      if (topic.form == bag::LidarTopicForm::kPointCloud2) {
        if (!std::isfinite(input.rate) || input.rate < 0) throw std::invalid_argument("rate must be positive or 0");
        clouds_ = std::make_unique<bag::BagCloudSource>(*input.bag, topic.name);
        return;
      }
      if (cloud_model)
        throw std::runtime_error(std::string("model ") + kPointCloud2Model + " needs a PointCloud2 topic; " + bag_topic_ +
                                 " holds packets: give the lidar's model");
      raw_source_ = std::make_unique<bag::BagPacketSource>(*input.bag, topic.name);
      source_ = std::make_unique<drivers::PacedSource>(*raw_source_, input.rate, stop_);
    } else if (sensor.source.port == 0) {
      throw std::runtime_error("has no UDP port: its source is the bag topic " + sensor.source.topic.value_or("") +
                               " (read it with --bag)");
    } else if (input.pcap) {
      raw_source_ = std::make_unique<drivers::PcapSource>(*input.pcap, filterFor(sensor, false));
      source_ = std::make_unique<drivers::PacedSource>(*raw_source_, input.rate, stop_);
    } else {
      drivers::UdpSourceConfig udp;
      udp.port = sensor.source.port;
      udp.filter = filterFor(sensor, true);
      if (sensor.source.bind) udp.bind_address = *sensor.source.bind;
      if (sensor.source.multicast_group) udp.multicast_group = *sensor.source.multicast_group;
      if (sensor.source.info_port)
        source_ = std::make_unique<drivers::InfoPortSource>(udp, *sensor.source.info_port);
      else
        source_ = std::make_unique<drivers::UdpSource>(udp);
    }
    filter_ = std::make_unique<ForeignPacketFilter>(*source_, drivers::familyOfModel(sensor.model));
  } catch (const std::exception& e) {
    throw std::runtime_error("sensor '" + sensor.name + "': " + e.what());
  }
}

SensorDriver::~SensorDriver() = default;

void SensorDriver::run(const std::function<void()>& idle) {
  if (clouds_) return runClouds();
  drivers::pumpScans(*filter_, *decoder_, assembler_, [&](bool was_idle) {
    if (stop_.load(std::memory_order_relaxed)) return false;
    if (!was_idle) return true;
    if (!live_) return false;  // a pcap that yields nothing has ended
    if (idle) idle();
    return true;
  });
}

// Each cloud is a whole scan: paced by its log time like PacedSource paces packets, its lag measured
// against that log time (the recorder's "arrival").
void SensorDriver::runClouds() {
  std::optional<TimeNs> first_recorded, start_wall;
  TimeNs last_deadline = 0;
  while (!stop_.load(std::memory_order_relaxed)) {
    auto cloud = clouds_->next();
    if (!cloud) return;
    if (rate_ > 0) {
      if (!first_recorded) {
        first_recorded = cloud->log_time_ns;
        start_wall = drivers::monotonicNow();
      }
      last_deadline = std::max(last_deadline,
                               *start_wall + TimeNs(double(cloud->log_time_ns - *first_recorded) / rate_));
      if (!drivers::sleepUntil(last_deadline, stop_)) return;
    }
    cloud->scan.sensor_id = sensor_.name;
    cloud->scan.stamp_ns -= sensor_.time_offset_ns;  // as for decoded packets (see the constructor)
    recordLag(cloud->scan, cloud->log_time_ns);
    on_scan_(std::move(cloud->scan));
  }
}

const drivers::SourceStats& SensorDriver::sourceStats() const {
  return clouds_ ? clouds_->stats() : source_->stats();
}

std::string SensorDriver::warning() const { return clouds_ ? clouds_->warning() : source_->warning(); }

void SensorDriver::recordLag(const Scan& scan, TimeNs receive_ns) {
  if (scan.empty() || receive_ns == 0) return;
  const TimeNs end = scan.stamp_ns + *std::max_element(scan.offset_ns.begin(), scan.offset_ns.end());
  recordLagMs(double(receive_ns - end) * 1e-6);
}

void SensorDriver::recordLagMs(double lag_ms) {
  std::lock_guard lock(lag_mutex_);
  if (lags_ms_.size() < kMaxLags) lags_ms_.push_back(lag_ms);
}

std::optional<double> SensorDriver::clockLagMs() const {
  std::lock_guard lock(lag_mutex_);
  if (lags_ms_.empty()) return std::nullopt;
  std::vector<double> v = lags_ms_;
  std::nth_element(v.begin(), v.begin() + long(v.size() / 2), v.end());
  return v[v.size() / 2];
}

const ForeignPackets& SensorDriver::foreignPackets() const {
  static const ForeignPackets kNone;  // a PointCloud2 sensor has no packets to recognise
  return filter_ ? filter_->foreign : kNone;
}

std::string ForeignPackets::describe(const std::string& model, std::uint16_t port) const {
  return std::to_string(packets) + " packets of another model (" + drivers::toString(family) + ", " +
         std::to_string(bytes) + " B) on its port " + std::to_string(port) + " (it is a " + model +
         "), the last from " + drivers::formatIpv4(last_source.address) + ":" + std::to_string(last_source.port) +
         ": ignored; is another sensor sending to this port?";
}

std::vector<double> SensorDriver::clockLagSamplesMs() const {
  std::lock_guard lock(lag_mutex_);
  return lags_ms_;
}

}  // namespace rigcal::pipeline
