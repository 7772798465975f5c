#pragma once
// Receives a sensor's UDP datagrams from a live socket (Linux). One non-blocking socket, read in batches
// with recvmmsg into buffers the source owns (no allocation per datagram), stamped with the kernel's
// receive time (SO_TIMESTAMPNS). next() blocks in poll() up to a timeout, never spins; stop() wakes it
// from another thread. Kernel drops (receive queue overflow) are read from SO_RXQ_OVFL / SO_MEMINFO.
#include <atomic>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "rigcal/drivers/packet_source.hpp"

struct mmsghdr;
struct iovec;
struct sockaddr_in;

namespace rigcal::drivers {

struct UdpSourceConfig {
  std::uint16_t port = 0;            // local port; 0 picks an ephemeral one (see UdpSource::port())
  std::string bind_address;          // local IPv4 address to bind; "" = any (0.0.0.0)
  std::string multicast_group;       // "" = unicast; else joined with IP_ADD_MEMBERSHIP
  std::string multicast_interface;   // IPv4 address of the interface to join on; "" = kernel's choice
  PacketFilter filter;               // source-address filter (two sensors on one port); port is implied
  std::chrono::milliseconds timeout{100};   // longest next() waits before returning nullopt
  std::size_t batch = 64;                   // datagrams per recvmmsg call
  std::size_t max_datagram = 65535;         // bytes per receive buffer; longer datagrams are truncated
  int receive_buffer_bytes = 16 << 20;      // SO_RCVBUF request (SO_RCVBUFFORCE tried first)
  bool reuse = false;                       // SO_REUSEADDR + SO_REUSEPORT: share the port with others
};

class UdpSource final : public PacketSource {
 public:
  /// Opens and binds the socket. Throws std::runtime_error with one line naming the address and port
  /// and what is wrong (port in use, not a multicast address, no such interface, ...).
  explicit UdpSource(UdpSourceConfig config);
  ~UdpSource() override;
  UdpSource(const UdpSource&) = delete;
  UdpSource& operator=(const UdpSource&) = delete;

  /// The next accepted datagram; nullopt when none arrived within the timeout, or after stop().
  /// The payload stays valid until the next call.
  std::optional<UdpPacket> next() override;
  [[nodiscard]] const SourceStats& stats() const override { return stats_; }

  /// Wakes a next() blocked in another thread and makes every later next() return nullopt.
  /// Thread-safe and async-signal-safe.
  void stop();
  [[nodiscard]] bool stopped() const { return stopped_.load(std::memory_order_acquire); }

  /// The bound local port (the kernel's pick when the config asked for 0).
  [[nodiscard]] std::uint16_t port() const { return port_; }
  /// Receive buffer the kernel granted, as getsockopt(SO_RCVBUF) reports it (Linux doubles the request
  /// for bookkeeping and caps it at net.core.rmem_max unless SO_RCVBUFFORCE was allowed).
  [[nodiscard]] int receiveBufferBytes() const { return granted_rcvbuf_; }
  /// Datagrams longer than max_datagram (cut and dropped; also counted in stats().malformed).
  [[nodiscard]] std::uint64_t truncated() const { return truncated_; }
  /// Re-reads the socket's cumulative drop count (SO_MEMINFO) into stats().kernel_drops; next() does
  /// this on every timeout, and the SO_RXQ_OVFL control message updates it with each datagram.
  void refreshKernelDrops();

 private:
  bool receiveBatch();        // one recvmmsg; false when nothing was waiting
  bool waitReadable(int timeout_ms);  // poll on socket + wake fd; false on timeout or stop
  void noteDropCounter(std::uint32_t cumulative);

  UdpSourceConfig config_;
  int fd_ = -1;
  int wake_fd_ = -1;  // eventfd written by stop()
  std::uint16_t port_ = 0;
  std::uint32_t local_address_ = 0;
  int granted_rcvbuf_ = 0;
  std::atomic<bool> stopped_{false};

  // Batch buffers, allocated once.
  std::vector<std::uint8_t> data_;      // batch × max_datagram
  std::vector<std::uint8_t> control_;   // batch × control bytes per message
  std::vector<mmsghdr> messages_;
  std::vector<iovec> iovecs_;
  std::vector<sockaddr_in> addresses_;
  std::size_t control_stride_ = 0;
  std::size_t received_ = 0;  // datagrams in the current batch
  std::size_t cursor_ = 0;    // next one to look at

  SourceStats stats_;
  std::uint64_t truncated_ = 0;
  std::optional<std::uint32_t> last_drop_counter_;
};

}  // namespace rigcal::drivers
