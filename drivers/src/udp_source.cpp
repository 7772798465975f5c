#include "rigcal/drivers/udp_source.hpp"

#include <arpa/inet.h>
#include <linux/sock_diag.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/eventfd.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <ctime>
#include <stdexcept>

namespace rigcal::drivers {

namespace {

std::string endpointText(const UdpSourceConfig& c) {
  return "udp " + (c.bind_address.empty() ? std::string("0.0.0.0") : c.bind_address) + ":" +
         std::to_string(c.port);
}

[[noreturn]] void fail(const UdpSourceConfig& c, const std::string& what) {
  throw std::runtime_error(endpointText(c) + ": " + what);
}

std::string errnoText(int err) { return std::strerror(err); }

std::uint32_t parseAddressOrFail(const UdpSourceConfig& c, const std::string& text, const char* role) {
  in_addr a{};
  if (inet_pton(AF_INET, text.c_str(), &a) != 1)
    fail(c, std::string(role) + " '" + text + "' is not an IPv4 address");
  return ntohl(a.s_addr);
}

TimeNs realtimeNow() {
  timespec ts{};
  clock_gettime(CLOCK_REALTIME, &ts);
  return TimeNs(ts.tv_sec) * kNsPerSec + ts.tv_nsec;
}

// Control bytes per message: a receive timestamp, the drop counter and the packet's destination.
constexpr std::size_t kControlBytes =
    CMSG_SPACE(sizeof(timespec)) + CMSG_SPACE(sizeof(std::uint32_t)) + CMSG_SPACE(sizeof(in_pktinfo));

}  // namespace

UdpSource::UdpSource(UdpSourceConfig config) : config_(std::move(config)) {
  if (config_.batch == 0) fail(config_, "batch must be at least 1");
  if (config_.max_datagram == 0 || config_.max_datagram > 65535)
    fail(config_, "max_datagram must be in 1..65535");

  std::uint32_t bind_addr = INADDR_ANY;
  if (!config_.bind_address.empty()) bind_addr = parseAddressOrFail(config_, config_.bind_address, "bind address");
  std::optional<std::uint32_t> group;
  if (!config_.multicast_group.empty()) {
    group = parseAddressOrFail(config_, config_.multicast_group, "multicast group");
    if ((*group >> 28) != 0xE)
      fail(config_, "multicast group '" + config_.multicast_group + "' is not a multicast address (224.0.0.0/4)");
  }
  std::uint32_t mc_interface = INADDR_ANY;
  if (!config_.multicast_interface.empty())
    mc_interface = parseAddressOrFail(config_, config_.multicast_interface, "multicast interface");

  fd_ = ::socket(AF_INET, SOCK_DGRAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
  if (fd_ < 0) fail(config_, "cannot create socket: " + errnoText(errno));
  wake_fd_ = ::eventfd(0, EFD_NONBLOCK | EFD_CLOEXEC);
  if (wake_fd_ < 0) {
    const int err = errno;
    ::close(fd_);
    fail(config_, "cannot create eventfd: " + errnoText(err));
  }

  try {
    const int one = 1;
    if (config_.reuse) {
      if (setsockopt(fd_, SOL_SOCKET, SO_REUSEADDR, &one, sizeof one) != 0 ||
          setsockopt(fd_, SOL_SOCKET, SO_REUSEPORT, &one, sizeof one) != 0)
        fail(config_, "cannot set SO_REUSEADDR/SO_REUSEPORT: " + errnoText(errno));
    }
    // A large receive queue rides out scheduling hiccups. SO_RCVBUFFORCE passes net.core.rmem_max
    // when we hold CAP_NET_ADMIN; otherwise the plain request is capped by it.
    if (config_.receive_buffer_bytes > 0) {
      const int want = config_.receive_buffer_bytes;
      if (setsockopt(fd_, SOL_SOCKET, SO_RCVBUFFORCE, &want, sizeof want) != 0)
        setsockopt(fd_, SOL_SOCKET, SO_RCVBUF, &want, sizeof want);  // best effort; granted size reported
    }
    socklen_t len = sizeof granted_rcvbuf_;
    getsockopt(fd_, SOL_SOCKET, SO_RCVBUF, &granted_rcvbuf_, &len);

    if (setsockopt(fd_, SOL_SOCKET, SO_TIMESTAMPNS, &one, sizeof one) != 0)
      fail(config_, "cannot enable SO_TIMESTAMPNS: " + errnoText(errno));
    // Optional extras: a kernel without them still works (drops then come from SO_MEMINFO only).
    setsockopt(fd_, SOL_SOCKET, SO_RXQ_OVFL, &one, sizeof one);
    setsockopt(fd_, IPPROTO_IP, IP_PKTINFO, &one, sizeof one);

    sockaddr_in local{};
    local.sin_family = AF_INET;
    local.sin_port = htons(config_.port);
    local.sin_addr.s_addr = htonl(bind_addr);
    if (::bind(fd_, reinterpret_cast<const sockaddr*>(&local), sizeof local) != 0) {
      const int err = errno;
      if (err == EADDRINUSE)
        fail(config_, "port already in use (another driver or tool is listening there; "
                      "stop it, or set reuse to share the port)");
      if (err == EADDRNOTAVAIL)
        fail(config_, "bind address is not an address of this machine");
      if (err == EACCES) fail(config_, "permission denied (ports below 1024 need privileges)");
      fail(config_, "cannot bind: " + errnoText(err));
    }
    sockaddr_in bound{};
    socklen_t bound_len = sizeof bound;
    getsockname(fd_, reinterpret_cast<sockaddr*>(&bound), &bound_len);
    port_ = ntohs(bound.sin_port);
    local_address_ = bind_addr;

    if (group) {
      ip_mreq request{};
      request.imr_multiaddr.s_addr = htonl(*group);
      request.imr_interface.s_addr = htonl(mc_interface);
      if (setsockopt(fd_, IPPROTO_IP, IP_ADD_MEMBERSHIP, &request, sizeof request) != 0) {
        const int err = errno;
        fail(config_, "cannot join multicast group " + config_.multicast_group +
                          (config_.multicast_interface.empty() ? std::string()
                                                               : " on interface " + config_.multicast_interface) +
                          ": " + errnoText(err));
      }
    }
  } catch (...) {
    ::close(fd_);
    ::close(wake_fd_);
    throw;
  }

  // Batch buffers: allocated here once, reused for every recvmmsg.
  const std::size_t n = config_.batch;
  control_stride_ = kControlBytes;
  data_.resize(n * config_.max_datagram);
  control_.resize(n * control_stride_);
  messages_.resize(n);
  iovecs_.resize(n);
  addresses_.resize(n);
}

UdpSource::~UdpSource() {
  if (fd_ >= 0) ::close(fd_);
  if (wake_fd_ >= 0) ::close(wake_fd_);
}

void UdpSource::stop() {
  stopped_.store(true, std::memory_order_release);
  const std::uint64_t one = 1;
  // write(2) is async-signal-safe; a full counter (EAGAIN) still leaves the fd readable.
  [[maybe_unused]] const ssize_t rc = ::write(wake_fd_, &one, sizeof one);
}

void UdpSource::noteDropCounter(std::uint32_t cumulative) {
  // The counter is cumulative over the socket's life and 32 bits wide: add forward steps only (a
  // datagram queued before the last SO_MEMINFO read carries an older, smaller value).
  if (!last_drop_counter_) {
    stats_.kernel_drops += cumulative;
  } else {
    const auto step = std::int32_t(cumulative - *last_drop_counter_);
    if (step <= 0) return;
    stats_.kernel_drops += std::uint32_t(step);
  }
  last_drop_counter_ = cumulative;
}

void UdpSource::refreshKernelDrops() {
  std::uint32_t meminfo[SK_MEMINFO_VARS] = {};
  socklen_t len = sizeof meminfo;
  if (getsockopt(fd_, SOL_SOCKET, SO_MEMINFO, meminfo, &len) == 0 &&
      len > SK_MEMINFO_DROPS * sizeof(std::uint32_t))
    noteDropCounter(meminfo[SK_MEMINFO_DROPS]);
}

bool UdpSource::receiveBatch() {
  const std::size_t n = config_.batch;
  for (std::size_t i = 0; i < n; ++i) {
    iovecs_[i].iov_base = data_.data() + i * config_.max_datagram;
    iovecs_[i].iov_len = config_.max_datagram;
    msghdr& h = messages_[i].msg_hdr;
    h.msg_name = &addresses_[i];
    h.msg_namelen = sizeof(sockaddr_in);
    h.msg_iov = &iovecs_[i];
    h.msg_iovlen = 1;
    h.msg_control = control_.data() + i * control_stride_;
    h.msg_controllen = control_stride_;
    h.msg_flags = 0;
    messages_[i].msg_len = 0;
  }
  int got;
  do {
    got = ::recvmmsg(fd_, messages_.data(), unsigned(n), MSG_DONTWAIT, nullptr);
  } while (got < 0 && errno == EINTR);
  if (got <= 0) {
    // EAGAIN: nothing waiting. Anything else (e.g. a pending ICMP error) is transient for UDP.
    received_ = cursor_ = 0;
    return false;
  }
  received_ = std::size_t(got);
  cursor_ = 0;
  return true;
}

bool UdpSource::waitReadable(int timeout_ms) {
  pollfd fds[2] = {{fd_, POLLIN, 0}, {wake_fd_, POLLIN, 0}};
  int rc;
  do {
    rc = ::poll(fds, 2, timeout_ms);
  } while (rc < 0 && errno == EINTR && !stopped());
  if (rc <= 0 || stopped()) return false;
  return (fds[0].revents & (POLLIN | POLLERR)) != 0;
}

std::optional<UdpPacket> UdpSource::next() {
  using Clock = std::chrono::steady_clock;
  std::optional<Clock::time_point> deadline;
  while (!stopped()) {
    while (cursor_ < received_) {
      const std::size_t i = cursor_++;
      const msghdr& h = messages_[i].msg_hdr;
      UdpPacket packet;
      packet.receive_ns = 0;
      packet.destination = {local_address_, port_};
      for (cmsghdr* c = CMSG_FIRSTHDR(&h); c; c = CMSG_NXTHDR(const_cast<msghdr*>(&h), c)) {
        if (c->cmsg_level == SOL_SOCKET && c->cmsg_type == SCM_TIMESTAMPNS &&
            c->cmsg_len >= CMSG_LEN(sizeof(timespec))) {
          timespec ts;
          std::memcpy(&ts, CMSG_DATA(c), sizeof ts);
          packet.receive_ns = TimeNs(ts.tv_sec) * kNsPerSec + ts.tv_nsec;
        } else if (c->cmsg_level == SOL_SOCKET && c->cmsg_type == SO_RXQ_OVFL &&
                   c->cmsg_len >= CMSG_LEN(sizeof(std::uint32_t))) {
          std::uint32_t drops;
          std::memcpy(&drops, CMSG_DATA(c), sizeof drops);
          noteDropCounter(drops);
        } else if (c->cmsg_level == IPPROTO_IP && c->cmsg_type == IP_PKTINFO &&
                   c->cmsg_len >= CMSG_LEN(sizeof(in_pktinfo))) {
          in_pktinfo info;
          std::memcpy(&info, CMSG_DATA(c), sizeof info);
          packet.destination.address = ntohl(info.ipi_addr.s_addr);
        }
      }
      if (h.msg_flags & MSG_TRUNC) {
        ++truncated_;
        ++stats_.malformed;
        continue;
      }
      if (packet.receive_ns == 0) packet.receive_ns = realtimeNow();
      packet.source = {ntohl(addresses_[i].sin_addr.s_addr), ntohs(addresses_[i].sin_port)};
      packet.payload = {data_.data() + i * config_.max_datagram, messages_[i].msg_len};
      // The destination port is the socket's own: only the source-address filter applies.
      if (config_.filter.source_address && packet.source.address != *config_.filter.source_address) {
        ++stats_.filtered;
        stats_.last_filtered = packet.source;
        continue;
      }
      ++stats_.packets;
      return packet;
    }
    // The batch is used up. The clock is read once per batch, not per datagram; the deadline also
    // bounds a next() that only sees datagrams the filter rejects.
    const auto now = Clock::now();
    if (!deadline) {
      deadline = now + config_.timeout;
    } else if (now >= *deadline) {
      refreshKernelDrops();
      return std::nullopt;
    }
    if (receiveBatch()) continue;
    const auto left = std::chrono::ceil<std::chrono::milliseconds>(*deadline - now);
    if (!waitReadable(int(left.count()))) {
      if (stopped()) return std::nullopt;
      if (Clock::now() >= *deadline) {
        refreshKernelDrops();
        return std::nullopt;
      }
    }
  }
  return std::nullopt;
}

}  // namespace rigcal::drivers
