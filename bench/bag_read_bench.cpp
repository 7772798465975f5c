// Bag read throughput (MB/s of file) through rigcal::bag::Bag: an uncompressed MCAP, a zstd MCAP and a
// sqlite3 .db3 of ~64 MB holding nebula's real PandarScan messages (bags/nebula_xt32, repeated with
// increasing times), against reading the same file to nowhere (`cat` > /dev/null) in the same run.
// The files are written once to a temp folder at start-up (page cache warm for all, as for `cat`).
#include <fcntl.h>
#include <sqlite3.h>
#include <unistd.h>

#include <array>
#include <cstdio>
#include <cstdlib>
#include <map>

#include "bench_support.hpp"
#include "mcap_test_writer.hpp"
#include "rigcal/bag/bag.hpp"

namespace {

using namespace rigcal;
namespace fs = std::filesystem;

constexpr std::size_t kTargetBytes = 64u << 20;

struct BenchFiles {
  fs::path dir, mcap_plain, mcap_zstd, db3;
  bool ok = false;
  ~BenchFiles() {
    if (!dir.empty()) fs::remove_all(dir);
  }
};

std::vector<std::vector<std::uint8_t>> realMessages() {
  std::vector<std::vector<std::uint8_t>> out;
  const auto folder = bench::dataDir() / "bags/nebula_xt32";
  if (!fs::exists(folder)) return out;
  bag::Bag source(folder);
  while (const auto m = source.next()) out.emplace_back(m->data.begin(), m->data.end());
  return out;
}

void writeDb3(const fs::path& path, const std::vector<std::vector<std::uint8_t>>& messages, std::size_t count) {
  sqlite3* db = nullptr;
  sqlite3_open(path.c_str(), &db);
  sqlite3_exec(db,
               "CREATE TABLE topics(id INTEGER PRIMARY KEY, name TEXT NOT NULL, type TEXT NOT NULL, "
               "serialization_format TEXT NOT NULL, offered_qos_profiles TEXT NOT NULL);"
               "CREATE TABLE messages(id INTEGER PRIMARY KEY, topic_id INTEGER NOT NULL, timestamp INTEGER NOT NULL, "
               "data BLOB NOT NULL);"
               "CREATE INDEX timestamp_idx ON messages (timestamp ASC);"
               "INSERT INTO topics VALUES(1, '/pandar_packets', 'pandar_msgs/msg/PandarScan', 'cdr', '');"
               "BEGIN;",
               nullptr, nullptr, nullptr);
  sqlite3_stmt* insert = nullptr;
  sqlite3_prepare_v2(db, "INSERT INTO messages(topic_id, timestamp, data) VALUES(1, ?, ?)", -1, &insert, nullptr);
  for (std::size_t i = 0; i < count; ++i) {
    const auto& m = messages[i % messages.size()];
    sqlite3_bind_int64(insert, 1, std::int64_t(i) * 100'000'000);
    sqlite3_bind_blob(insert, 2, m.data(), int(m.size()), SQLITE_STATIC);
    sqlite3_step(insert);
    sqlite3_reset(insert);
  }
  sqlite3_finalize(insert);
  sqlite3_exec(db, "COMMIT;", nullptr, nullptr, nullptr);
  sqlite3_close(db);
}

BenchFiles& files() {
  static BenchFiles f = [] {
    BenchFiles b;
    const auto messages = realMessages();
    if (messages.empty()) return b;
    std::string pattern = (fs::temp_directory_path() / "rigcal_bag_bench_XXXXXX").string();
    if (!mkdtemp(pattern.data())) return b;
    b.dir = pattern;
    b.mcap_plain = b.dir / "plain.mcap";
    b.mcap_zstd = b.dir / "zstd.mcap";
    b.db3 = b.dir / "bag.db3";
    std::size_t count = 0, bytes = 0;
    while (bytes < kTargetBytes) bytes += messages[count++ % messages.size()].size();
    bag::test::McapTestWriter plain, zstd;
    for (std::size_t i = 0; i < count; ++i) {  // one message per chunk: each is ~0.75 MB, rosbag2's chunk size
      bag::test::TestMessage m{1, std::uint64_t(i) * 100'000'000, messages[i % messages.size()]};
      plain.addChunk({m}, "");
      zstd.addChunk({m}, "zstd");
    }
    bag::test::McapTestWriter::save(b.mcap_plain, plain.bytes(true));
    bag::test::McapTestWriter::save(b.mcap_zstd, zstd.bytes(true));
    writeDb3(b.db3, messages, count);
    b.ok = true;
    return b;
  }();
  return f;
}

void report(benchmark::State& state, const fs::path& file) {
  const auto size = fs::file_size(file);
  state.SetBytesProcessed(std::int64_t(state.iterations() * size));
  state.counters["file_MB"] = double(size) / 1e6;
}

void readBag(benchmark::State& state, fs::path BenchFiles::*which) {
  if (!files().ok) {
    state.SkipWithError("bags/nebula_xt32 not found (set RIGCAL_DATA_DIR)");
    return;
  }
  const fs::path file = files().*which;
  for (auto _ : state) {
    bag::Bag bag(file);
    std::uint64_t checksum = 0, count = 0;
    while (const auto m = bag.next()) {
      checksum += m->data[m->data.size() / 2];
      ++count;
    }
    benchmark::DoNotOptimize(checksum);
    state.counters["messages"] = double(count);
  }
  report(state, file);
}

void catToDevNull(benchmark::State& state, fs::path BenchFiles::*which) {
  if (!files().ok) {
    state.SkipWithError("bags/nebula_xt32 not found (set RIGCAL_DATA_DIR)");
    return;
  }
  const fs::path file = files().*which;
  std::vector<char> buffer(128 << 10);  // coreutils cat's block size
  for (auto _ : state) {
    const int fd = ::open(file.c_str(), O_RDONLY);
    while (::read(fd, buffer.data(), buffer.size()) > 0) benchmark::DoNotOptimize(buffer.data());
    ::close(fd);
  }
  report(state, file);
}

}  // namespace

#define BAG_BENCH(name, member)                                                                          \
  BENCHMARK_CAPTURE(readBag, name, &BenchFiles::member)->Unit(benchmark::kMillisecond)->UseRealTime()    \
      ->ComputeStatistics("p99", rigcal::bench::p99);                                                    \
  BENCHMARK_CAPTURE(catToDevNull, name, &BenchFiles::member)->Unit(benchmark::kMillisecond)->UseRealTime() \
      ->ComputeStatistics("p99", rigcal::bench::p99)
BAG_BENCH(mcap_uncompressed, mcap_plain);
BAG_BENCH(mcap_zstd, mcap_zstd);
BAG_BENCH(sqlite3, db3);

BENCHMARK_MAIN();
