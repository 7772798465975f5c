// Receive-path throughput on loopback: UdpSource (recvmmsg batches + kernel timestamps) against a plain
// recvfrom loop, for Velodyne-sized (1206 B) and Ouster-sized (8 KiB) datagrams; and PcapSource read
// throughput on real captures.
//
// Each iteration first queues kBurst datagrams in the receiving socket (untimed), then times draining
// them: this measures the receive side alone, without the sender competing for the 2 cores. Rates are
// per CPU second of the receiving thread (the copy happens in its syscalls). Run pinned:
//   taskset -c 0,1 build/bench/udp_source_bench --benchmark_repetitions=10 --benchmark_report_aggregates_only=true
#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <benchmark/benchmark.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <stdexcept>
#include <vector>

#include "bench_support.hpp"
#include "rigcal/drivers/pcap_source.hpp"
#include "rigcal/drivers/udp_source.hpp"

namespace {

using namespace rigcal::drivers;

constexpr int kBurst = 512;  // datagrams queued per iteration (8 KiB × 512 fits the 32 MiB queue)

// Sends bursts to 127.0.0.1:port with sendmmsg.
class BurstSender {
 public:
  BurstSender(std::uint16_t port, std::size_t size) : payload_(size, 0x5a) {
    fd_ = ::socket(AF_INET, SOCK_DGRAM | SOCK_CLOEXEC, 0);
    sockaddr_in to{};
    to.sin_family = AF_INET;
    to.sin_port = htons(port);
    to.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    if (fd_ < 0 || ::connect(fd_, reinterpret_cast<sockaddr*>(&to), sizeof to) != 0)
      throw std::runtime_error("cannot connect the sender");
    const int bytes = 8 << 20;
    setsockopt(fd_, SOL_SOCKET, SO_SNDBUFFORCE, &bytes, sizeof bytes);
    iov_ = {payload_.data(), payload_.size()};
    messages_.resize(64);
    for (auto& m : messages_) {
      m = {};
      m.msg_hdr.msg_iov = &iov_;
      m.msg_hdr.msg_iovlen = 1;
    }
  }
  ~BurstSender() { ::close(fd_); }
  void send(int count) {
    while (count > 0) {
      const int n = ::sendmmsg(fd_, messages_.data(), unsigned(std::min<int>(count, int(messages_.size()))), 0);
      if (n <= 0) throw std::runtime_error("sendmmsg failed");
      count -= n;
    }
  }

 private:
  int fd_ = -1;
  std::vector<std::uint8_t> payload_;
  iovec iov_{};
  std::vector<mmsghdr> messages_;
};

void setRate(benchmark::State& state, std::size_t size) {
  state.SetItemsProcessed(std::int64_t(state.iterations()) * kBurst);
  state.SetBytesProcessed(std::int64_t(state.iterations()) * kBurst * std::int64_t(size));
}

void BM_UdpSource_recvmmsg(benchmark::State& state) {
  const auto size = std::size_t(state.range(0));
  UdpSourceConfig config;
  config.bind_address = "127.0.0.1";
  config.batch = std::size_t(state.range(1));
  config.max_datagram = 9000;
  config.receive_buffer_bytes = 32 << 20;
  config.timeout = std::chrono::milliseconds(1000);
  UdpSource source(config);
  BurstSender sender(source.port(), size);
  for (auto _ : state) {
    state.PauseTiming();
    sender.send(kBurst);
    state.ResumeTiming();
    for (int i = 0; i < kBurst; ++i) {
      auto p = source.next();
      if (!p) {
        state.SkipWithError("datagram lost");
        return;
      }
      benchmark::DoNotOptimize(p->payload.data());
    }
  }
  if (source.stats().kernel_drops != 0) state.SkipWithError("kernel dropped datagrams");
  setRate(state, size);
}

// Baseline: one recvfrom(2) per datagram, no timestamps.
void BM_recvfrom_single(benchmark::State& state) {
  const auto size = std::size_t(state.range(0));
  const int fd = ::socket(AF_INET, SOCK_DGRAM | SOCK_CLOEXEC, 0);
  const int bytes = 32 << 20;
  setsockopt(fd, SOL_SOCKET, SO_RCVBUFFORCE, &bytes, sizeof bytes);
  sockaddr_in local{};
  local.sin_family = AF_INET;
  local.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  ::bind(fd, reinterpret_cast<sockaddr*>(&local), sizeof local);
  socklen_t len = sizeof local;
  getsockname(fd, reinterpret_cast<sockaddr*>(&local), &len);
  BurstSender sender(ntohs(local.sin_port), size);
  std::vector<std::uint8_t> buffer(9000);
  for (auto _ : state) {
    state.PauseTiming();
    sender.send(kBurst);
    state.ResumeTiming();
    for (int i = 0; i < kBurst; ++i) {
      sockaddr_in from{};
      socklen_t from_len = sizeof from;
      const ssize_t n = ::recvfrom(fd, buffer.data(), buffer.size(), MSG_DONTWAIT,
                                   reinterpret_cast<sockaddr*>(&from), &from_len);
      if (n <= 0) {
        state.SkipWithError("datagram lost");
        ::close(fd);
        return;
      }
      benchmark::DoNotOptimize(buffer.data());
    }
  }
  ::close(fd);
  setRate(state, size);
}

const char* const kCaptures[] = {"velodyne/vls128_strongest.pcap", "ouster/OS-2-128-U1_v2.3.0_1024x10.pcap",
                                 "hesai/xt32_dual.pcap"};

void BM_PcapSource_read(benchmark::State& state) {
  const auto file = rigcal::bench::dataDir() / kCaptures[state.range(0)];
  if (!std::filesystem::exists(file)) {
    state.SkipWithError(("capture not found (set RIGCAL_DATA_DIR): " + file.string()).c_str());
    return;
  }
  state.SetLabel(file.filename().string());
  std::int64_t packets = 0, bytes = 0;
  for (auto _ : state) {
    PcapSource source(file);
    while (auto p = source.next()) {
      ++packets;
      bytes += std::int64_t(p->payload.size());
      benchmark::DoNotOptimize(p->payload.data());
    }
  }
  state.SetItemsProcessed(packets);
  state.SetBytesProcessed(bytes);
}

BENCHMARK(BM_UdpSource_recvmmsg)
    ->ArgNames({"bytes", "batch"})
    ->Args({1206, 64})
    ->Args({8192, 64})
    ->Args({1206, 1})
    ->Args({8192, 1})
    ->ComputeStatistics("p99", rigcal::bench::p99);
BENCHMARK(BM_recvfrom_single)->ArgName("bytes")->Arg(1206)->Arg(8192)->ComputeStatistics("p99", rigcal::bench::p99);
BENCHMARK(BM_PcapSource_read)->ArgName("capture")->DenseRange(0, 2)->ComputeStatistics("p99", rigcal::bench::p99)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
