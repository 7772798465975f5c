// McapWriter against our reader, both paths (summary index and linear scan), zstd and stored chunks:
// every message comes back exactly, in log-time order. Real bags (rosbag2's and nebula's) copied through
// the writer read back identical. The file's record structure (chunks, message indexes, statistics,
// summary offsets, CRCs) is checked by walking it independently of the reader.
#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <random>
#include <tuple>

#include "rigcal/bag/bag.hpp"
#include "rigcal/bag/byte_cursor.hpp"
#include "rigcal/bag/crc32.hpp"
#include "rigcal/bag/mcap_file.hpp"
#include "rigcal/bag/mcap_records.hpp"
#include "rigcal/bag/mcap_writer.hpp"
#include "rigcal/bag/ros_message_definitions.hpp"
#include "test_data.hpp"

namespace rigcal::bag {
namespace {

using rigcal::test::TempDir;

using Bytes = std::vector<std::uint8_t>;

struct Sent {
  std::string topic;
  TimeNs log_time;
  Bytes data;
  bool operator==(const Sent&) const = default;
};

struct Variant {
  std::string compression;
  bool summary;
};

std::string variantName(const testing::TestParamInfo<Variant>& info) {
  return (info.param.compression.empty() ? std::string("stored") : info.param.compression) +
         (info.param.summary ? "_indexed" : "_linear");
}

std::vector<Sent> readAll(StorageReader& reader) {
  std::vector<Sent> out;
  while (const auto m = reader.next())
    out.push_back({reader.topics()[m->topic].name, m->log_time_ns, Bytes(m->data.begin(), m->data.end())});
  return out;
}

Bytes fileBytes(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  return Bytes(std::istreambuf_iterator<char>(in), {});
}

class McapWriterRoundTrip : public testing::TestWithParam<Variant> {};

TEST_P(McapWriterRoundTrip, EveryMessageReadsBackExactlyInLogTimeOrder) {
  TempDir dir;
  const auto file = dir / "out.mcap";
  McapWriterOptions options;
  options.compression = GetParam().compression;
  options.summary = GetParam().summary;
  options.chunk_bytes = 4096;  // many chunks
  std::vector<Sent> sent;
  std::mt19937 rng(7);
  {
    McapWriter writer(file, options);
    const auto schema = writer.addSchema("std_msgs/msg/String", "ros2msg", "string data\n");
    const std::uint16_t a = writer.addChannel("/a", schema), b = writer.addChannel("/b", schema);
    for (int i = 0; i < 600; ++i) {
      // Mostly increasing times with some written late, as a recorder with several sources writes them.
      const TimeNs t = 1'700'000'000'000'000'000 + TimeNs(i) * 1000 - (i % 7 == 3 ? 2500 : 0) + (i % 2);
      Bytes data(std::size_t(rng() % 300), 0);
      for (auto& v : data) v = std::uint8_t(rng());
      const bool on_a = rng() % 3 != 0;
      writer.write(on_a ? a : b, t, data);
      sent.push_back({on_a ? "/a" : "/b", t, data});
    }
    EXPECT_EQ(writer.messageCount(), 600u);
    EXPECT_GT(writer.chunkCount(), 10u);
    writer.close();
  }
  std::stable_sort(sent.begin(), sent.end(), [](const Sent& x, const Sent& y) { return x.log_time < y.log_time; });

  McapFile mcap(file);
  EXPECT_EQ(mcap.indexed(), GetParam().summary);
  EXPECT_TRUE(mcap.warning().empty()) << mcap.warning();
  ASSERT_EQ(mcap.topics().size(), 2u);
  EXPECT_EQ(mcap.topics()[0].type, "std_msgs/msg/String");
  EXPECT_EQ(mcap.topics()[0].serialization_format, "cdr");
  const auto got = readAll(mcap);
  ASSERT_EQ(got.size(), sent.size());
  for (std::size_t i = 0; i < got.size(); ++i) {
    EXPECT_EQ(got[i].log_time, sent[i].log_time) << i;
    EXPECT_EQ(got[i].topic, sent[i].topic) << i;
  }
  // Equal log times may come out in either order across chunks: compare as multisets of whole messages.
  auto key = [](const Sent& s) { return std::tie(s.log_time, s.topic, s.data); };
  auto sorted = [&](std::vector<Sent> v) {
    std::sort(v.begin(), v.end(), [&](const Sent& x, const Sent& y) { return key(x) < key(y); });
    return v;
  };
  EXPECT_TRUE(sorted(got) == sorted(sent));
}

INSTANTIATE_TEST_SUITE_P(Variants, McapWriterRoundTrip,
                         testing::Values(Variant{"zstd", true}, Variant{"zstd", false}, Variant{"", true},
                                         Variant{"", false}),
                         variantName);

// Walks the written file record by record, as any MCAP reader would, and checks what the spec asks.
TEST(McapWriter, FileStructureFollowsTheSpec) {
  TempDir dir;
  const auto file = dir / "s.mcap";
  McapWriterOptions options;
  options.chunk_bytes = 1000;
  {
    McapWriter writer(file, options);
    const auto schema = writer.addSchema("std_msgs/msg/String", "ros2msg", "string data\n");
    const auto a = writer.addChannel("/a", schema), b = writer.addChannel("/b", schema, "cdr", {{"k", "v"}});
    for (int i = 0; i < 50; ++i) writer.write(i % 3 ? a : b, 1000 + i, Bytes(100, std::uint8_t(i)));
    writer.close();
  }
  const Bytes bytes = fileBytes(file);
  ASSERT_GT(bytes.size(), 16u);
  ASSERT_TRUE(std::equal(mcap::kMagic.begin(), mcap::kMagic.end(), bytes.begin()));
  ASSERT_TRUE(std::equal(mcap::kMagic.begin(), mcap::kMagic.end(), bytes.end() - 8));
  const std::span<const std::uint8_t> all(bytes);
  mcap::RecordSplitter split(all.subspan(8, bytes.size() - 16), "file");
  std::map<int, int> count;
  std::uint64_t stats_messages = 0, stats_chunks = 0, chunk_index_count = 0;
  std::uint64_t data_end_offset = 0, summary_start = 0, summary_offset_start = 0;
  std::uint32_t summary_crc = 0;
  std::map<int, std::pair<std::uint64_t, std::uint64_t>> groups;
  std::uint64_t message_index_entries = 0;
  while (const auto r = split.next()) {
    ++count[r->opcode];
    const std::uint64_t at = 8 + r->offset;
    ByteCursor c(r->body, "record");
    switch (mcap::Opcode(r->opcode)) {
      case mcap::Opcode::kDataEnd: {
        data_end_offset = at;
        const auto crc = c.read<std::uint32_t>();
        EXPECT_EQ(crc, crc32Update(0, all.first(at))) << "data section CRC";
        break;
      }
      case mcap::Opcode::kMessageIndex: {
        c.read<std::uint16_t>();
        message_index_entries += c.read<std::uint32_t>() / 16;
        break;
      }
      case mcap::Opcode::kStatistics:
        stats_messages = c.read<std::uint64_t>();
        EXPECT_EQ(c.read<std::uint16_t>(), 1);  // schemas
        EXPECT_EQ(c.read<std::uint32_t>(), 2u);  // channels
        c.read<std::uint32_t>();
        c.read<std::uint32_t>();
        stats_chunks = c.read<std::uint32_t>();
        EXPECT_EQ(c.read<std::uint64_t>(), 1000u);
        EXPECT_EQ(c.read<std::uint64_t>(), 1049u);
        break;
      case mcap::Opcode::kChunkIndex: {
        ++chunk_index_count;
        const auto index = mcap::parseChunkIndex(r->body, "index");
        // It points at a chunk record of the stated length.
        EXPECT_EQ(bytes.at(index.chunk_start_offset), std::uint8_t(mcap::Opcode::kChunk));
        std::uint64_t length = 0;
        std::memcpy(&length, bytes.data() + index.chunk_start_offset + 1, 8);
        EXPECT_EQ(length + 9, index.chunk_length);
        break;
      }
      case mcap::Opcode::kSummaryOffset: {
        const int group = c.read<std::uint8_t>();
        const auto start = c.read<std::uint64_t>();
        groups[group] = {start, c.read<std::uint64_t>()};
        EXPECT_EQ(bytes.at(start), group) << "a summary group starts with a record of its opcode";
        if (summary_offset_start == 0) summary_offset_start = at;
        break;
      }
      case mcap::Opcode::kFooter: {
        summary_start = c.read<std::uint64_t>();
        EXPECT_EQ(c.read<std::uint64_t>(), summary_offset_start);
        summary_crc = c.read<std::uint32_t>();
        const std::uint64_t crc_end = at + 9 + 16;
        EXPECT_EQ(summary_crc, crc32Update(0, all.subspan(summary_start, crc_end - summary_start)));
        break;
      }
      default:
        break;
    }
  }
  EXPECT_EQ(count[0x01], 1);  // header
  EXPECT_EQ(count[0x02], 1);  // footer
  EXPECT_EQ(count[0x05], 0);  // every message inside a chunk
  EXPECT_GT(count[0x06], 3);
  EXPECT_EQ(stats_messages, 50u);
  EXPECT_EQ(stats_chunks, std::uint64_t(count[0x06]));
  EXPECT_EQ(chunk_index_count, std::uint64_t(count[0x06]));
  EXPECT_EQ(message_index_entries, 50u);
  EXPECT_EQ(summary_start, data_end_offset + 9 + 4);
  EXPECT_EQ(groups.size(), 4u);  // schemas, channels, statistics, chunk indexes
  EXPECT_EQ(count[0x03], 2);      // schema in the data section and in the summary
  EXPECT_EQ(count[0x04], 4);
}

TEST(McapWriter, NothingAtTheNameWithoutClose) {
  TempDir dir;
  {
    McapWriter writer(dir / "x.mcap");
    writer.write(writer.addChannel("/a", writer.addSchema("t/msg/T", "ros2msg", "")), 1, Bytes(3, 1));
  }
  EXPECT_FALSE(std::filesystem::exists(dir / "x.mcap"));
  EXPECT_TRUE(std::filesystem::is_empty(dir.path()));
}

TEST(McapWriter, RefusesWhatItCannotWrite) {
  TempDir dir;
  McapWriterOptions lz4;
  lz4.compression = "lz4";
  EXPECT_THROW(McapWriter(dir / "a.mcap", lz4), std::invalid_argument);
  McapWriter writer(dir / "b.mcap");
  EXPECT_THROW(writer.addChannel("/a", 3), std::invalid_argument);
  EXPECT_THROW(writer.write(5, 1, Bytes{}), std::invalid_argument);
}

TEST(McapWriter, EmptyBagIsValid) {
  TempDir dir;
  McapWriter(dir / "e.mcap").close();
  McapFile mcap(dir / "e.mcap");
  EXPECT_FALSE(mcap.next().has_value());
  EXPECT_TRUE(mcap.warning().empty());
}

TEST(RosMessageDefinitions, IncludeEveryDependencyOnce) {
  const std::string cloud = rosMessageDefinition("sensor_msgs/msg/PointCloud2");
  EXPECT_EQ(cloud.rfind("std_msgs/Header header\n", 0), 0u);
  for (const char* dep : {"MSG: std_msgs/Header\n", "MSG: builtin_interfaces/Time\n", "MSG: sensor_msgs/PointField\n"}) {
    const auto at = cloud.find(dep);
    EXPECT_NE(at, std::string::npos) << dep;
    EXPECT_EQ(cloud.find(dep, at + 1), std::string::npos) << dep;
  }
  EXPECT_NE(rosMessageDefinition("nav_msgs/msg/Odometry").find("MSG: geometry_msgs/TwistWithCovariance\n"),
            std::string::npos);
  EXPECT_THROW(rosMessageDefinition("foo_msgs/msg/Bar"), std::invalid_argument);
}

// Real bags (rosbag2's MCAPs and sqlite3, nebula's packet bags) copied message by message through the
// writer read back identical, by both reading paths.
class McapWriterCopiesRealBags : public testing::TestWithParam<const char*> {};

TEST_P(McapWriterCopiesRealBags, Identically) {
  RIGCAL_REQUIRE_DATA(source_path, std::string("bags/") + GetParam());
  std::vector<Sent> original;
  std::vector<TopicInfo> topics;
  {
    Bag source(source_path);
    while (const auto m = source.next())
      original.push_back({source.topics()[m->topic].name, m->log_time_ns, Bytes(m->data.begin(), m->data.end())});
    topics = source.topics();
  }
  ASSERT_FALSE(original.empty());
  for (const Variant& v : {Variant{"zstd", true}, Variant{"", false}}) {
    TempDir dir;
    McapWriterOptions options;
    options.compression = v.compression;
    options.summary = v.summary;
    {
      McapWriter writer(dir / "copy.mcap", options);
      std::map<std::string, std::uint16_t> channel;
      for (const auto& t : topics)
        channel[t.name] = writer.addChannel(t.name, writer.addSchema(t.type, "ros2msg", ""), t.serialization_format);
      for (const auto& m : original) writer.write(channel.at(m.topic), m.log_time, m.data);
      writer.close();
    }
    McapFile copy(dir / "copy.mcap");
    EXPECT_EQ(copy.indexed(), v.summary);
    const auto got = readAll(copy);
    ASSERT_EQ(got.size(), original.size());
    EXPECT_TRUE(got == original) << GetParam() << " " << v.compression;
    for (const auto& t : topics) {
      const auto found = std::find_if(copy.topics().begin(), copy.topics().end(),
                                      [&](const TopicInfo& c) { return c.name == t.name; });
      ASSERT_NE(found, copy.topics().end());
      EXPECT_EQ(found->type, t.type);
    }
  }
}

INSTANTIATE_TEST_SUITE_P(SharedBags, McapWriterCopiesRealBags,
                         testing::Values("nebula_xt32", "robosense_helios16p", "rosbag2/mcap_wbag",
                                         "rosbag2/mcap_talker"),
                         [](const testing::TestParamInfo<const char*>& param) {
                           std::string name = param.param;
                           std::replace(name.begin(), name.end(), '/', '_');
                           return name;
                         });

}  // namespace
}  // namespace rigcal::bag
