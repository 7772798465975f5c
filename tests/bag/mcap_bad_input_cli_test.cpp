// Bad MCAP input through the real binary (`rigcal decode --bag`), on a real capture: nebula's VLP-32C
// packet bag rewritten as an MCAP of one VelodyneScan per zstd chunk, then damaged one way per case as the
// issue lists them. A cut file or a damaged later chunk keeps the scans decoded before it and says why
// in one warning line naming the file and offset; damage that leaves nothing to decode, an unknown type on
// the chosen topic and an absent topic are one-line errors with exit code 4 (bad input).
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <functional>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "rigcal/bag/bag.hpp"
#include "rigcal/bag/mcap_writer.hpp"
#include "run_command.hpp"
#include "test_data.hpp"

namespace rigcal::test {
namespace {

namespace fs = std::filesystem;
using Bytes = std::vector<std::uint8_t>;

constexpr const char* kTopic = "/sensing/lidar/front/velodyne_packets";

Bytes readBytes(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

void save(const fs::path& p, const Bytes& b) {
  std::ofstream(p, std::ios::binary).write(reinterpret_cast<const char*>(b.data()), std::streamsize(b.size()));
}

/// The VelodyneScan messages of nebula's bag as an MCAP, each in its own zstd chunk (`cut_message`: that
/// message written `cut_bytes` short, as a CDR message shorter than its layout); plus, with `extra_type`,
/// a second topic /lidar/unknown of that type holding the same messages.
void writeMcap(const fs::path& source, const fs::path& out, int cut_message = -1, std::size_t cut_bytes = 0,
               const std::string& extra_type = {}) {
  bag::McapWriterOptions options;
  options.chunk_bytes = 1;  // every message closes its chunk
  bag::McapWriter writer(out, options);
  const auto channel = writer.addChannel(kTopic, writer.addSchema("velodyne_msgs/msg/VelodyneScan", "ros2msg", ""));
  const auto extra = extra_type.empty() ? 0 : writer.addChannel("/lidar/unknown", writer.addSchema(extra_type, "ros2msg", ""));
  bag::Bag in(source);
  int k = 0;
  while (const auto m = in.next()) {
    auto data = m->data;
    if (k++ == cut_message) data = data.first(data.size() - cut_bytes);
    writer.write(channel, m->log_time_ns, data);
    if (!extra_type.empty()) writer.write(extra, m->log_time_ns, data);
  }
  writer.close();
}

std::vector<std::size_t> chunkOffsets(const Bytes& b) {
  std::vector<std::size_t> out;
  for (std::size_t p = 8; p + 9 <= b.size();) {
    std::uint64_t length;
    std::memcpy(&length, b.data() + p + 1, 8);
    if (b[p] == 0x06) out.push_back(p);
    if (b[p] == 0x0F || b[p] == 0x02) break;  // Data End, Footer
    p += 9 + std::size_t(length);
  }
  return out;
}

// A chunk's fields after the record header: start, end, uncompressed size (8 each), CRC (4), compression.
constexpr std::size_t kCrcField = 9 + 24, kCompressionField = 9 + 28;

std::size_t chunkRecordsOffset(const Bytes& b, std::size_t chunk) {
  std::uint32_t n;
  std::memcpy(&n, b.data() + chunk + kCompressionField, 4);
  return chunk + kCompressionField + 4 + n + 8;
}

struct BadMcap : ::testing::Test {
  void SetUp() override {
    source = dataDir() / "bags/nebula_vlp32";
    if (!fs::exists(source)) GTEST_SKIP() << "missing test data: " << source;
    writeMcap(source, dir / "good.mcap");
    good = readBytes(dir / "good.mcap");
    chunks = chunkOffsets(good);
    ASSERT_EQ(chunks.size(), 5u) << "one chunk per message";
    baseline = decode(dir / "good.mcap", "good");
    ASSERT_EQ(baseline.exit_code, 0) << baseline.err;
    baseline_scans = scans(baseline);
    ASSERT_GE(baseline_scans, 3);
  }
  CommandResult decode(const fs::path& bag, const std::string& out, const std::string& topic = {}) {
    std::vector<std::string> args{"decode", "--bag", bag.string(), "--sensor", "VLP-32C", "--out", (dir / out).string()};
    if (!topic.empty()) args.insert(args.end(), {"--topic", topic});
    return runRigcal(args);
  }
  static int scans(const CommandResult& r) {
    const auto at = r.out.find("decoded ");
    return at == std::string::npos ? -1 : std::stoi(r.out.substr(at + 8));
  }
  /// good.mcap with `edit` applied, decoded.
  template <class Edit>
  CommandResult damaged(const std::string& name, Edit edit) {
    Bytes b = good;
    edit(b);
    save(dir / (name + ".mcap"), b);
    return decode(dir / (name + ".mcap"), name);
  }

  TempDir dir;
  fs::path source;
  Bytes good;
  std::vector<std::size_t> chunks;
  CommandResult baseline;
  int baseline_scans = 0;
};

std::size_t lines(const std::string& s) { return std::size_t(std::count(s.begin(), s.end(), '\n')); }

/// The first `n` scan files of two decode outputs are the same bytes.
void expectSameFirstScans(const fs::path& a, const fs::path& b, int n) {
  for (int i = 0; i < n; ++i) {
    char name[32];
    std::snprintf(name, sizeof name, "scan_%06d.pcd", i);
    ASSERT_TRUE(fs::exists(a / name) && fs::exists(b / name)) << name;
    EXPECT_TRUE(readBytes(a / name) == readBytes(b / name)) << name;
  }
}

TEST_F(BadMcap, ACutFileKeepsTheScansBeforeTheCutAndWarnsOnce) {
  const auto cut = damaged("cut", [&](Bytes& b) { b.resize(chunks[3] + 40); });  // inside the 4th chunk
  ASSERT_EQ(cut.exit_code, 0) << cut.err;
  const int n = scans(cut);
  EXPECT_GT(n, 0);
  EXPECT_LT(n, baseline_scans);
  EXPECT_EQ(lines(cut.err), 1u) << cut.err;
  EXPECT_NE(cut.err.find("warning: " + (dir / "cut.mcap").string() + ": truncated at offset " +
                         std::to_string(chunks[3])),
            std::string::npos) << cut.err;
  EXPECT_NE(cut.err.find("(using the 3 chunks before the cut)"), std::string::npos) << cut.err;
  // The last scan before the cut may be short of its end: the ones before it are the intact file's.
  expectSameFirstScans(dir / "good", dir / "cut", n - 1);
}

// A damaged chunk after good ones: the stream stops there, what came before is decoded and kept, and
// the one warning line names the file, the chunk's offset and what is wrong with it.
TEST_F(BadMcap, ADamagedLaterChunkKeepsWhatCameBeforeAndNamesItsOffset) {
  const std::string chunk4 = ": chunk at offset " + std::to_string(chunks[3]) + ": ";
  struct Case {
    std::string name, reason;
    std::function<void(Bytes&)> edit;
  };
  const std::vector<Case> cases{
      {"crc", "chunk CRC mismatch", [&](Bytes& b) { b[chunks[3] + kCrcField] ^= 0x01; }},
      {"compression", "unknown compression 'zstx' (zstd, lz4 or none)",
       [&](Bytes& b) { b[chunks[3] + kCompressionField + 4 + 3] = 'x'; }},
      {"inflate", "zstd chunk does not decompress",
       [&](Bytes& b) {
         const std::size_t r = chunkRecordsOffset(b, chunks[3]);
         for (std::size_t i = r + 20; i < r + 60; ++i) b[i] ^= 0x5A;  // inside the compressed blocks
       }},
  };
  for (const auto& c : cases) {
    const auto r = damaged(c.name, c.edit);
    ASSERT_EQ(r.exit_code, 0) << c.name << ": " << r.err;
    const int n = scans(r);
    EXPECT_GT(n, 0) << c.name;
    EXPECT_LT(n, baseline_scans) << c.name;
    EXPECT_EQ(lines(r.err), 1u) << c.name << ": " << r.err;
    EXPECT_NE(r.err.find((dir / (c.name + ".mcap")).string() + chunk4 + c.reason), std::string::npos) << r.err;
    expectSameFirstScans(dir / "good", dir / c.name, n - 1);
  }
}

TEST_F(BadMcap, ADamagedFirstChunkIsAOneLineErrorWithExitCode4) {
  const auto r = damaged("first", [&](Bytes& b) { b[chunks[0] + kCrcField] ^= 0x01; });
  EXPECT_EQ(r.exit_code, 4);
  EXPECT_EQ(lines(r.err), 1u) << r.err;
  EXPECT_NE(r.err.find("first.mcap: chunk at offset " + std::to_string(chunks[0]) + ": chunk CRC mismatch"),
            std::string::npos) << r.err;
}

TEST_F(BadMcap, AMessageShorterThanItsLayoutIsDroppedAndTheOthersDecoded) {
  writeMcap(source, dir / "short.mcap", 2, 100);  // the third scan message loses the end of its last packet
  const auto r = decode(dir / "short.mcap", "short");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_GE(scans(r), baseline_scans - 2) << "one message of five lost: at most its two scans";
  EXPECT_EQ(lines(r.err), 1u) << r.err;
  EXPECT_NE(r.err.find("1 malformed messages dropped, last: " + (dir / "short.mcap").string() + ": " + kTopic +
                       " message at log time "),
            std::string::npos) << r.err;
  EXPECT_NE(r.err.find("message shorter than its layout: field packets[].data"), std::string::npos) << r.err;
}

TEST_F(BadMcap, AnUnknownTypeOnTheChosenTopicAnAbsentTopicAndAnEmptyFileAreExitCode4) {
  writeMcap(source, dir / "unknown.mcap", -1, 0, "acme_msgs/msg/LidarBlob");
  const auto unknown = decode(dir / "unknown.mcap", "unknown", "/lidar/unknown");
  EXPECT_EQ(unknown.exit_code, 4);
  EXPECT_EQ(lines(unknown.err), 1u) << unknown.err;
  EXPECT_NE(unknown.err.find("unknown.mcap: topic /lidar/unknown has type acme_msgs/msg/LidarBlob, not a packet type"),
            std::string::npos) << unknown.err;

  const auto absent = decode(dir / "unknown.mcap", "absent", "/nope");
  EXPECT_EQ(absent.exit_code, 4);
  EXPECT_EQ(lines(absent.err), 1u) << absent.err;
  EXPECT_NE(absent.err.find("topic /nope not in the bag; it has " + std::string(kTopic) + ", /lidar/unknown"),
            std::string::npos) << absent.err;

  {
    bag::McapWriter empty(dir / "empty.mcap");
    empty.close();
  }
  const auto empty = decode(dir / "empty.mcap", "empty");
  EXPECT_EQ(empty.exit_code, 4);
  EXPECT_EQ(lines(empty.err), 1u) << empty.err;
  EXPECT_NE(empty.err.find("empty.mcap: empty bag (no topics)"), std::string::npos) << empty.err;
}

}  // namespace
}  // namespace rigcal::test
