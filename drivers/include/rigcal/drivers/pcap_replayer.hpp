#pragma once
// Re-sends the UDP payloads of a capture to a target address, keeping each datagram's destination port
// (plus an offset) and the recorded inter-packet timing, so that a live pipeline can be run from a file.
// Each original source endpoint (address, port) gets its own sending socket, so the receiver still
// sees one distinct source port per original source. Loopback targets only, unless allowed explicitly.
#include <atomic>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <map>
#include <utility>
#include <vector>

#include "rigcal/core/time.hpp"
#include "rigcal/drivers/packet_source.hpp"

namespace rigcal::drivers {

struct ReplayConfig {
  std::uint32_t target_address = 0x7f000001;  // host byte order; 127.0.0.1
  double rate = 1.0;               // speed factor on the recorded timing; 0 = as fast as possible
  bool loop = false;               // start over at the end until stop()
  int port_offset = 0;             // added to every destination port (result must stay in 1..65535)
  bool allow_remote = false;       // permit targets outside 127.0.0.0/8
  PacketFilter filter;             // which datagrams of the capture to send
  TimeNs late_threshold_ns = kNsPerMs;  // a send later than its deadline by more than this is "late"
  /// Optional: rewrites a copy of each datagram's payload before it is sent (restamping).
  /// `capture_to_wall_ns` added to a capture time gives the wall-clock (CLOCK_REALTIME) time this pass
  /// sends it at (exactly at rate 1; later passes of --loop continue where the last one ended).
  std::function<void(const UdpPacket& packet, std::vector<std::uint8_t>& payload, TimeNs capture_to_wall_ns)>
      rewrite;
};

struct ReplayStats {
  std::uint64_t packets = 0;       // datagrams sent
  std::uint64_t bytes = 0;         // payload bytes sent
  std::uint64_t send_errors = 0;   // sendto failures (e.g. ENOBUFS), datagram skipped
  std::uint64_t late_packets = 0;  // sent more than late_threshold_ns after their deadline
  TimeNs max_lateness_ns = 0;
  TimeNs duration_ns = 0;          // wall time from the first send to the last
  TimeNs capture_span_ns = 0;      // recorded time from the first to the last datagram sent (one pass)
  std::uint64_t loops = 0;         // complete passes over the capture
  std::size_t sockets = 0;         // sending sockets = distinct original source endpoints
  bool stopped = false;            // ended by stop()
};

class PcapReplayer {
 public:
  /// Checks the config (target address policy, rate, port offset) and that the capture opens; throws
  /// std::invalid_argument (bad config: the message names the option) or std::runtime_error (file).
  PcapReplayer(std::filesystem::path capture, ReplayConfig config);
  ~PcapReplayer();
  PcapReplayer(const PcapReplayer&) = delete;
  PcapReplayer& operator=(const PcapReplayer&) = delete;

  /// Sends the capture (once, or until stop() with loop). Blocks the calling thread. Call once.
  ReplayStats run();
  /// Ends run() soon (within ~10 ms) from another thread or a signal handler.
  void stop() { stop_.store(true, std::memory_order_relaxed); }

  /// True for addresses in 127.0.0.0/8.
  static bool isLoopback(std::uint32_t address) { return (address >> 24) == 127; }

 private:
  int socketFor(const UdpEndpoint& source);

  std::filesystem::path capture_;
  ReplayConfig config_;
  std::atomic<bool> stop_{false};
  static_assert(std::atomic<bool>::is_always_lock_free, "stop() must be async-signal-safe");
  std::map<std::pair<std::uint32_t, std::uint16_t>, int> sockets_;  // original source → socket
};

}  // namespace rigcal::drivers
