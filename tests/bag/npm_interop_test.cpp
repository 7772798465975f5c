// An MCAP written by an independent implementation (Foxglove's npm @mcap/core and
// @foxglove/rosmsg2-serialization, run with node: tests/bag/npm/write_clouds.mjs) holding a real
// capture's decoded clouds (the real rigcal binary decodes velodyne/vlp16_dual.pcap) in four PointCloud2
// field layouts (Velodyne time f32 s, Ouster t u32 ns, Hesai timestamp f64 absolute s, Livox offset_time
// u32 ns): our reader reads every cloud back point for point, per-point times included.
#include <gtest/gtest.h>

#include <charconv>
#include <cstdlib>
#include <fstream>
#include <map>
#include <regex>
#include <sstream>

#include "rigcal/bag/bag.hpp"
#include "rigcal/bag/mcap_file.hpp"
#include "rigcal/bag/point_cloud2_message.hpp"
#include "rigcal/core/pcd_io.hpp"
#include "rigcal/core/point_table.hpp"
#include "run_command.hpp"
#include "test_data.hpp"

namespace rigcal::test {
namespace {

namespace fs = std::filesystem;

// A float's exact value as the shortest double text: JavaScript parses it exactly, so Math.fround (what
// DataView.setFloat32 does) gives back the same float.
std::string exactText(float v) {
  char buf[64];
  const auto r = std::to_chars(buf, buf + sizeof buf, double(v));
  return std::string(buf, r.ptr);
}

template <class V>
void jsonArray(std::ostream& out, const char* name, const V& values) {
  out << '"' << name << "\": [";
  for (std::size_t i = 0; i < values.size(); ++i) {
    if (i) out << ',';
    if constexpr (std::is_same_v<typename V::value_type, float>)
      out << exactText(values[i]);
    else
      out << +values[i];
  }
  out << ']';
}

bool nodeModulesInstalled() { return fs::exists(fs::path(RIGCAL_NPM_DIR) / "node_modules" / "@mcap" / "core"); }

TEST(NpmInterop, PointCloud2FromFoxgloveWritersReadsBackPointForPoint) {
  RIGCAL_REQUIRE_DATA(pcap, "velodyne/vlp16_dual.pcap");
  if (std::system("node --version >/dev/null 2>&1") != 0 || !nodeModulesInstalled()) {
    if (inCi()) FAIL() << "node or " << RIGCAL_NPM_DIR << "/node_modules missing under CI (scripts/install-deps)";
    GTEST_SKIP() << "node or the npm packages are not installed: run scripts/install-deps";
  }
  TempDir dir;
  const auto decoded = runRigcal({"decode", pcap.string(), "--sensor", "VLP-16", "--out", (dir / "scans").string()});
  ASSERT_EQ(decoded.exit_code, 0) << decoded.err;
  // "scan_000003.pcd  points 14879  stamp_ns 1673398940854499304 ..." per scan.
  const std::regex line(R"((scan_\d+\.pcd)\s+points\s+(\d+)\s+stamp_ns\s+(\d+))");
  std::vector<Scan> scans;
  for (auto it = std::sregex_iterator(decoded.out.begin(), decoded.out.end(), line); it != std::sregex_iterator(); ++it) {
    Scan s = toScan(readPcd(dir / "scans" / (*it)[1].str()));
    s.stamp_ns = std::stoll((*it)[3].str());
    ASSERT_EQ(s.size(), std::stoul((*it)[2].str()));
    scans.push_back(std::move(s));
  }
  ASSERT_GE(scans.size(), 3u) << decoded.out;

  std::ofstream json(dir / "clouds.json");
  json << "{\"scans\": [";
  for (std::size_t k = 0; k < scans.size(); ++k) {
    const Scan& s = scans[k];
    json << (k ? ",\n" : "") << "{\"stamp_ns\": \"" << s.stamp_ns << "\", \"frame_id\": \"velodyne\", ";
    jsonArray(json, "x", s.x);
    json << ", ";
    jsonArray(json, "y", s.y);
    json << ", ";
    jsonArray(json, "z", s.z);
    json << ", ";
    jsonArray(json, "intensity", s.intensity);
    json << ", ";
    jsonArray(json, "ring", s.ring);
    json << ", ";
    jsonArray(json, "offset_ns", s.offset_ns);
    json << "}";
  }
  json << "]}\n";
  json.close();
  const fs::path mcap = dir / "foxglove.mcap";
  const std::string command = "node '" + (fs::path(RIGCAL_NPM_DIR) / "write_clouds.mjs").string() + "' '" +
                              (dir / "clouds.json").string() + "' '" + mcap.string() + "' >'" +
                              (dir / "node.log").string() + "' 2>&1";
  const int status = std::system(command.c_str());
  std::ifstream log(dir / "node.log");
  ASSERT_EQ(status, 0) << std::string(std::istreambuf_iterator<char>(log), {});

  EXPECT_TRUE(bag::McapFile(mcap).indexed());
  struct Expect {
    const char* time_field;
    TimeNs tolerance_ns;  // f32 seconds after the stamp: ~8 ns at 0.1 s; f64 absolute: ~0.24 us at 1.7e9 s
  };
  const std::map<std::string, Expect> topics = {{"/velodyne/points", {"time", 10}},
                                                {"/ouster/points", {"t", 0}},
                                                {"/hesai/points", {"timestamp", 1000}},
                                                {"/livox/points", {"offset_time", 0}}};
  std::map<std::string, std::size_t> seen;
  bag::Bag reader(mcap);
  ASSERT_EQ(reader.topics().size(), topics.size()) << reader.topicList();
  std::size_t points = 0;
  while (const auto m = reader.next()) {
    const std::string& topic = reader.topics()[m->topic].name;
    ASSERT_EQ(reader.topics()[m->topic].type, bag::kPointCloud2Type);
    const Expect& e = topics.at(topic);
    const auto cloud = bag::decodePointCloud2(m->data, topic);
    const Scan& want = scans.at(seen[topic]++);
    EXPECT_EQ(cloud.time_field, e.time_field);
    EXPECT_EQ(cloud.frame_id, "velodyne");
    EXPECT_EQ(cloud.header_stamp_ns, want.stamp_ns);
    ASSERT_EQ(cloud.scan.size(), want.size()) << topic;
    for (std::size_t i = 0; i < want.size(); ++i) {
      ASSERT_EQ(cloud.scan.x[i], want.x[i]) << topic << " point " << i;
      ASSERT_EQ(cloud.scan.y[i], want.y[i]) << topic << " point " << i;
      ASSERT_EQ(cloud.scan.z[i], want.z[i]) << topic << " point " << i;
      ASSERT_EQ(cloud.scan.intensity[i], want.intensity[i]) << topic << " point " << i;
      if (topic != "/livox/points") {
        ASSERT_EQ(cloud.scan.ring[i], want.ring[i]) << topic << " point " << i;
      }
      ASSERT_LE(std::llabs(cloud.scan.pointTime(i) - want.pointTime(i)), e.tolerance_ns) << topic << " point " << i;
    }
    points += want.size();
  }
  for (const auto& [topic, e] : topics) EXPECT_EQ(seen[topic], scans.size()) << topic;
  EXPECT_GT(points, 4 * 20000u);
}

}  // namespace
}  // namespace rigcal::test
