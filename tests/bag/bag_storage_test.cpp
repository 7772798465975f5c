// rosbag2's own bags (MCAP zstd, a 5-file split MCAP, uncompressed MCAP, sqlite3): every topic's name,
// type and message count and the bag's time range exactly as the metadata.yaml rosbag2 wrote says.
#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <cstring>
#include <fstream>
#include <iterator>
#include <limits>
#include <map>

#include "rigcal/bag/bag.hpp"
#include "rigcal/bag/mcap_file.hpp"
#include "test_data.hpp"

namespace rigcal::bag {
namespace {

struct Expected {
  std::map<std::string, std::pair<std::string, std::uint64_t>> topics;  // name -> type, count
  std::uint64_t message_count = 0;
  TimeNs start = 0, duration = 0;
};

Expected readMetadata(const std::filesystem::path& folder) {
  const YAML::Node info = YAML::LoadFile((folder / "metadata.yaml").string())["rosbag2_bagfile_information"];
  Expected e;
  for (const auto& t : info["topics_with_message_count"])
    e.topics[t["topic_metadata"]["name"].as<std::string>()] = {t["topic_metadata"]["type"].as<std::string>(),
                                                                t["message_count"].as<std::uint64_t>()};
  e.message_count = info["message_count"].as<std::uint64_t>();
  e.start = info["starting_time"]["nanoseconds_since_epoch"].as<TimeNs>();
  e.duration = info["duration"]["nanoseconds"].as<TimeNs>();
  return e;
}

struct Read {
  std::map<std::string, std::uint64_t> counts;
  std::uint64_t total = 0;
  TimeNs first = std::numeric_limits<TimeNs>::max(), last = std::numeric_limits<TimeNs>::min();
  bool ordered = true;
};

Read readAll(Bag& bag) {
  Read r;
  TimeNs previous = std::numeric_limits<TimeNs>::min();
  while (const auto m = bag.next()) {
    ++r.counts[bag.topics()[m->topic].name];
    ++r.total;
    r.first = std::min(r.first, m->log_time_ns);
    r.last = std::max(r.last, m->log_time_ns);
    r.ordered = r.ordered && m->log_time_ns >= previous;
    previous = m->log_time_ns;
  }
  return r;
}

// An independent reading of an MCAP file's Statistics record (summary section): message start and end
// time, for bags whose metadata.yaml time range is not the data's (rosbag2's own wbag test resource).
std::pair<TimeNs, TimeNs> mcapStatisticsTimeRange(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  const std::vector<char> b((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  auto u64 = [&](std::size_t at) {
    std::uint64_t v;
    std::memcpy(&v, b.data() + at, 8);
    return v;
  };
  const std::size_t footer = b.size() - 8 - 29;
  for (std::size_t p = std::size_t(u64(footer + 9)); p < footer; p += 9 + std::size_t(u64(p + 1)))
    if (b[p] == 0x0B) return {TimeNs(u64(p + 9 + 26)), TimeNs(u64(p + 9 + 34))};  // after 8+2+4+4+4+4 counts
  ADD_FAILURE() << file << ": no Statistics record";
  return {0, 0};
}

void expectMatchesMetadata(const std::string& folder_name, std::size_t expected_files,
                           bool time_range_from_mcap_statistics = false) {
  RIGCAL_REQUIRE_DATA(folder, "bags/rosbag2/" + folder_name);
  const Expected expected = readMetadata(folder);
  Bag bag(folder);
  EXPECT_EQ(bag.files().size(), expected_files);
  const Read read = readAll(bag);
  EXPECT_TRUE(read.ordered) << "messages must come out in log-time order across files";
  EXPECT_TRUE(bag.warnings().empty());
  EXPECT_EQ(read.total, expected.message_count);
  if (time_range_from_mcap_statistics) {
    TimeNs first = std::numeric_limits<TimeNs>::max(), last = std::numeric_limits<TimeNs>::min();
    for (const auto& file : bag.files()) {
      const auto [lo, hi] = mcapStatisticsTimeRange(file);
      first = std::min(first, lo);
      last = std::max(last, hi);
    }
    EXPECT_EQ(read.first, first);
    EXPECT_EQ(read.last, last);
  } else {
    EXPECT_EQ(read.first, expected.start);
    EXPECT_EQ(read.last - read.first, expected.duration);
  }
  for (const auto& [name, type_count] : expected.topics) {
    const auto topic = bag.findTopic(name);
    if (type_count.second == 0 && !topic) continue;  // a topic never published need not be stored
    ASSERT_TRUE(topic) << name << " missing; bag has " << bag.topicList();
    EXPECT_EQ(bag.topics()[*topic].type, type_count.first) << name;
    EXPECT_EQ(bag.topics()[*topic].serialization_format, "cdr") << name;
    EXPECT_EQ(read.counts.count(name) ? read.counts.at(name) : 0u, type_count.second) << name;
  }
  for (const auto& t : bag.topics()) EXPECT_TRUE(expected.topics.count(t.name)) << t.name << " not in metadata";
}

TEST(BagStorage, McapZstdTalkerMatchesMetadata) { expectMatchesMetadata("mcap_talker", 1); }
// wbag's metadata.yaml gives starting_time 2623 (the last split file's first message) and duration 411
// (the second file's span): its counts are right, its time range is not the data's. The range is checked
// against the Statistics record of each split file instead (1000 .. 2998 ns).
TEST(BagStorage, McapFiveFileSplitBagMatchesMetadata) { expectMatchesMetadata("mcap_wbag", 5, true); }
TEST(BagStorage, McapUncompressedMatchesMetadata) { expectMatchesMetadata("mcap_cdr_test", 1); }
TEST(BagStorage, Sqlite3TalkerMatchesMetadata) { expectMatchesMetadata("sqlite3_talker", 1); }

// A single storage file opens without its folder, and rosbag2's MCAP files carry a usable summary.
TEST(BagStorage, SingleFilesOpenByContentAndUseTheSummary) {
  RIGCAL_REQUIRE_DATA(mcap, "bags/rosbag2/mcap_talker/talker.mcap");
  RIGCAL_REQUIRE_DATA(db3, "bags/rosbag2/sqlite3_talker/talker.db3");
  McapFile file(mcap);
  EXPECT_TRUE(file.indexed());
  EXPECT_GE(file.chunkCount(), 1u);
  Bag from_mcap(mcap), from_db3(db3);
  const Read a = readAll(from_mcap), b = readAll(from_db3);
  EXPECT_EQ(a.total, 20u);
  EXPECT_EQ(a.counts, b.counts) << "the same talker run recorded by both storage plugins";
  EXPECT_EQ(a.first, b.first);
}

}  // namespace
}  // namespace rigcal::bag
