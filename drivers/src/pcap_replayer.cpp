#include "rigcal/drivers/pcap_replayer.hpp"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <ctime>
#include <span>
#include <stdexcept>

#include "rigcal/drivers/pacing.hpp"
#include "rigcal/drivers/pcap_source.hpp"

namespace rigcal::drivers {

PcapReplayer::PcapReplayer(std::filesystem::path capture, ReplayConfig config)
    : capture_(std::move(capture)), config_(config) {
  if (!isLoopback(config_.target_address) && !config_.allow_remote)
    throw std::invalid_argument("target " + formatIpv4(config_.target_address) +
                                " is outside 127.0.0.0/8; replaying to another host needs --allow-remote");
  if (!std::isfinite(config_.rate) || config_.rate < 0)
    throw std::invalid_argument("rate must be a positive number, or 'max'");
  if (config_.port_offset < -65535 || config_.port_offset > 65535)
    throw std::invalid_argument("port offset " + std::to_string(config_.port_offset) +
                                " is outside -65535..65535");
  PcapSource probe(capture_, config_.filter);  // throws "<file>: <reason>" now rather than in run()
}

PcapReplayer::~PcapReplayer() {
  for (const auto& [source, fd] : sockets_) ::close(fd);
}

int PcapReplayer::socketFor(const UdpEndpoint& source) {
  const auto key = std::make_pair(source.address, source.port);
  if (auto it = sockets_.find(key); it != sockets_.end()) return it->second;
  const int fd = ::socket(AF_INET, SOCK_DGRAM | SOCK_CLOEXEC, 0);
  if (fd < 0) throw std::runtime_error(std::string("cannot create a UDP socket: ") + std::strerror(errno));
  // Room for bursts of large (Ouster) datagrams; capped by net.core.wmem_max.
  const int bytes = 4 << 20;
  setsockopt(fd, SOL_SOCKET, SO_SNDBUF, &bytes, sizeof bytes);
  // Bind now, on the target's side (an ephemeral port): one stable source port per original source.
  sockaddr_in local{};
  local.sin_family = AF_INET;
  local.sin_addr.s_addr = htonl(isLoopback(config_.target_address) ? 0x7f000001u : INADDR_ANY);
  if (::bind(fd, reinterpret_cast<const sockaddr*>(&local), sizeof local) != 0) {
    const int err = errno;
    ::close(fd);
    throw std::runtime_error(std::string("cannot bind a UDP socket: ") + std::strerror(err));
  }
  sockets_.emplace(key, fd);
  return fd;
}

ReplayStats PcapReplayer::run() {
  ReplayStats stats;
  const bool paced = config_.rate > 0;
  std::optional<TimeNs> start_wall;      // monotonic time of the first send
  TimeNs start_realtime = 0;              // the same instant on the wall clock (for rewrite)
  std::vector<std::uint8_t> rewritten;
  TimeNs pass_offset_ns = 0;              // capture time already played in earlier passes (scaled)
  TimeNs last_deadline = 0;
  TimeNs last_send = 0;

  sockaddr_in target{};
  target.sin_family = AF_INET;
  target.sin_addr.s_addr = htonl(config_.target_address);

  while (true) {
    PcapSource source(capture_, config_.filter);
    std::optional<TimeNs> pass_first;
    TimeNs pass_last = 0;
    std::uint64_t pass_packets = 0;
    while (auto packet = source.next()) {
      if (stop_.load(std::memory_order_relaxed)) break;
      if (!pass_first) pass_first = packet->receive_ns;
      pass_last = std::max(pass_last, packet->receive_ns);
      const int port = int(packet->destination.port) + config_.port_offset;
      if (port < 1 || port > 65535)
        throw std::invalid_argument("port offset " + std::to_string(config_.port_offset) + " moves port " +
                                    std::to_string(packet->destination.port) + " outside 1..65535");
      const int fd = socketFor(packet->source);

      TimeNs deadline = 0;
      if (!start_wall) {
        start_wall = monotonicNow();
        timespec now{};
        ::clock_gettime(CLOCK_REALTIME, &now);
        start_realtime = TimeNs(now.tv_sec) * kNsPerSec + now.tv_nsec;
      }
      std::span<const std::uint8_t> payload = packet->payload;
      if (config_.rewrite) {
        rewritten.assign(payload.begin(), payload.end());
        config_.rewrite(*packet, rewritten, start_realtime + pass_offset_ns - *pass_first);
        payload = rewritten;
      }
      if (paced) {
        const TimeNs recorded = packet->receive_ns - *pass_first;
        deadline = *start_wall + pass_offset_ns + TimeNs(double(recorded) / config_.rate);
        deadline = std::max(deadline, last_deadline);  // a capture clock that steps back: send at once
        last_deadline = deadline;
        if (!sleepUntil(deadline, stop_)) break;
      }
      const TimeNs send_time = monotonicNow();
      if (paced) {
        const TimeNs lateness = send_time - deadline;
        stats.max_lateness_ns = std::max(stats.max_lateness_ns, lateness);
        if (lateness > config_.late_threshold_ns) ++stats.late_packets;
      }
      target.sin_port = htons(std::uint16_t(port));
      ssize_t rc;
      do {
        rc = ::sendto(fd, payload.data(), payload.size(), 0,
                      reinterpret_cast<const sockaddr*>(&target), sizeof target);
      } while (rc < 0 && errno == EINTR && !stop_.load(std::memory_order_relaxed));
      if (rc < 0) {
        ++stats.send_errors;
      } else {
        ++stats.packets;
        stats.bytes += payload.size();
      }
      last_send = monotonicNow();
      ++pass_packets;
    }
    if (pass_first) stats.capture_span_ns = pass_last - *pass_first;
    if (stop_.load(std::memory_order_relaxed)) {
      stats.stopped = true;
      break;
    }
    ++stats.loops;
    if (!config_.loop || pass_packets == 0) break;
    // The next pass starts one mean packet interval after this one's last packet.
    const TimeNs span = stats.capture_span_ns;
    const TimeNs gap = pass_packets > 1 ? span / TimeNs(pass_packets - 1) : 100 * kNsPerMs;
    pass_offset_ns += TimeNs(double(span + gap) / (paced ? config_.rate : 1.0));
  }
  stats.duration_ns = start_wall ? last_send - *start_wall : 0;
  stats.sockets = sockets_.size();
  return stats;
}

}  // namespace rigcal::drivers
