// UdpSource on loopback: batching, kernel timestamps, filtering, truncation, drops, timeouts, stop(),
// and its one-line errors. Every datagram here goes to 127.0.0.0/8 only.
#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <ctime>
#include <iostream>
#include <optional>
#include <thread>
#include <vector>

#include "rigcal/drivers/udp_source.hpp"

namespace rigcal::drivers {
namespace {

using Clock = std::chrono::steady_clock;
using std::chrono::milliseconds;

constexpr std::uint32_t kLoopback = 0x7f000001;

// A UDP socket bound to a loopback address (127.x.y.z) that sends to 127.0.0.1:port.
class Sender {
 public:
  explicit Sender(std::uint32_t local = kLoopback) {
    fd_ = ::socket(AF_INET, SOCK_DGRAM | SOCK_CLOEXEC, 0);
    EXPECT_GE(fd_, 0);
    sockaddr_in a{};
    a.sin_family = AF_INET;
    a.sin_addr.s_addr = htonl(local);
    EXPECT_EQ(::bind(fd_, reinterpret_cast<sockaddr*>(&a), sizeof a), 0);
    socklen_t len = sizeof a;
    getsockname(fd_, reinterpret_cast<sockaddr*>(&a), &len);
    port_ = ntohs(a.sin_port);
  }
  ~Sender() { ::close(fd_); }
  Sender(const Sender&) = delete;
  Sender& operator=(const Sender&) = delete;

  void send(std::uint16_t port, const std::vector<std::uint8_t>& payload, std::uint32_t to = kLoopback) const {
    sockaddr_in a{};
    a.sin_family = AF_INET;
    a.sin_port = htons(port);
    a.sin_addr.s_addr = htonl(to);
    ASSERT_EQ(::sendto(fd_, payload.data(), payload.size(), 0, reinterpret_cast<sockaddr*>(&a), sizeof a),
              ssize_t(payload.size()));
  }
  [[nodiscard]] int fd() const { return fd_; }
  [[nodiscard]] std::uint16_t port() const { return port_; }

