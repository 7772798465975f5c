// The degraded-capture table of issue 18 through the real binaries: one short simulated drive (the lost
// preset's first 16 s: OS1-64 mapping, one VLP-16 0.3 m / 5° off), its capture damaged the way networks
// and clocks damage captures, then `rigcal calibrate` and `rigcal compare`. Each row either calibrates
// within the accuracy goal (1 cm / 0.05°) or refuses to call the result ok (non-zero exit, a one-line
// message, report.json's status not "ok"). None may print a wrong `ok`.
// Measured (Release, load 3-4 from parallel builds, 10 s default deadline), error of front_left / exit:
//   clean 0.19 cm ok (dl) exit 0; loss 2 % 0.18 cm unverified (deadline: 1 of 4 frames) exit 6; loss 10 %
//   exit 5 (1 of 2 frames) with the losses warned; reorder 16 and duplicates 1 %: 0.18-0.19 cm, unverified
//   (deadline); clock +50 ms 6.9 cm and +1 s 68 cm: unverified naming the clock (+52.9 / +1002.9 ms);
//   corrupt record half-way: base-lidar failed (exit 1), damaged capture warned; truncated at 80 %:
//   unverified, damaged capture warned. Measured clock lags with agreeing clocks: top 14.3, front_left 11.4 ms.
// Clock rows of the rig's time_offset_ns (issue 18, same conditions): +35 ms uncorrected 4.83 cm, unverified
//   naming +37.9 ms; time_offset_ns given (35 ms, 50 ms, 1 s): exit 0, 0.17-0.19 cm, residual +2.9 ms
//   (± 0.05); `estimate`: +53.0 / +1003.0 ms (± 0.1) from 101 sweeps each, 0.47 cm (the estimate also takes
//   the 2.9 ms by which an OS1-64's and a VLP-16's sweep-end lags differ with agreeing clocks).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>
#include <vector>

#include "calibrate_chain.hpp"
#include "rigcal/drivers/packet_restamper.hpp"
#include "sanitizers.hpp"
#include "test_data.hpp"

