// shm_ring_bench: ScanRing across processes. A plain main() rather than Google Benchmark: what is measured
// spans two processes (a writer and a reader, each pinned to a core), which its per-thread loop does not model.
//
//  1. Latency with blocking wake-up: the reader sleeps on the ring's futex; the writer publishes one scan
//     every --period-us. Reported per scan size, writer core 0 -> reader core 1, and both on core 0:
//       hop = reader has its copy - scan complete in its slot (futex wake-up + reader copy-out)
//       e2e = reader has its copy - publish() called       (writer copy-in + hop)
//  2. Throughput of full VLS-128-sized scans (240 000 points, 5.5 MB): the writer publishes as fast as the
//     reader keeps up (it only pauses when it would overwrite an unread slot), against memcpy of the same
//     bytes into ring-sized rotating buffers in the same run.
//
// Usage: shm_ring_bench [--latency-scans N] [--period-us P] [--throughput-scans N] [--fifo PRIO]
//   --fifo PRIO runs writer, reader and the memcpy baseline under SCHED_FIFO (needs CAP_SYS_NICE): on a
//   machine busy with other work it measures the ring rather than the queue for the CPU.
// The latency table is printed twice: with the default idle states and with the CPU wake-up latency limit
// held at 0 (/dev/cpu_dma_latency, see rigcal/core/cpu_latency_request.hpp), when this process may hold it.
#include <sched.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <map>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "rigcal/core/cpu_latency_request.hpp"
#include "rigcal/drivers/pacing.hpp"
#include "rigcal/shm/liveness.hpp"
#include "rigcal/shm/ring_segment.hpp"
#include "rigcal/shm/scan_ring_reader.hpp"
#include "rigcal/shm/scan_ring_writer.hpp"

