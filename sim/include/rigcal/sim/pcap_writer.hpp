#pragma once
// Classic pcap files (nanosecond timestamps, magic 0xa1b23c4d, Ethernet link type) holding UDP
// datagrams we frame ourselves: Ethernet II + IPv4 (header checksum, identification per source) + UDP
// (checksum 0, legal for IPv4). A datagram larger than the MTU is split into IPv4 fragments, as Ouster
// sensors' packets are on the wire; fragments follow each other at wire speed.
#include <array>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <span>
#include <vector>

#include "rigcal/core/atomic_file.hpp"
#include "rigcal/core/time.hpp"
#include "rigcal/sim/random.hpp"

namespace rigcal::sim {

using MacAddress = std::array<std::uint8_t, 6>;

struct NetEndpoint {
  std::uint32_t address = 0;  // IPv4, host byte order
  std::uint16_t port = 0;
  MacAddress mac{};
};

/// "a.b.c.d" → host-order IPv4; throws std::invalid_argument naming the text.
std::uint32_t ipv4FromText(const std::string& text);
/// A locally administered unicast MAC derived from an IPv4 address (02:00:a:b:c:d).
MacAddress macForAddress(std::uint32_t address);

/// Time a frame of `bytes` (with preamble, FCS and inter-frame gap) occupies a 1 Gbit/s link.
TimeNs wireTimeNs(std::size_t bytes);

class PcapWriter {
 public:
  struct Options {
    std::size_t mtu = 1500;
    std::uint32_t snaplen = 65535;
  };
  /// Throws std::runtime_error "<file>: <reason>" when the file cannot be created.
  explicit PcapWriter(const std::filesystem::path& file) : PcapWriter(file, Options{}) {}
  PcapWriter(const std::filesystem::path& file, Options options);

  /// Writes one UDP datagram: one frame, or IPv4 fragments each stamped `capture_ns` plus the wire
  /// time of the fragments before it. Returns the stamp of the last frame written.
  TimeNs writeDatagram(const NetEndpoint& source, const NetEndpoint& destination,
                       std::span<const std::uint8_t> payload, TimeNs capture_ns);
  /// Writes one raw Ethernet frame.
  void writeFrame(std::span<const std::uint8_t> frame, TimeNs capture_ns);
  /// Flushes, closes and puts the file in place (written atomically: before close() or when it fails,
  /// nothing is at the final name); throws std::runtime_error on an I/O error.
  void close();
  [[nodiscard]] std::uint64_t frames() const { return frames_; }

 private:
  std::filesystem::path file_;
  Options options_;
  std::unique_ptr<AtomicFile> file_out_;
  std::ostream& out_;
  std::map<std::uint32_t, std::uint16_t> next_id_;  // IPv4 identification per source address
  std::vector<std::uint8_t> frame_;
  std::uint64_t frames_ = 0;
};

/// Capture stamps as a NIC gives them: the send time plus a link latency and a small seeded jitter,
/// never before the previous frame has finished arriving (so stamps are monotonic per file).
class NicClock {
 public:
  explicit NicClock(std::uint64_t seed, TimeNs latency_ns = 40'000, TimeNs jitter_ns = 20'000)
      : rng_(seed), latency_(latency_ns), jitter_(jitter_ns) {}
  /// The capture stamp of a datagram sent (true clock) at `send_ns` that occupies `wire_ns`.
  TimeNs stamp(TimeNs send_ns, TimeNs wire_ns);

 private:
  Rng rng_;
  TimeNs latency_, jitter_;
  TimeNs free_at_ = 0;  // when the link is free again
};

}  // namespace rigcal::sim
