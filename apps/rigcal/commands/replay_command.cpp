// `rigcal replay FILE --to 127.0.0.1 [--rate 1.0|max] [--loop] [--port-offset N] [--config RIG
// [--clock now|recorded]]`: re-sends a capture's UDP payloads over the network with their recorded
// timing, so a live driver can be run from a file.
//
// Replay-time policy. The receiving drivers cannot tell a replay from a live sensor, and sensors do not
// carry the same clock: a Velodyne sends only microseconds past the hour (the receiver takes the hour
// from its own clock, so an old capture decodes as "this hour"), an Ouster or Hesai its full sensor
// time (the day it was recorded), and a `time_source: host` sensor gets the receive time (now). Played
// as recorded, the sensors of one capture end up hours or years apart and nothing pairs. With the rig
// file, replay therefore shifts every sensor timestamp in the packets by one common amount (whole
// microseconds) so the capture looks recorded now: the first packet's sensor time becomes the moment
// it is sent. Offsets between the sensors' clocks in the capture are kept exactly. `--clock recorded`
// sends the packets untouched.
#include <csignal>
#include <cstdio>
#include <iomanip>
#include <iostream>
#include <optional>
#include <sstream>
#include <vector>

#include "../commands.hpp"
#include "../exit_codes.hpp"
#include "../rig_loading.hpp"
#include "rigcal/config/rig_config.hpp"
#include "rigcal/drivers/packet_restamper.hpp"
#include "rigcal/drivers/pcap_replayer.hpp"
#include "rigcal/pipeline/sensor_driver.hpp"

namespace rigcal::app {

namespace {

drivers::PcapReplayer* g_replayer = nullptr;  // for the signal handler only

extern "C" void stopReplay(int) {
  if (g_replayer) g_replayer->stop();  // an atomic store: async-signal-safe
}

/// Restamps each rig sensor's packets (matched by destination port and, when the rig names one, source
/// address) by the replay's capture-to-now shift; counts what it did for the summary.
struct Restamping {
  struct Sensor {
    std::string name;
    std::uint16_t port = 0;
    std::optional<std::uint32_t> address;
    drivers::PacketRestamper restamper;
    std::uint64_t packets = 0;
  };
  std::vector<Sensor> sensors;
  std::optional<TimeNs> shift_ns;  // of the first pass

  void rewrite(const drivers::UdpPacket& packet, std::vector<std::uint8_t>& payload, TimeNs capture_to_wall_ns) {
    if (!shift_ns) shift_ns = capture_to_wall_ns;
    for (Sensor& s : sensors) {
      if (packet.destination.port != s.port || (s.address && packet.source.address != *s.address)) continue;
      if (s.restamper.restamp(payload, capture_to_wall_ns / kNsPerUs)) ++s.packets;
      return;
    }
  }