 private:
  int fd_ = -1;
  std::uint16_t port_ = 0;
};

std::vector<std::uint8_t> payload(std::size_t size, int tag) {
  std::vector<std::uint8_t> p(size);
  for (std::size_t i = 0; i < size; ++i) p[i] = std::uint8_t(tag * 31 + int(i));
  return p;
}

TimeNs realtimeNow() {
  timespec ts{};
  clock_gettime(CLOCK_REALTIME, &ts);
  return TimeNs(ts.tv_sec) * kNsPerSec + ts.tv_nsec;
}

UdpSourceConfig loopbackConfig() {
  UdpSourceConfig c;
  c.bind_address = "127.0.0.1";
  c.port = 0;  // ephemeral: tests never clash with each other or with real sensors
  c.timeout = milliseconds(200);
  return c;
}

TEST(UdpSource, ReceivesEveryDatagramInOrderAcrossBatchesWithKernelTimestamps) {
  UdpSourceConfig config = loopbackConfig();
  config.batch = 16;
  UdpSource source(config);
  ASSERT_NE(source.port(), 0);
  Sender sender;
  // Linux turns arrival stamping on for the first socket that asks through deferred work: until it has run,
  // a datagram is stamped when it is read (which had made this test fail now and then in a fresh process).
  // Probe until a datagram read 20 ms after its sending carries the earlier, arrival time.
  bool stamping = false;
  int probes = 0;
  while (!stamping && probes < 100) {
    ++probes;
    sender.send(source.port(), payload(8, 255));
    std::this_thread::sleep_for(milliseconds(20));
    const TimeNs read_at = realtimeNow();
    const auto p = source.next();
    ASSERT_TRUE(p) << "probe " << probes;
    stamping = p->receive_ns < read_at;
  }
  ASSERT_TRUE(stamping) << "the kernel never stamped a datagram on arrival";
  std::cout << "arrival stamps from probe " << probes << "\n";
  const TimeNs before = realtimeNow();
  constexpr int kCount = 100;  // spans several recvmmsg batches of 16
  for (int k = 0; k < kCount; ++k) sender.send(source.port(), payload(100 + std::size_t(k) * 13, k));
  // Long enough for loopback to deliver all of them (its softirq may run after the last send returned).
  std::this_thread::sleep_for(milliseconds(50));
  const TimeNs reading = realtimeNow();

  for (int k = 0; k < kCount; ++k) {
    auto p = source.next();
    ASSERT_TRUE(p) << "datagram " << k;
    const auto expected = payload(100 + std::size_t(k) * 13, k);
    ASSERT_EQ(std::vector<std::uint8_t>(p->payload.begin(), p->payload.end()), expected) << "datagram " << k;
    EXPECT_EQ(p->source.address, kLoopback);
    EXPECT_EQ(p->source.port, sender.port());
    EXPECT_EQ(p->destination.address, kLoopback);
    EXPECT_EQ(p->destination.port, source.port());
    // The kernel's wall-clock time of arrival: every datagram had arrived before the reading began, so a
    // time taken when the program read it would fail. The order is the payloads' (the stamps need not be
    // monotonic: the clean clone's ASan run saw them go 0.6 ms back while stamping was being turned on).
    EXPECT_GE(p->receive_ns, before) << "datagram " << k;
    EXPECT_LE(p->receive_ns, reading) << "datagram " << k << ": not the kernel's time of arrival";
  }
  EXPECT_EQ(source.stats().packets, std::uint64_t(kCount + probes));
  EXPECT_EQ(source.stats().kernel_drops, 0u);
}

TEST(UdpSource, ReportsTheReceiveBufferTheKernelGranted) {
  UdpSource source(loopbackConfig());
  // Linux reports twice the usable size; without privileges the request is capped by rmem_max.
  EXPECT_GT(source.receiveBufferBytes(), 0);
  std::cout << "SO_RCVBUF granted: " << source.receiveBufferBytes() << " bytes\n";
}

TEST(UdpSource, TimesOutWithNothing) {
  UdpSourceConfig config = loopbackConfig();
  config.timeout = milliseconds(80);
  UdpSource source(config);
  const auto t0 = Clock::now();
  EXPECT_FALSE(source.next().has_value());
  const auto waited = Clock::now() - t0;
  EXPECT_GE(waited, milliseconds(75));
  EXPECT_LT(waited, milliseconds(1000));
}

TEST(UdpSource, StopWakesANextBlockedInAnotherThread) {
  UdpSourceConfig config = loopbackConfig();
  config.timeout = milliseconds(20'000);
  UdpSource source(config);
  std::atomic<bool> returned{false};
  bool got_packet = true;
  Clock::duration blocked{};
  std::thread reader([&] {
    const auto t0 = Clock::now();
    got_packet = source.next().has_value();
    blocked = Clock::now() - t0;
    returned = true;
  });
  std::this_thread::sleep_for(milliseconds(150));
  EXPECT_FALSE(returned.load()) << "next() must block while nothing arrives";
  source.stop();
  reader.join();
  EXPECT_FALSE(got_packet);
  EXPECT_GE(blocked, milliseconds(140));
  EXPECT_LT(blocked, milliseconds(5000)) << "stop() must wake next() long before its timeout";
  EXPECT_TRUE(source.stopped());
  // Stopped for good: even a waiting datagram is not returned.
  Sender sender;
  sender.send(source.port(), payload(10, 1));
  EXPECT_FALSE(source.next().has_value());
}

TEST(UdpSource, ASecondSourceOnTheSamePortFailsWithAClearMessage) {
  UdpSource first(loopbackConfig());
  UdpSourceConfig config = loopbackConfig();
  config.port = first.port();
  try {
    UdpSource second(config);
    FAIL() << "binding an occupied port must fail";
  } catch (const std::runtime_error& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("127.0.0.1:" + std::to_string(first.port())), std::string::npos) << what;
    EXPECT_NE(what.find("already in use"), std::string::npos) << what;
    EXPECT_EQ(what.find('\n'), std::string::npos) << what;
  }
}

TEST(UdpSource, TwoSourcesShareAPortWhenBothAskForReuse) {
  UdpSourceConfig config = loopbackConfig();
  config.reuse = true;
  UdpSource first(config);
  config.port = first.port();
  EXPECT_NO_THROW(UdpSource second(config));
}

TEST(UdpSource, BadAddressesAreRefusedWithOneLine) {
  UdpSourceConfig config = loopbackConfig();
  config.multicast_group = "10.1.2.3";
  try {
    UdpSource s(config);
    FAIL();
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("'10.1.2.3' is not a multicast address"), std::string::npos) << e.what();
  }
  config.multicast_group = "239.1.2.x";
  try {
    UdpSource s(config);
    FAIL();
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("'239.1.2.x' is not an IPv4 address"), std::string::npos) << e.what();
  }
  config.multicast_group.clear();
  config.bind_address = "192.0.2.77";  // TEST-NET-1: not an address of this machine
  try {
    UdpSource s(config);
    FAIL();
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("not an address of this machine"), std::string::npos) << e.what();
  }
}

