// ring_peer: the other process in the ring tests. One writer or one reader per process, talking to the test
// only through the ring and one-line "key=value" reports on stdout.
//
//   ring_peer writer --prefix P --sensor S --points N [--slots K] [--count C] [--rate HZ] [--first-seq F]
//                    [--start-delay-ms D] [--stall-after M] [--hold] [--wait-readers R]
//   ring_peer reader --prefix P --sensor S --points N [--count C] [--timeout-ms T] [--delay-ms D]
//                    [--oldest] [--until-closed]
//
// Scans follow scan_pattern.hpp, so the reader checks every value of every scan it gets. --wait-readers R
// is test-only flow control (the ring itself never waits for readers): the writer waits for R readers to
// attach, and after each publish until they have read it, so a loaded machine cannot turn an exchange test
// into an overrun test. A reader stops once it has accounted for --count ring indices (read or lost).
#include <signal.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <map>
#include <set>
#include <string>
#include <thread>

#include "rigcal/shm/liveness.hpp"
#include "rigcal/shm/ring_error.hpp"
#include "rigcal/shm/scan_ring_reader.hpp"
#include "rigcal/shm/scan_ring_writer.hpp"
#include "scan_pattern.hpp"

namespace {

using namespace rigcal;
using namespace rigcal::shm;

struct Args {
  std::map<std::string, std::string> values;
  [[nodiscard]] bool has(const std::string& k) const { return values.count(k) != 0; }
  [[nodiscard]] std::string str(const std::string& k, const std::string& dflt = "") const {
    const auto it = values.find(k);
    return it == values.end() ? dflt : it->second;
  }
  [[nodiscard]] long long num(const std::string& k, long long dflt) const {
    const auto it = values.find(k);
    return it == values.end() ? dflt : std::strtoll(it->second.c_str(), nullptr, 10);
  }
};

Args parse(int argc, char** argv) {
  Args a;
  for (int i = 2; i < argc; ++i) {
    std::string key = argv[i];
    if (key.rfind("--", 0) != 0) continue;
    key = key.substr(2);
    const bool has_value = i + 1 < argc && std::string(argv[i + 1]).rfind("--", 0) != 0;
    a.values.insert_or_assign(key, has_value ? std::string(argv[++i]) : std::string(1, '1'));
  }
  return a;
}

void say(const std::string& line) {
  std::printf("%s\n", line.c_str());
  std::fflush(stdout);
}

void sleepUntil(std::int64_t mono_ns) {
  timespec ts{static_cast<time_t>(mono_ns / 1'000'000'000), static_cast<long>(mono_ns % 1'000'000'000)};
  while (::clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, nullptr) == EINTR) {
  }
}

/// Live reader records: how many, and how many of them have not read up to `index` yet.
std::pair<int, int> readers(const ScanRingWriter& w, std::uint64_t index) {
  int live = 0, behind = 0;
  for (const ReaderRecord& r : w.view().header().readers) {
    if (r.pid.load() <= 0) continue;
    ++live;
    if (r.next_index.load() < index) ++behind;
  }
  return {live, behind};
}