namespace {

using namespace rigcal;
using namespace rigcal::shm;

using Args = std::map<std::string, std::string>;

long long num(const Args& a, const std::string& k, long long dflt) {
  const auto it = a.find(k);
  return it == a.end() ? dflt : std::strtoll(it->second.c_str(), nullptr, 10);
}

void pin(int cpu, int fifo_priority) {
  cpu_set_t set;
  CPU_ZERO(&set);
  CPU_SET(cpu, &set);
  if (::sched_setaffinity(0, sizeof set, &set) != 0) std::perror("sched_setaffinity");
  if (fifo_priority > 0) {
    sched_param p{};
    p.sched_priority = fifo_priority;
    if (::sched_setscheduler(0, SCHED_FIFO, &p) != 0) std::perror("sched_setscheduler(SCHED_FIFO)");
  }
}

void fill(Scan& s, std::uint32_t points) {
  s.resize(points);
  for (std::uint32_t i = 0; i < points; ++i) {
    s.x[i] = static_cast<float>(i) * 0.01f;
    s.y[i] = -static_cast<float>(i) * 0.02f;
    s.z[i] = static_cast<float>(i % 128) * 0.1f;
    s.intensity[i] = static_cast<float>(i % 256);
    s.ring[i] = static_cast<std::uint16_t>(i % 128);
    s.offset_ns[i] = i * 400;
    s.return_index[i] = static_cast<std::uint8_t>(i & 1);
  }
}

std::string stats(std::vector<std::int64_t> v) {
  if (v.empty()) return "n=0";
  std::sort(v.begin(), v.end());
  const auto at = [&](double q) { return static_cast<double>(v[std::min(v.size() - 1, static_cast<std::size_t>(q * static_cast<double>(v.size())))]) * 1e-3; };
  char buf[128];
  std::snprintf(buf, sizeof buf, "p50=%.1f p99=%.1f max=%.1f", at(0.5), at(0.99), static_cast<double>(v.back()) * 1e-3);
  return buf;
}

/// The first live reader record's next index, or -1 while no reader has attached.
long long readerNext(const ScanRingWriter& w) {
  for (const ReaderRecord& r : w.view().header().readers) {
    if (r.pid.load() > 0) return static_cast<long long>(r.next_index.load());
  }
  return -1;
}

int runWriter(const Args& a) {
  pin(static_cast<int>(num(a, "cpu", 0)), static_cast<int>(num(a, "fifo", 0)));
  const auto points = static_cast<std::uint32_t>(num(a, "points", 1000));
  const long long scans = num(a, "scans", 1000);
  const long long period_ns = num(a, "period-us", 0) * 1000;
  const bool lockstep = num(a, "lockstep", 0) != 0;
  WriterOptions o;
  o.sensor = "bench";
  o.name_prefix = a.at("prefix");
  o.max_points = points;
  o.slot_count = 8;
  ScanRingWriter writer(o);
  Scan scan;
  fill(scan, points);
  for (int i = 0; i < 5000 && readerNext(writer) < 0; ++i) std::this_thread::sleep_for(std::chrono::milliseconds(1));
  const RingHeader& h = writer.view().header();
  std::int64_t in_publish = 0;
  const std::atomic<bool> never_stop{false};
  const std::int64_t t0 = monotonicNs();  // the same CLOCK_MONOTONIC as drivers::sleepUntil
  for (long long k = 0; k < scans; ++k) {
    if (period_ns > 0) drivers::sleepUntil(t0 + k * period_ns, never_stop);
    // Throughput run: never overwrite a scan the reader has not read, so every byte counted is delivered.
    for (long long r; lockstep && (r = readerNext(writer)) >= 0 &&
                      static_cast<long long>(h.write_index.load()) - r >= o.slot_count - 1;) {
      std::this_thread::sleep_for(std::chrono::microseconds(20));
    }
    scan.sequence = static_cast<std::uint64_t>(k);
    scan.stamp_ns = monotonicNs();  // the bench's own stamp: when publish() was called
    writer.publish(scan);
    in_publish += monotonicNs() - scan.stamp_ns;
  }
  std::printf("writer t0=%lld in_publish_ns=%lld\n", static_cast<long long>(t0), static_cast<long long>(in_publish));
  std::fflush(stdout);
  for (int i = 0; i < 5000 && readerNext(writer) >= 0 && readerNext(writer) < scans; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  return 0;
}

int runReader(const Args& a) {
  pin(static_cast<int>(num(a, "cpu", 1)), static_cast<int>(num(a, "fifo", 0)));
  const long long scans = num(a, "scans", 1000);
  ReaderOptions o;
  o.sensor = "bench";
  o.name_prefix = a.at("prefix");
  o.start_at = ReaderOptions::StartAt::kOldest;
  o.liveness_period = std::chrono::milliseconds(10);
  ScanRingReader reader(o);
  Scan scan;
  ScanMeta meta;
  std::vector<std::int64_t> hop, e2e;
  hop.reserve(static_cast<std::size_t>(scans));
  e2e.reserve(static_cast<std::size_t>(scans));
  std::int64_t last = 0;
  long long got = 0;
  const std::int64_t deadline = monotonicNs() + 60'000'000'000;
  const ReaderStats& s = reader.stats();
  while (got + static_cast<long long>(s.overruns) < scans && monotonicNs() < deadline) {
    if (reader.read(scan, std::chrono::milliseconds(200), &meta) != ReadStatus::kScan) {
      if (reader.writerStatus() == WriterStatus::kClosed) break;
      continue;
    }
    last = monotonicNs();
    if (++got > 10) {  // the first few pay for page faults and cold caches
      hop.push_back(last - meta.publish_ns);
      e2e.push_back(last - scan.stamp_ns);
    }
  }
  std::printf("reader got=%lld overruns=%llu torn=%llu last=%lld hop: %s e2e: %s\n", got,
              static_cast<unsigned long long>(reader.stats().overruns),
              static_cast<unsigned long long>(reader.stats().torn_reads), static_cast<long long>(last),
              stats(hop).c_str(), stats(e2e).c_str());
  return 0;
}

/// Runs a writer and a reader process with `args`; returns their report lines.
std::pair<std::string, std::string> runPair(const std::string& self, const std::string& args, int writer_cpu,
                                            int reader_cpu, int fifo) {
  const std::string common =
      " --prefix rigcal-bench-" + std::to_string(::getpid()) + ". --fifo " + std::to_string(fifo) + " " + args;
  FILE* r = ::popen((self + " --role reader --cpu " + std::to_string(reader_cpu) + common).c_str(), "r");
  std::this_thread::sleep_for(std::chrono::milliseconds(100));
  FILE* w = ::popen((self + " --role writer --cpu " + std::to_string(writer_cpu) + common).c_str(), "r");
  char line[512] = {0};
  std::string wline, rline;
  while (std::fgets(line, sizeof line, w)) wline += line;
  while (std::fgets(line, sizeof line, r)) rline += line;
  ::pclose(w);
  ::pclose(r);
  return {wline, rline};
}

double memcpyMBps(std::uint32_t points, int reps) {
  Scan s;
  fill(s, points);
  const std::size_t slot = slotGeometry(points).slot_bytes;
  std::vector<std::vector<unsigned char>> slots(8, std::vector<unsigned char>(slot, 1));
  const auto copy = [&](int k) {
    unsigned char* d = slots[static_cast<std::size_t>(k) % slots.size()].data();
    const SlotGeometry g = slotGeometry(points);
    std::memcpy(d + g.x, s.x.data(), 4u * points);
    std::memcpy(d + g.y, s.y.data(), 4u * points);
    std::memcpy(d + g.z, s.z.data(), 4u * points);
    std::memcpy(d + g.intensity, s.intensity.data(), 4u * points);
    std::memcpy(d + g.offset_ns, s.offset_ns.data(), 4u * points);
    std::memcpy(d + g.ring, s.ring.data(), 2u * points);
    std::memcpy(d + g.return_index, s.return_index.data(), points);
  };
  for (int k = 0; k < 8; ++k) copy(k);  // fault the pages in
  const std::int64_t t0 = monotonicNs();
  for (int k = 0; k < reps; ++k) copy(k);
  const double secs = static_cast<double>(monotonicNs() - t0) * 1e-9;
  return static_cast<double>(payloadBytes(points)) * reps / secs / 1e6;
}

int runParent(const std::string& self, const Args& a) {
  const long long lat_scans = num(a, "latency-scans", 2000);
  const long long period_us = num(a, "period-us", 2000);
  const long long tput_scans = num(a, "throughput-scans", 300);
  const int fifo = static_cast<int>(num(a, "fifo", 0));
  char load[64] = "?";
  if (FILE* f = std::fopen("/proc/loadavg", "r")) {
    if (!std::fgets(load, sizeof load, f)) load[0] = '\0';
    std::fclose(f);
  }
  std::printf("shm_ring_bench  cpus=%ld  scheduling %s  loadavg %s", ::sysconf(_SC_NPROCESSORS_ONLN),
              fifo > 0 ? ("SCHED_FIFO " + std::to_string(fifo)).c_str() : "SCHED_OTHER", load);
  // Twice: with the kernel's default idle states, and with the CPU wake-up latency limit held at 0 (what
  // `rigcal driver --low-latency` does): the difference is the idle core's wake-up, not the ring.
  for (const bool low_latency : {false, true}) {
    std::optional<CpuLatencyRequest> request;
    if (low_latency) {
      request.emplace(0);
      if (!request->active()) {
        std::printf("latency with cpu_dma_latency=0: not measured (%s)\n", request->error().c_str());
        continue;
      }
    }
    std::printf("latency, blocking futex wake-up, %s, %lld scans, one every %lld us (microseconds)\n",
                low_latency ? "cpu_dma_latency held at 0" : "default idle states", lat_scans, period_us);
    std::printf("  %-8s %-9s %-7s %s\n", "points", "payload", "cores", "result");
    for (std::uint32_t points : {1'000u, 65'536u, 240'000u}) {
      for (const auto& [wc, rc] : {std::pair{0, 1}, std::pair{0, 0}}) {
        const std::string args = "--mode latency --points " + std::to_string(points) + " --scans " +
                                 std::to_string(lat_scans) + " --period-us " + std::to_string(period_us);
        const auto [wline, rline] = runPair(self, args, wc, rc, fifo);
        char payload[32];
        std::snprintf(payload, sizeof payload, "%.2f MB", static_cast<double>(payloadBytes(points)) / 1e6);
        std::printf("  %-8u %-9s %d -> %d   %s", points, payload, wc, rc, rline.c_str());
      }
    }
  }
  constexpr std::uint32_t kVls128 = 240'000;
  const double bytes = static_cast<double>(payloadBytes(kVls128));
  pin(0, fifo);  // the baseline runs where the writer runs
  const double memcpy_mbps = memcpyMBps(kVls128, 40);
  const auto [wline, rline] = runPair(self,
                                      "--mode throughput --lockstep 1 --points " + std::to_string(kVls128) +
                                          " --scans " + std::to_string(tput_scans),
                                      0, 1, fifo);
  const long long t0 = std::strtoll(wline.substr(wline.find("t0=") + 3).c_str(), nullptr, 10);
  const long long in_publish = std::strtoll(wline.substr(wline.find("in_publish_ns=") + 14).c_str(), nullptr, 10);
  const long long last = std::strtoll(rline.substr(rline.find("last=") + 5).c_str(), nullptr, 10);
  const long long got = std::strtoll(rline.substr(rline.find("got=") + 4).c_str(), nullptr, 10);
  const double delivered = bytes * static_cast<double>(got) / (static_cast<double>(last - t0) * 1e-9) / 1e6;
  const double publish = bytes * static_cast<double>(tput_scans) / (static_cast<double>(in_publish) * 1e-9) / 1e6;
  std::printf("throughput, %u-point scans (%.2f MB payload), writer core 0, reader core 1, %lld scans\n",
              kVls128, bytes / 1e6, tput_scans);
  std::printf("  memcpy, same bytes into 8 slot-sized buffers: %8.0f MB/s\n", memcpy_mbps);
  std::printf("  ring publish (writer copy-in + checksum):     %8.0f MB/s  %3.0f%% of memcpy\n", publish,
              100.0 * publish / memcpy_mbps);
  std::printf("  ring delivered (writer -> reader's copy):     %8.0f MB/s  %3.0f%% of memcpy  (%s)\n", delivered,
              100.0 * delivered / memcpy_mbps, rline.substr(0, rline.find(" hop")).c_str());
  for (const auto& s : listSegments("rigcal-bench-" + std::to_string(::getpid()) + ".")) removeSegment(s);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  Args a;
  for (int i = 1; i < argc; i += 2) {
    if (std::strncmp(argv[i], "--", 2) != 0 || i + 1 >= argc) {
      std::fprintf(stderr, "shm_ring_bench: '%s' needs a value: --option VALUE (see the comment at the top)\n",
                   argv[i]);
      return 2;
    }
    a[argv[i] + 2] = argv[i + 1];
  }
  try {
    const auto role = a.find("role");
    if (role == a.end()) {
      char self[4096];
      const ssize_t n = ::readlink("/proc/self/exe", self, sizeof self - 1);
      if (n <= 0) return 1;
      self[n] = '\0';
      return runParent(self, a);
    }
    return role->second == "writer" ? runWriter(a) : runReader(a);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "shm_ring_bench: %s\n", e.what());
    return 1;
  }
}
