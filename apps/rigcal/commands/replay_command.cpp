// `rigcal replay FILE --to 127.0.0.1 [--rate 1.0|max] [--loop] [--port-offset N]`: re-sends a capture's
// UDP payloads over the network with their recorded timing, so a live driver can be run from a file.
#include <csignal>
#include <cstdio>
#include <iostream>

#include "../commands.hpp"
#include "../exit_codes.hpp"
#include "rigcal/drivers/pcap_replayer.hpp"

namespace rigcal::app {

namespace {

drivers::PcapReplayer* g_replayer = nullptr;  // for the signal handler only

extern "C" void stopReplay(int) {
  if (g_replayer) g_replayer->stop();  // an atomic store: async-signal-safe
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
  };
  auto o = std::make_shared<Options>();
  cmd->add_option("file", o->file, "Capture file (pcap or pcapng)")->required();
  cmd->add_option("--to", o->to, "Target IPv4 address (127.0.0.0/8 unless --allow-remote)")->required();
  cmd->add_option("--rate", o->rate, "Speed factor on the recorded timing, or 'max'")->capture_default_str();
  cmd->add_flag("--loop", o->loop, "Start over at the end until interrupted");
  cmd->add_option("--port-offset", o->port_offset, "Added to every destination port");
  cmd->add_option("--port", o->only_port, "Send only datagrams to this destination port (0: all)");
  cmd->add_flag("--allow-remote", o->allow_remote, "Allow a target outside the loopback network");
  cmd->footer(kExitCodesHelp);
  cmd->callback([o] {
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
    if (s.stopped) throw CommandFailed(kExitInterrupted, "replay interrupted");
  });
}

}  // namespace rigcal::app