/// Polls every millisecond, at most 5 s, until `count` readers are attached and none is behind `index`
/// (a reader that has finished and left is not behind).
void waitForReaders(const ScanRingWriter& w, int count, std::uint64_t index, bool first) {
  for (int i = 0; i < 5000; ++i) {
    const auto [live, behind] = readers(w, index);
    if ((!first || live >= count) && behind == 0) return;
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
}

int runWriter(const Args& a) {
  WriterOptions options;
  options.sensor = a.str("sensor", "lidar");
  options.name_prefix = a.str("prefix");
  options.max_points = static_cast<std::uint32_t>(a.num("points", 1000));
  options.slot_count = static_cast<std::uint32_t>(a.num("slots", 8));
  ScanRingWriter writer(options);
  say("ready pid=" + std::to_string(::getpid()) + " epoch=" + std::to_string(writer.epoch()) +
      " took_over=" + (writer.tookOver() ? "1" : "0"));
  if (const long long d = a.num("start-delay-ms", 0); d > 0) std::this_thread::sleep_for(std::chrono::milliseconds(d));

  const long long count = a.num("count", 10);
  const long long first = a.num("first-seq", 0);
  const long long stall_after = a.num("stall-after", -1);
  const double rate = static_cast<double>(a.num("rate", 0));
  const int wait_readers = static_cast<int>(a.num("wait-readers", 0));
  if (wait_readers > 0) waitForReaders(writer, wait_readers, writer.view().header().write_index.load(), true);
  Scan scan;
  const std::int64_t t0 = monotonicNs();
  for (long long k = 0; k < count; ++k) {
    const auto seq = static_cast<std::uint64_t>(first + k);
    test::fillPattern(scan, seq, test::patternPoints(seq, options.max_points));
    if (k == stall_after) {
      // Die mid-write: the slot counter is odd and half the slot is overwritten when the test kills us.
      const std::uint64_t index = beginPublish(writer.view());
      writePayload(writer.view(), index, scan, writer.epoch());
      say("midwrite index=" + std::to_string(index));
      for (;;) ::pause();
    }
    if (rate > 0) sleepUntil(t0 + static_cast<std::int64_t>(static_cast<double>(k) * 1e9 / rate));
    writer.publish(scan);
    if (wait_readers > 0) waitForReaders(writer, wait_readers, writer.view().header().write_index.load(), false);
  }
  const double elapsed_ms = static_cast<double>(monotonicNs() - t0) * 1e-6;
  say("published n=" + std::to_string(writer.stats().published) +
      " elapsed_ms=" + std::to_string(static_cast<long long>(elapsed_ms)) +
      " oversize=" + std::to_string(writer.stats().oversize_drops));
  if (a.has("hold")) {
    say("holding");
    for (;;) {
      writer.heartbeat();
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
  }
  writer.close();
  say("closed");
  return 0;
}

int runReader(const Args& a) {
  ReaderOptions options;
  options.sensor = a.str("sensor", "lidar");
  options.name_prefix = a.str("prefix");
  options.start_at = a.has("oldest") ? ReaderOptions::StartAt::kOldest : ReaderOptions::StartAt::kNext;
  const auto max_points = static_cast<std::uint32_t>(a.num("points", 1000));
  const long long count = a.num("count", 0);
  const long long delay_ms = a.num("delay-ms", 0);
  const bool until_closed = a.has("until-closed");
  const std::int64_t deadline = monotonicNs() + a.num("timeout-ms", 8000) * 1'000'000;

  ScanRingReader reader(options);
  say("started attached=" + std::string(reader.attached() ? "1" : "0"));
  Scan scan;
  ScanMeta meta;
  long long good = 0, bad = 0;
  long long first_seq = -1, last_seq = -1;
  bool dead_seen = false;
  std::set<std::uint64_t> epochs;
  std::string last_report;
  std::int64_t next_status_check = 0;
  const ReaderStats& s = reader.stats();
  const auto accounted = [&] { return good + bad + static_cast<long long>(s.overruns + s.checksum_errors); };
  while (monotonicNs() < deadline && (count <= 0 || accounted() < count)) {
    const ReadStatus got = reader.read(scan, std::chrono::milliseconds(50), &meta);
    if (got == ReadStatus::kScan) {
      const std::string why = test::checkPattern(scan, max_points);
      if (why.empty()) {
        ++good;
      } else if (++bad <= 5) {
        say("bad " + why);
      }
      if (first_seq < 0) first_seq = static_cast<long long>(scan.sequence);
      last_seq = static_cast<long long>(scan.sequence);
      epochs.insert(meta.epoch);
      if (delay_ms > 0) std::this_thread::sleep_for(std::chrono::milliseconds(delay_ms));
    }
    const std::int64_t now = monotonicNs();
    if (got != ReadStatus::kScan || now >= next_status_check) {
      next_status_check = now + 20'000'000;
      const WriterStatus status = reader.writerStatus();
      dead_seen = dead_seen || status == WriterStatus::kDead;
      const std::string report =
          std::string("status=") + toString(status) + " epoch=" + std::to_string(reader.epoch());
      if (report != last_report) say(report);
      last_report = report;
      if (until_closed && got != ReadStatus::kScan && status == WriterStatus::kClosed) break;
    }
  }
  std::string epoch_list;
  for (std::uint64_t e : epochs) {
    if (!epoch_list.empty()) epoch_list += ',';
    epoch_list += std::to_string(e);
  }
  say("summary scans=" + std::to_string(good + bad) + " good=" + std::to_string(good) +
      " bad=" + std::to_string(bad) + " overruns=" + std::to_string(s.overruns) +
      " torn=" + std::to_string(s.torn_reads) + " checksum_errors=" + std::to_string(s.checksum_errors) +
      " restarts=" + std::to_string(s.writer_restarts) + " reattaches=" + std::to_string(s.reattaches) +
      " dead_seen=" + (dead_seen ? "1" : "0") + " first_seq=" + std::to_string(first_seq) +
      " last_seq=" + std::to_string(last_seq) + " epochs=" + (epoch_list.empty() ? "-" : epoch_list));
  return bad == 0 ? 0 : 1;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: ring_peer writer|reader --prefix P --sensor S ...\n");
    return 2;
  }
  const std::string mode = argv[1];
  const Args args = parse(argc, argv);
  try {
    if (mode == "writer") return runWriter(args);
    if (mode == "reader") return runReader(args);
  } catch (const RingError& e) {
    std::fprintf(stderr, "ring_peer: %s\n", e.what());
    return 3;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "ring_peer: %s\n", e.what());
    return 4;
  }
  std::fprintf(stderr, "ring_peer: unknown mode '%s'\n", mode.c_str());
  return 2;
}
