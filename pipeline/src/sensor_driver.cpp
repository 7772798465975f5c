#include "rigcal/pipeline/sensor_driver.hpp"

#include <stdexcept>

#include "rigcal/drivers/info_port_source.hpp"
#include "rigcal/drivers/paced_source.hpp"
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
drivers::PacketFilter filterFor(const config::SensorConfig& sensor) {
  drivers::PacketFilter f;
  f.destination_port = sensor.source.port;
  f.info_port = sensor.source.info_port;
  if (sensor.source.address) f.source_address = drivers::parseIpv4(*sensor.source.address);
  return f;
}
}  // namespace

SensorDriver::SensorDriver(const config::SensorConfig& sensor, const DriverInput& input,
                           const std::atomic<bool>& stop, drivers::ScanAssembler::ScanCallback on_scan)
    : sensor_(sensor),
      assembler_(sensor.name, drivers::AssemblerConfig{sensor.cut_angle_deg}, std::move(on_scan)),
      stop_(stop),
      live_(!input.pcap) {
  try {
    decoder_ = drivers::makeDecoder(decoderConfigFor(sensor));
    if (input.pcap) {
      raw_source_ = std::make_unique<drivers::PcapSource>(*input.pcap, filterFor(sensor));
      source_ = std::make_unique<drivers::PacedSource>(*raw_source_, input.rate, stop_);
    } else {
      drivers::UdpSourceConfig udp;
      udp.port = sensor.source.port;
      udp.filter = filterFor(sensor);
      if (sensor.source.multicast_group) udp.multicast_group = *sensor.source.multicast_group;
      if (sensor.source.info_port)
        source_ = std::make_unique<drivers::InfoPortSource>(udp, *sensor.source.info_port);
      else
        source_ = std::make_unique<drivers::UdpSource>(udp);
    }
  } catch (const std::exception& e) {
    throw std::runtime_error("sensor '" + sensor.name + "': " + e.what());
  }
}

SensorDriver::~SensorDriver() = default;

void SensorDriver::run(const std::function<void()>& idle) {
  drivers::pumpScans(*source_, *decoder_, assembler_, [&](bool was_idle) {
    if (stop_.load(std::memory_order_relaxed)) return false;
    if (!was_idle) return true;
    if (!live_) return false;  // a pcap that yields nothing has ended
    if (idle) idle();
    return true;
  });
}

}  // namespace rigcal::pipeline