namespace rigcal::test {
namespace {

namespace fs = std::filesystem;

/// A classic pcap file as its global header and records (each its 16-byte header and captured bytes).
struct PcapFile {
  std::vector<std::uint8_t> header;
  std::vector<std::vector<std::uint8_t>> records;
};

std::uint32_t le32(const std::uint8_t* p) { return p[0] | p[1] << 8 | p[2] << 16 | std::uint32_t(p[3]) << 24; }

PcapFile readPcap(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  const std::vector<std::uint8_t> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  PcapFile f;
  if (bytes.size() < 24) return f;
  f.header.assign(bytes.begin(), bytes.begin() + 24);
  for (std::size_t at = 24; at + 16 <= bytes.size();) {
    const std::size_t size = 16 + le32(&bytes[at + 8]);
    if (at + size > bytes.size()) break;
    f.records.emplace_back(bytes.begin() + long(at), bytes.begin() + long(at + size));
    at += size;
  }
  return f;
}

void writePcap(const fs::path& path, const PcapFile& f) {
  std::ofstream out(path, std::ios::binary);
  out.write(reinterpret_cast<const char*>(f.header.data()), std::streamsize(f.header.size()));
  for (const auto& r : f.records) out.write(reinterpret_cast<const char*>(r.data()), std::streamsize(r.size()));
}

/// The UDP payload of an unfragmented Ethernet/IPv4/UDP record to `port`, or an empty span.
std::span<std::uint8_t> udpPayloadTo(std::vector<std::uint8_t>& record, std::uint16_t port) {
  constexpr std::size_t eth = 16 + 14;
  if (record.size() < eth + 28 || record[eth - 2] != 0x08 || record[eth - 1] != 0x00) return {};
  const std::size_t ihl = 4u * (record[eth] & 0x0f);
  const bool fragment = ((record[eth + 6] & 0x3f) | record[eth + 7]) != 0;  // MF flag or an offset
  const std::size_t udp = eth + ihl;
  if (fragment || record[eth + 9] != 17 || record.size() < udp + 8) return {};
  if ((record[udp + 2] << 8 | record[udp + 3]) != port) return {};
  return {record.data() + udp + 8, record.size() - udp - 8};
}

enum class Damage { kNone, kLoss, kReorder, kDuplicate, kClockShift, kCorruptRecord, kTruncated };

struct Row {
  const char* name;
  Damage damage;
  double amount;  // loss / duplicate share, reorder window, clock shift in µs, where the capture is cut (share)
  const char* cause;  // when the run is not ok: what its message (stderr) must name; nullptr = anything
  bool warns;         // the damage must show as a warning (stderr, the summary and report.json's warnings)
  /// The calibration lidar's time_offset_ns in the rig (a number or "estimate"); nullptr = the rig as simulated.
  /// Such a row must come out within the accuracy goal, its clock no longer doubted.
  const char* time_offset = nullptr;
};

void PrintTo(const Row& r, std::ostream* os) { *os << r.name; }

PcapFile damaged(const PcapFile& clean, const Row& row);

/// The simulated rig with `time_offset_ns: value` added to `sensor`'s entry, written next to it (its
/// calibration files are found relative to it).
fs::path rigWithTimeOffset(const fs::path& sim, const std::string& sensor, const std::string& value,
                           const std::string& tag) {
  std::string text = fileContents(sim / "rig.yaml");
  const auto entry = text.find("  - name: " + sensor + "\n");
  const auto ts = entry == std::string::npos ? entry : text.find("    time_source: ", entry);
  const auto eol = ts == std::string::npos ? ts : text.find('\n', ts);
  EXPECT_NE(eol, std::string::npos) << "no time_source line for " << sensor << " in the simulated rig";
  if (eol == std::string::npos) return sim / "rig.yaml";
  text.insert(eol + 1, "    time_offset_ns: " + value + "\n");
  const fs::path path = sim / ("rig_time_offset_" + tag + ".yaml");
  std::ofstream(path) << text;
  return path;
}

void writeDamagedCapture(const fs::path& path, const PcapFile& clean, const Row& row) {
  writePcap(path, damaged(clean, row));
  // A capture cut mid-record, as when the recorder was killed or the disk filled.
  if (row.damage == Damage::kTruncated) fs::resize_file(path, std::uintmax_t(double(fs::file_size(path)) * row.amount) + 7);
}

PcapFile damaged(const PcapFile& clean, const Row& row) {
  PcapFile f{clean.header, {}};
  std::mt19937 rng(18);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  switch (row.damage) {
    case Damage::kNone:
    case Damage::kTruncated: return clean;  // cut after writing (writeDamagedCapture)
    case Damage::kCorruptRecord: {
      // A record half-way claims 4 GB: the reader cannot step over it and must say so.
      f.records = clean.records;
      auto& r = f.records[f.records.size() / 2];
      r[8] = r[9] = r[10] = 0xff;
      r[11] = 0x7f;
      return f;
    }
    case Damage::kLoss:
      for (const auto& r : clean.records)
        if (u(rng) >= row.amount) f.records.push_back(r);
      return f;
    case Damage::kDuplicate:
      for (const auto& r : clean.records) {
        f.records.push_back(r);
        if (u(rng) < row.amount) f.records.push_back(r);
      }
      return f;
    case Damage::kReorder: {
      f.records = clean.records;
      const auto window = std::size_t(row.amount);
      for (std::size_t at = 0; at < f.records.size(); at += window)
        std::shuffle(f.records.begin() + long(at), f.records.begin() + long(std::min(at + window, f.records.size())), rng);
      return f;
    }
    case Damage::kClockShift: {
      // The calibration lidar's own clock runs late: its packets' timestamps move, the capture times do not.
      drivers::DecoderConfig vlp16;
      vlp16.model = "VLP-16";
      const drivers::PacketRestamper restamper(vlp16);
      f.records = clean.records;
      std::size_t shifted = 0;
      for (auto& r : f.records) {
        const auto payload = udpPayloadTo(r, 2368);
        if (!payload.empty() && restamper.restamp(payload, std::int64_t(row.amount))) ++shifted;
      }
      EXPECT_GT(shifted, 100u) << "the VLP-16's packets were not found in the capture";
      return f;
    }
  }
  return f;
}

class CalibrateDegraded : public ::testing::TestWithParam<Row> {
 protected:
  static void SetUpTestSuite() {
    if (RIGCAL_SANITIZED) return;
    sim_ = new TempDir;
    // The lost preset's first 16 s (before its mapping-lidar outage ends usable data), as CalibratePresetsShort.
    const std::string text = shortenedPreset("lost",
                                             "    - {type: accelerate, to_kmh: 5, duration: 2.0}\n"
                                             "    - {type: cruise, duration: 14.0}\n",
                                             "    calibration_skip_keyframes: 1\n"
                                             "    dense_pointcloud_num_keyframes: 3\n"
                                             "    calibration_min_distance_between_frames: 1.5\n"
                                             "    lidar_calibration_max_frames: 4\n");
    ASSERT_FALSE(text.empty());
    ASSERT_NO_FATAL_FAILURE(simulateYaml(text, sim_->path()));
  }
  static void TearDownTestSuite() {
    delete sim_;
    sim_ = nullptr;
  }
  static TempDir* sim_;
};

TempDir* CalibrateDegraded::sim_ = nullptr;

TEST_P(CalibrateDegraded, CalibratesWithinTheGoalOrSaysWhyNot) {
  if (RIGCAL_SANITIZED) GTEST_SKIP() << "a simulated drive calibrated seven times: Release only";
  ASSERT_NE(sim_, nullptr);
  const Row row = GetParam();
  // Each row is a calibration of 30-70 s on a loaded 2-core machine: the default suite runs the rows that
  // exercise each detection once (loss, a late clock, a damaged record); the others with RIGCAL_LONG_TESTS=1.
  const std::string name = row.name;
  if (!longTests() && name != "loss_10pct" && name != "clock_plus_50ms" && name != "corrupt_record_half_way" &&
      name != "clock_plus_50ms_estimated")
    GTEST_SKIP() << "long row: set RIGCAL_LONG_TESTS=1 (Release only)";
  TempDir dir;
  const fs::path sim = sim_->path(), capture = dir / "damaged.pcap", out = dir / "out";
  writeDamagedCapture(capture, readPcap(sim / "recording.pcap"), row);
  const fs::path rig =
      row.time_offset == nullptr ? sim / "rig.yaml" : rigWithTimeOffset(sim, "front_left", row.time_offset, row.name);
  const auto calibrated = runRigcal({"calibrate", "--config", rig.string(), "--pcap", capture.string(),
                                     "--out", out.string()});
  const auto compared = compareWithTruth(sim, out, 1.0, 0.05);
  std::printf("[%s] exit %d\n%s%s%s\n", row.name, calibrated.exit_code, calibrated.out.c_str(), calibrated.err.c_str(),
              compared.out.c_str());
  const auto report = readJson(out / "report.json");
  if (row.time_offset != nullptr) {
    // Corrected by the rig: within the goal, and the residual clock offset is small and reported.
    EXPECT_EQ(compared.exit_code, 0) << row.name << ": the corrected clock did not give the accuracy goal\n"
                                     << calibrated.out << calibrated.err << compared.out;
    EXPECT_EQ(calibrated.err.find("clock: "), std::string::npos) << row.name << ": still doubted\n" << calibrated.err;
    EXPECT_NE(calibrated.out.find("front_left: clock "), std::string::npos) << "the summary reports it\n"
                                                                            << calibrated.out;
    const auto& evidence = report["lidars"][0]["evidence"];
    std::printf("[%s] evidence %s\n", row.name, evidence.dump().c_str());
    EXPECT_LT(std::abs(evidence["clock_offset_ms"].get<double>()), 10.0);
    EXPECT_GE(evidence["clock_offset_uncertainty_ms"].get<double>(), 0.0);
    EXPECT_NEAR(evidence["time_offset_applied_ms"].get<double>(), row.amount / 1000.0, 5.0);
  }
  if (calibrated.exit_code == 0) {
    EXPECT_EQ(compared.exit_code, 0) << row.name << ": a wrong result printed as ok\n" << calibrated.out << compared.out;
    EXPECT_EQ(report["status"], "ok");
  } else {
    EXPECT_NE(report["status"], "ok") << row.name;
    EXPECT_FALSE(calibrated.err.empty()) << row.name << ": a failure must say why";
    if (row.cause != nullptr) {
      EXPECT_NE(calibrated.err.find(row.cause), std::string::npos) << row.name << ": the message names the cause\n"
                                                                   << calibrated.err;
    }
  }
  if (row.warns) {
    EXPECT_NE(calibrated.err.find("warning: "), std::string::npos) << row.name << "\n" << calibrated.err;
    EXPECT_NE(calibrated.out.find("warning: "), std::string::npos) << row.name << ": in the summary\n" << calibrated.out;
    EXPECT_FALSE(report["warnings"].empty()) << row.name;
  }
  std::printf("[%s] input %s\n", row.name, report["input"].dump().c_str());
}

INSTANTIATE_TEST_SUITE_P(Table, CalibrateDegraded,
                         ::testing::Values(Row{"clean", Damage::kNone, 0, nullptr, false},
                                           Row{"loss_2pct", Damage::kLoss, 0.02, nullptr, true},
                                           Row{"loss_10pct", Damage::kLoss, 0.10, nullptr, true},
                                           Row{"reorder_16", Damage::kReorder, 16, nullptr, false},
                                           Row{"duplicates_1pct", Damage::kDuplicate, 0.01, nullptr, false},
                                           Row{"clock_plus_50ms", Damage::kClockShift, 50'000, "clock", false},
                                           Row{"clock_plus_1s", Damage::kClockShift, 1'000'000, "clock", false},
                                           Row{"clock_plus_35ms", Damage::kClockShift, 35'000, "clock", false},
                                           Row{"clock_plus_35ms_given", Damage::kClockShift, 35'000, nullptr, false,
                                               "35000000"},
                                           Row{"clock_plus_50ms_given", Damage::kClockShift, 50'000, nullptr, false,
                                               "50000000"},
                                           Row{"clock_plus_1s_given", Damage::kClockShift, 1'000'000, nullptr, false,
                                               "1000000000"},
                                           Row{"clock_plus_50ms_estimated", Damage::kClockShift, 50'000, nullptr,
                                               false, "estimate"},
                                           Row{"clock_plus_1s_estimated", Damage::kClockShift, 1'000'000, nullptr,
                                               false, "estimate"},
                                           Row{"corrupt_record_half_way", Damage::kCorruptRecord, 0, nullptr, true},
                                           Row{"truncated_at_80pct", Damage::kTruncated, 0.8, nullptr, true}),
                         [](const ::testing::TestParamInfo<Row>& row) { return std::string(row.param.name); });

}  // namespace
}  // namespace rigcal::test
