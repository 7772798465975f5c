// `rigcal decode FILE --sensor MODEL ... --out DIR`: decodes a capture into one file per scan.
// `rigcal decode --bag PATH [--topic T] --sensor MODEL ...` reads the packets from a ROS 2 bag instead.
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>

#include "../commands.hpp"
#include "../exit_codes.hpp"
#include "../output_folder.hpp"
#include "../rig_loading.hpp"
#include "rigcal/bag/bag_packet_source.hpp"
#include "rigcal/core/pcd_io.hpp"
#include "rigcal/drivers/packet_decoder.hpp"
#include "rigcal/drivers/pcap_source.hpp"
#include "rigcal/drivers/robosense/robosense_decoder.hpp"
#include "rigcal/drivers/scan_assembler.hpp"
#include "rigcal/drivers/scan_pump.hpp"

namespace rigcal::app {

namespace {

struct DecodeOptions {
  std::string file, bag, topic, model, calibration, metadata, out, format = "pcd", address, time_source = "sensor";
  int port = 0;
  double cut_angle = 0.0;
  double min_range = 0.3, max_range = 300.0;
};

void writeCsv(const std::filesystem::path& path, const Scan& scan) {
  AtomicFile atomic(path);
  std::ostream& out = atomic.stream();
  out << "x,y,z,intensity,ring,offset_ns\n" << std::setprecision(9);
  for (std::size_t i = 0; i < scan.size(); ++i)
    out << scan.x[i] << ',' << scan.y[i] << ',' << scan.z[i] << ',' << scan.intensity[i] << ','
        << scan.ring[i] << ',' << scan.offset_ns[i] << '\n';
  commitOutput(atomic);
}

void run(const DecodeOptions& o) {
  if (o.file.empty() == o.bag.empty())
    throw CommandFailed(kExitUsage, "decode: give either a capture FILE or --bag PATH");
  if (!o.file.empty()) requireInputFile(o.file, "capture");
  if (!o.calibration.empty()) requireInputFile(o.calibration, "calibration file");
  if (!o.metadata.empty()) requireInputFile(o.metadata, "metadata file");
  drivers::DecoderConfig config;
  config.model = o.model;
  config.calibration = o.calibration;
  config.metadata = o.metadata;
  config.time_source = o.time_source == "host" ? TimeSource::kHostReceive : TimeSource::kSensorClock;
  config.min_range_m = float(o.min_range);
  config.max_range_m = float(o.max_range);

  prepareOutputFolder(o.out);
  std::unique_ptr<drivers::PacketDecoder> decoder;
  std::unique_ptr<drivers::PacketSource> source;
  if (!o.bag.empty() && (o.port || !o.address.empty()))
    throw CommandFailed(kExitUsage, "decode: --port/--address filter pcap datagrams; with --bag choose --topic");
  try {
    decoder = drivers::makeDecoder(config);
    if (!o.bag.empty()) {
      auto bag = std::make_unique<bag::BagPacketSource>(o.bag, o.topic);
      std::cout << "bag topic " << bag->topic() << " (" << bag->type() << ")\n";
      source = std::move(bag);
    } else {
      drivers::PacketFilter filter;
      if (o.port) filter.destination_port = std::uint16_t(o.port);
      if (!o.address.empty()) filter.source_address = drivers::parseIpv4(o.address);
      source = std::make_unique<drivers::PcapSource>(o.file, filter);
    }
  } catch (const std::exception& e) {
    throw CommandFailed(kExitInput, e.what());
  }

  std::size_t written = 0;
  drivers::ScanAssembler assembler(o.model, drivers::AssemblerConfig{o.cut_angle}, [&](Scan&& scan) {
    char name[32];
    std::snprintf(name, sizeof name, "scan_%06zu.%s", written, o.format.c_str());
    const auto path = std::filesystem::path(o.out) / name;
    if (o.format == "csv")
      writeCsv(path, scan);
    else
      writePcd(path, toTable(scan));
    std::cout << name << "  points " << scan.size() << "  stamp_ns " << scan.stamp_ns << "  span_ms "
              << std::fixed << std::setprecision(2) << double(scan.endTime() - scan.stamp_ns) * 1e-6
              << "  missing_packets " << scan.missing_packets << '\n';
    ++written;
  });
  drivers::pumpScans(*source, *decoder, assembler);

  const auto& a = assembler.stats();
  const auto& s = source->stats();
  std::cout << "decoded " << written << " scans from " << a.packets << " packets (" << a.malformed
            << " malformed, " << a.ignored << " ignored, " << a.lost_packets << " lost; " << s.filtered
            << " other datagrams filtered out)\n";
  if (a.malformed) std::cerr << "warning: last malformed packet: " << a.last_error << '\n';
  if (const auto* rs = dynamic_cast<const drivers::RobosenseDecoder*>(decoder.get()); rs && rs->stats().dropped_without_difop)
    std::cerr << "warning: " << rs->stats().dropped_without_difop << " " << o.model
              << " data packets dropped: no DIFOP packet (angle calibration, port 7788) came before the end\n";
  if (!source->warning().empty()) std::cerr << "warning: " << source->warning() << '\n';
  if (written == 0)
    throw CommandFailed(kExitNotEnoughData, (o.bag.empty() ? o.file : o.bag) + ": no " + o.model + " scans decoded");
}

}  // namespace

void addDecodeCommand(CLI::App& app) {
  auto o = std::make_shared<DecodeOptions>();
  auto* cmd = app.add_subcommand("decode", "Decode a capture of one lidar into one file per scan");
  cmd->add_option("file", o->file, "pcap or pcapng capture");
  cmd->add_option("--bag", o->bag, "ROS 2 bag (rosbag2 folder, .mcap or .db3) with packet-scan messages");
  cmd->add_option("--topic", o->topic, "The bag's packet topic (needed when it holds several)");
  cmd->add_option("--sensor", o->model, "Lidar model, e.g. VLP-16, OS1-64, PandarXT32")->required();
  cmd->add_option("--calibration", o->calibration, "Velodyne YAML/XML or Hesai angle CSV");
  cmd->add_option("--metadata", o->metadata, "Ouster sensor_info JSON");
  cmd->add_option("--port", o->port, "Only datagrams to this UDP port")->check(CLI::Range(1, 65535));
  cmd->add_option("--address", o->address, "Only datagrams from this sensor IPv4 address");
  cmd->add_option("--time-source", o->time_source, "sensor (packet clock) or host (capture time)")
      ->check(CLI::IsMember({"sensor", "host"}));
  cmd->add_option("--cut-angle", o->cut_angle, "Azimuth (deg) where a scan starts")->check(CLI::Range(0.0, 360.0));
  cmd->add_option("--min-range", o->min_range, "Drop returns closer than this (m)");
  cmd->add_option("--max-range", o->max_range, "Drop returns farther than this (m)");
  cmd->add_option("--out", o->out, "Output folder")->required();
  cmd->add_option("--format", o->format, "pcd or csv")->check(CLI::IsMember({"pcd", "csv"}));
  cmd->footer(kExitCodesHelp);
  cmd->callback([o] { run(*o); });
}

}  // namespace rigcal::app