TEST(UdpSource, JoinsAMulticastGroupOnLoopback) {
  UdpSourceConfig config;
  config.multicast_group = "239.255.42.99";
  config.multicast_interface = "127.0.0.1";
  config.timeout = milliseconds(500);
  std::optional<UdpSource> source;
  try {
    source.emplace(config);
  } catch (const std::runtime_error& e) {
    GTEST_SKIP() << "cannot join a multicast group on loopback here: " << e.what();
  }
  // Send with TTL 0 through the loopback interface: the datagram is looped back locally and can
  // never leave the machine.
  Sender sender;
  in_addr lo{};
  lo.s_addr = htonl(kLoopback);
  const int ttl = 0, loop = 1;
  if (setsockopt(sender.fd(), IPPROTO_IP, IP_MULTICAST_IF, &lo, sizeof lo) != 0 ||
      setsockopt(sender.fd(), IPPROTO_IP, IP_MULTICAST_TTL, &ttl, sizeof ttl) != 0 ||
      setsockopt(sender.fd(), IPPROTO_IP, IP_MULTICAST_LOOP, &loop, sizeof loop) != 0)
    GTEST_SKIP() << "cannot restrict multicast sending to loopback";
  sender.send(source->port(), payload(64, 5), 0xEFFF2A63);  // 239.255.42.99
  auto p = source->next();
  if (!p) GTEST_SKIP() << "this kernel does not loop multicast back on lo";
  EXPECT_EQ(p->payload.size(), 64u);
  EXPECT_EQ(p->destination.address, 0xEFFF2A63u);
}

TEST(UdpSource, FiltersBySourceAddress) {
  UdpSourceConfig config = loopbackConfig();
  config.filter.source_address = 0x7f000003;  // 127.0.0.3
  UdpSource source(config);
  Sender a(0x7f000002), b(0x7f000003);
  for (int k = 0; k < 10; ++k) {
    a.send(source.port(), payload(20, k));
    b.send(source.port(), payload(30, k));
  }
  int received = 0;
  while (auto p = source.next()) {
    EXPECT_EQ(p->source.address, 0x7f000003u);
    EXPECT_EQ(p->payload.size(), 30u);
    ++received;
  }
  EXPECT_EQ(received, 10);
  EXPECT_EQ(source.stats().filtered, 10u);
  EXPECT_EQ(source.stats().packets, 10u);
}

TEST(UdpSource, ADatagramLongerThanTheBufferIsCountedNotDelivered) {
  UdpSourceConfig config = loopbackConfig();
  config.max_datagram = 100;
  UdpSource source(config);
  Sender sender;
  sender.send(source.port(), payload(200, 1));
  sender.send(source.port(), payload(100, 2));
  auto p = source.next();
  ASSERT_TRUE(p);
  EXPECT_EQ(p->payload.size(), 100u);
  EXPECT_EQ(p->payload[0], payload(100, 2)[0]);
  EXPECT_EQ(source.truncated(), 1u);
  EXPECT_EQ(source.stats().malformed, 1u);
}

TEST(UdpSource, CountsDatagramsTheKernelDroppedOnAFullQueue) {
  UdpSourceConfig config = loopbackConfig();
  config.receive_buffer_bytes = 16 * 1024;  // tiny on purpose: the queue overflows
  config.timeout = milliseconds(100);
  UdpSource source(config);
  Sender sender;
  constexpr int kSent = 300;
  for (int k = 0; k < kSent; ++k) sender.send(source.port(), payload(1200, k));
  std::uint64_t received = 0;
  while (source.next()) ++received;
  EXPECT_GT(received, 0u);
  EXPECT_GT(source.stats().kernel_drops, 0u);
  EXPECT_EQ(received + source.stats().kernel_drops, std::uint64_t(kSent))
      << "received " << received << ", kernel drops " << source.stats().kernel_drops;
}

}  // namespace
}  // namespace rigcal::drivers