  [[nodiscard]] std::string summary() const {
    std::ostringstream o;
    o << "sensor clocks moved by " << std::fixed << std::setprecision(3) << toSeconds(shift_ns.value_or(0))
      << " s to now; restamped";
    for (const Sensor& s : sensors) o << ' ' << s.name << ' ' << s.packets;
    o << " packets";
    return o.str();
  }
};

std::shared_ptr<Restamping> makeRestamping(const std::string& rig_file) {
  const config::RigConfig rig = loadRig(rig_file);
  auto r = std::make_shared<Restamping>();
  for (const auto& sensor : rig.sensors) {
    try {
      std::optional<std::uint32_t> address;
      if (sensor.source.address) address = drivers::parseIpv4(*sensor.source.address);
      r->sensors.push_back({sensor.name, sensor.source.port, address,
                            drivers::PacketRestamper(pipeline::decoderConfigFor(sensor)), 0});
    } catch (const std::exception& e) {
      throw CommandFailed(kExitConfig, rig_file + ": sensor '" + sensor.name + "': " + e.what());
    }
  }
  return r;
}

}  // namespace

void addReplayCommand(CLI::App& app) {
  auto* cmd = app.add_subcommand("replay", "Re-send a capture's UDP payloads with their recorded timing");
  struct Options {
    std::string file;
    std::string to;
    std::string rate = "1.0";
    bool loop = false;
    int port_offset = 0;
    int only_port = 0;
    bool allow_remote = false;
    std::string config;
    std::string clock;
  };
  auto o = std::make_shared<Options>();
  cmd->add_option("file", o->file, "Capture file (pcap or pcapng)")->required();
  cmd->add_option("--to", o->to, "Target IPv4 address (127.0.0.0/8 unless --allow-remote)")->required();
  cmd->add_option("--rate", o->rate, "Speed factor on the recorded timing, or 'max'")->capture_default_str();
  cmd->add_flag("--loop", o->loop, "Start over at the end until interrupted");
  cmd->add_option("--port-offset", o->port_offset, "Added to every destination port");
  cmd->add_option("--port", o->only_port, "Send only datagrams to this destination port (0: all)");
  cmd->add_flag("--allow-remote", o->allow_remote, "Allow a target outside the loopback network");
  cmd->add_option("--config", o->config, "Rig YAML file: which port is which sensor, to restamp their packets");
  cmd->add_option("--clock", o->clock,
                  "now (default with --config): shift every sensor timestamp in the packets by one amount so the "
                  "capture looks recorded now, keeping the sensors' clocks consistent with each other and with "
                  "the receiver's (Velodyne packets carry only the time past the hour); recorded (default "
                  "without --config): send the packets untouched")
      ->check(CLI::IsMember({"now", "recorded"}));
  cmd->footer(std::string("An old capture replayed with --clock recorded mixes clocks: Velodyne stamps land in the "
                          "receiver's current hour, Ouster/Hesai stamps on the recording day, so nothing pairs. ") +
              kExitCodesHelp);
  cmd->callback([o] {
    requireInputFile(o->file, "capture");
    drivers::ReplayConfig config;
    try {
      config.target_address = drivers::parseIpv4(o->to);
    } catch (const std::invalid_argument& e) {
      throw CommandFailed(kExitUsage, std::string("--to: ") + e.what());
    }
    if (o->rate == "max") {
      config.rate = 0;
    } else {
      std::size_t used = 0;
      try {
        config.rate = std::stod(o->rate, &used);
      } catch (const std::exception&) {
        used = 0;
      }
      if (used != o->rate.size() || !(config.rate > 0))
        throw CommandFailed(kExitUsage, "--rate: '" + o->rate + "' is neither a positive number nor 'max'");
    }
    config.loop = o->loop;
    config.port_offset = o->port_offset;
    config.allow_remote = o->allow_remote;
    if (o->only_port < 0 || o->only_port > 65535)
      throw CommandFailed(kExitUsage, "--port: " + std::to_string(o->only_port) + " is outside 0..65535");
    if (o->only_port > 0) config.filter.destination_port = std::uint16_t(o->only_port);
    const std::string clock = o->clock.empty() ? (o->config.empty() ? "recorded" : "now") : o->clock;
    std::shared_ptr<Restamping> restamping;
    if (clock == "now") {
      if (o->config.empty())
        throw CommandFailed(kExitUsage, "--clock now needs --config RIG.yaml (which port is which sensor model)");
      restamping = makeRestamping(o->config);
      config.rewrite = [restamping](const drivers::UdpPacket& p, std::vector<std::uint8_t>& payload, TimeNs shift) {
        restamping->rewrite(p, payload, shift);
      };
    }

    std::unique_ptr<drivers::PcapReplayer> replayer;
    try {
      replayer = std::make_unique<drivers::PcapReplayer>(o->file, config);
    } catch (const std::invalid_argument& e) {
      throw CommandFailed(kExitUsage, e.what());
    } catch (const std::exception& e) {
      throw CommandFailed(kExitInput, e.what());
    }

    g_replayer = replayer.get();
    struct sigaction action {};
    action.sa_handler = stopReplay;
    sigemptyset(&action.sa_mask);
    struct sigaction old_int {}, old_term {};
    sigaction(SIGINT, &action, &old_int);
    sigaction(SIGTERM, &action, &old_term);
    drivers::ReplayStats s;
    try {
      s = replayer->run();
    } catch (...) {
      sigaction(SIGINT, &old_int, nullptr);
      sigaction(SIGTERM, &old_term, nullptr);
      g_replayer = nullptr;
      throw;
    }
    sigaction(SIGINT, &old_int, nullptr);
    sigaction(SIGTERM, &old_term, nullptr);
    g_replayer = nullptr;

    const double seconds = toSeconds(s.duration_ns);
    char line[512];
    std::snprintf(line, sizeof line,
                  "replayed %llu packets, %llu bytes to %s in %.3f s (capture span %.3f s, %llu pass%s): "
                  "%.0f packets/s, %.2f MB/s; late %llu (max %.3f ms), send errors %llu, sockets %zu",
                  static_cast<unsigned long long>(s.packets), static_cast<unsigned long long>(s.bytes),
                  o->to.c_str(), seconds, toSeconds(s.capture_span_ns),
                  static_cast<unsigned long long>(s.loops), s.loops == 1 ? "" : "es",
                  seconds > 0 ? double(s.packets) / seconds : 0.0,
                  seconds > 0 ? double(s.bytes) / seconds / 1e6 : 0.0,
                  static_cast<unsigned long long>(s.late_packets), double(s.max_lateness_ns) / 1e6,
                  static_cast<unsigned long long>(s.send_errors), s.sockets);
    std::cout << line << std::endl;
    if (restamping) std::cout << restamping->summary() << std::endl;
    if (s.stopped) throw CommandFailed(kExitInterrupted, "replay interrupted");
  });
}

}  // namespace rigcal::app
