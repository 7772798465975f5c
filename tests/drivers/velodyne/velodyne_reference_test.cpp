// Real captures against their reference decodes (../shared/data/velodyne, see its README).
//
// nebula (the reference for three captures) cuts scans per packet at its scan_phase, then moves the
// trailing points within 2° past the phase to the next scan, and keeps only blocks and points inside
// its cloud_min_angle..cloud_max_angle window. Its test setups: VLP-16 and VLS-128 phase 0°, window
// 0°..359°; VLP-32C phase 180°, window 270°..90°, range 0.4–50 m. We reproduce each window with the
// assembler's cut angle, the decoder's cut granularity and the same angular filter applied here.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <numbers>
#include <optional>

#include "point_match.hpp"
#include "rigcal/core/pcd_io.hpp"
#include "rigcal/drivers/pcap_source.hpp"
#include "rigcal/drivers/scan_assembler.hpp"
#include "rigcal/drivers/velodyne/velodyne_decoder.hpp"
#include "test_data.hpp"

namespace rigcal::drivers {
namespace {


using Cut = VelodyneOptions::Cut;

// nebula's cloud_min_angle..cloud_max_angle (degrees, inclusive, wrapping when min > max), applied to
// the block azimuth and, when `points` is set, to the point's azimuth as well.
struct AngleWindow {
  double min_deg = 0, max_deg = 360;
  bool points = false;
  [[nodiscard]] bool contains(double deg) const {
    constexpr double e = 1e-4;
    return min_deg <= max_deg ? deg >= min_deg - e && deg <= max_deg + e : deg <= max_deg + e || deg >= min_deg - e;
  }
};

double pointAzimuthDeg(const Point& p) {
  const double h = std::fmod(std::atan2(-p.y, p.x) * 18000.0 / std::numbers::pi + 36000.0, 36000.0);
  return std::fmod(std::round(h), 36000.0) / 100.0;
}

struct DecodeRun {
  std::vector<Scan> scans;
  AssemblerStats stats;
  std::size_t max_points_per_scan = 0;
};

// Decodes a capture into scans. With a window, a second decoder (block cut) runs in lockstep to tell
// each point's block azimuth.
DecodeRun decodeCapture(const std::filesystem::path& pcap, const DecoderConfig& config, VelodyneOptions options,
                  double cut_angle_deg, std::optional<AngleWindow> window = std::nullopt) {
  DecodeRun run;
  auto decoder = makeVelodyneDecoder(config, options);
  VelodyneOptions block_options = options;
  block_options.cut = Cut::kBlock;
  auto blocks = makeVelodyneDecoder(config, block_options);
  run.max_points_per_scan = decoder->maxPointsPerScan();
  AssemblerConfig assembler_config;
  assembler_config.cut_angle_deg = cut_angle_deg;
  ScanAssembler assembler("velodyne", assembler_config, [&](Scan&& s) { run.scans.push_back(std::move(s)); });
  PcapSource source(pcap);
  DecodedPacket out, block_out, kept;
  while (auto packet = source.next()) {
    decoder->decode(*packet, out);
    if (!window || out.kind != DecodedPacket::Kind::kData) {
      assembler.add(out);
      continue;
    }
    blocks->decode(*packet, block_out);
    EXPECT_EQ(block_out.points.size(), out.points.size());
    kept = out;
    kept.points.clear();
    kept.azimuth_deg.clear();
    for (std::size_t i = 0; i < out.points.size(); ++i) {
      if (!window->contains(block_out.azimuth_deg[i])) continue;
      if (window->points && !window->contains(pointAzimuthDeg(out.points[i]))) continue;
      kept.points.push_back(out.points[i]);
      kept.azimuth_deg.push_back(out.azimuth_deg[i]);
    }
    assembler.add(kept);
  }
  assembler.flush();
  run.stats = assembler.stats();
  return run;
}

std::vector<test::Xyz> xyz(const Scan& s) {
  std::vector<test::Xyz> out;
  for (std::size_t i = 0; i < s.size(); ++i) out.push_back({s.x[i], s.y[i], s.z[i]});
  return out;
}

std::vector<test::Xyz> readReference(const std::filesystem::path& pcd) {
  const PointTable t = readPcd(pcd);
  std::vector<test::Xyz> out;
  const auto &x = t.column("x"), &y = t.column("y"), &z = t.column("z");
  for (std::size_t i = 0; i < t.size(); ++i) out.push_back({float(x[i]), float(y[i]), float(z[i])});
  return out;
}

struct Match {
  std::size_t scan = 0, scan_points = 0, reference_points = 0, reference_matched = 0, scan_matched = 0;
};

// The scan sharing most points with the reference (judged on every 50th reference point), and how
// many points match both ways within `tolerance`.
Match bestMatch(const std::vector<Scan>& scans, const std::vector<test::Xyz>& reference, double tolerance) {
  std::vector<test::Xyz> sample;
  for (std::size_t i = 0; i < reference.size(); i += 50) sample.push_back(reference[i]);
  Match best;
  best.reference_points = reference.size();
  std::size_t best_sampled = 0;
  for (std::size_t i = 0; i < scans.size(); ++i) {
    const std::size_t sampled = test::countMatched(sample, xyz(scans[i]), tolerance);
    if (i == 0 || sampled > best_sampled) {
      best.scan = i;
      best_sampled = sampled;
    }
  }
  if (scans.empty()) return best;
  const auto points = xyz(scans[best.scan]);
  best.scan_points = points.size();
  best.reference_matched = test::countMatched(reference, points, tolerance);
  best.scan_matched = test::countMatched(points, reference, tolerance);
  return best;
}

void expectMatch(const Match& m, std::size_t scan, double fraction) {
  EXPECT_EQ(m.scan, scan);
  EXPECT_EQ(m.scan_points, m.reference_points);
  EXPECT_GE(double(m.reference_matched), fraction * double(m.reference_points))
      << m.reference_matched << " of " << m.reference_points << " reference points matched";
  EXPECT_GE(double(m.scan_matched), fraction * double(m.scan_points))
      << m.scan_matched << " of " << m.scan_points << " decoded points matched";
  std::printf("[ measured ] scan %zu: %zu points (reference %zu); reference→decoded %zu, decoded→reference %zu\n",
              m.scan, m.scan_points, m.reference_points, m.reference_matched, m.scan_matched);
}

DecoderConfig config(const std::string& model, const std::filesystem::path& calibration, float min_m, float max_m) {
  DecoderConfig c;
  c.model = model;
  c.calibration = calibration;
  c.min_range_m = min_m;
  c.max_range_m = max_m;
  return c;
}

VelodyneOptions nebulaOptions(Cut cut) {
  VelodyneOptions o;
  o.cut = cut;
  o.nebula_azimuth = true;
  return o;
}

TEST(VelodyneReference, Vlp16DualMatchesNebula) {
  RIGCAL_REQUIRE_DATA(dir, "velodyne");
  const auto reference = readReference(dir / "vlp16_dual.reference.pcd");
  ASSERT_EQ(reference.size(), 14831u);
  const DecodeRun run = decodeCapture(dir / "vlp16_dual.pcap", config("VLP-16", dir / "VLP16.calibration.yaml", 0.3f, 300.f),
                                nebulaOptions(Cut::kBlock), 0.0, AngleWindow{0, 359, true});
  EXPECT_EQ(run.stats.malformed, 0u);
  EXPECT_EQ(run.stats.lost_packets, 0u);
  expectMatch(bestMatch(run.scans, reference, 0.001), 3, 0.999);
}

TEST(VelodyneReference, Vlp32cLimitedFovMatchesNebula) {
  RIGCAL_REQUIRE_DATA(dir, "velodyne");
  const auto reference = readReference(dir / "vlp32c_fov270to90.reference.pcd");
  ASSERT_EQ(reference.size(), 26216u);
  // The scan phase (180°) lies in the dead sector; the packet holding the jump from 90° to 270°
  // closes the scan, with its post-jump blocks.
  const DecodeRun run = decodeCapture(dir / "vlp32c_fov270to90.pcap",
                                config("VLP-32C", dir / "VLP32.calibration.yaml", 0.4f, 50.f),
                                nebulaOptions(Cut::kPacket), 180.0, AngleWindow{270, 90, false});
  EXPECT_EQ(run.stats.malformed, 0u);
  EXPECT_EQ(run.stats.lost_packets, 0u) << "the dead sector is not packet loss";
  expectMatch(bestMatch(run.scans, reference, 0.001), 0, 0.999);
}

TEST(VelodyneReference, Vls128MatchesNebula) {
  RIGCAL_REQUIRE_DATA(dir, "velodyne");
  const auto reference = readReference(dir / "vls128_strongest.reference.pcd");
  ASSERT_EQ(reference.size(), 208680u);
  const DecodeRun run = decodeCapture(dir / "vls128_strongest.pcap",
                                config("VLS-128", dir / "VLS128.calibration.yaml", 0.3f, 300.f),
                                nebulaOptions(Cut::kPacket), 0.0, AngleWindow{0, 359, true});
  EXPECT_EQ(run.stats.malformed, 0u);
  EXPECT_EQ(run.stats.lost_packets, 0u);
  expectMatch(bestMatch(run.scans, reference, 0.001), 1, 0.999);
  for (const Scan& s : run.scans) EXPECT_LE(s.size(), run.max_points_per_scan);
}

// Our own azimuth (by firing time) and nebula's differ only in azimuth, by at most about one firing
// sequence's rotation: same points, same order, same range and elevation. The exception is nebula's
// interpolation across the dead-sector jump of a limited field of view (VLP-32C capture), where it
// spreads the last block before the jump over up to 170°: those points are counted apart.
TEST(VelodyneReference, FiringTimeAzimuthStaysWithinOneSequenceOfNebulas) {
  RIGCAL_REQUIRE_DATA(dir, "velodyne");
  struct Case {
    std::string pcap, model, calibration;
    double max_deg;  // one firing sequence at the capture's rotor speed, plus rounding
  };
  for (const Case& c : {Case{"vlp16_dual.pcap", "VLP-16", "VLP16.calibration.yaml", 0.45},
                        Case{"vlp32c_fov270to90.pcap", "VLP-32C", "VLP32.calibration.yaml", 0.25},
                        Case{"vls128_strongest.pcap", "VLS-128", "VLS128.calibration.yaml", 0.2}}) {
    auto ours = makeVelodyneDecoder(config(c.model, dir / c.calibration, 0.3f, 300.f));
    VelodyneOptions nb;
    nb.nebula_azimuth = true;
    auto theirs = makeVelodyneDecoder(config(c.model, dir / c.calibration, 0.3f, 300.f), nb);
    PcapSource source(dir / c.pcap);
    DecodedPacket a, b;
    double worst = 0;
    std::size_t n = 0, beyond = 0;
    while (auto p = source.next()) {
      ours->decode(*p, a);
      theirs->decode(*p, b);
      ASSERT_EQ(a.points.size(), b.points.size());
      for (std::size_t i = 0; i < a.points.size(); ++i) {
        const Point &pa = a.points[i], &pb = b.points[i];
        ASSERT_EQ(pa.ring, pb.ring);
        ASSERT_EQ(pa.time_ns, pb.time_ns);
        EXPECT_NEAR(std::hypot(pa.x, pa.y), std::hypot(pb.x, pb.y), 1e-4);
        EXPECT_NEAR(pa.z, pb.z, 1e-5);
        double d = std::abs(pointAzimuthDeg(pa) - pointAzimuthDeg(pb));
        d = std::min(d, 360 - d);
        if (d > c.max_deg) {
          ++beyond;
        } else {
          worst = std::max(worst, d);
        }
        ++n;
      }
    }
    EXPECT_GT(n, 10000u);
    EXPECT_LE(double(beyond), 0.002 * double(n)) << c.pcap;
    std::printf("[ measured ] %s: %zu points, azimuth within %.3f deg of nebula's but for %zu\n", c.pcap.c_str(), n,
                worst, beyond);
  }
}

TEST(VelodyneReference, Vlp16FramesMatchVeloView) {
  RIGCAL_REQUIRE_DATA(dir, "velodyne");
  // VeloView: a frame ends where a block's azimuth falls below the previous block's (cut at 0°,
  // per block); zero ranges dropped, no range limit.
  const DecodeRun run = decodeCapture(dir / "vlp16_20hz_veloview.pcap", config("VLP-16", dir / "VLP-16.xml", 0.f, 1000.f),
                                VelodyneOptions{}, 0.0);
  ASSERT_EQ(run.scans.size(), 52u);
  EXPECT_EQ(run.scans[0].size(), 5736u);
  EXPECT_EQ(run.scans[2].size(), 13898u);
  EXPECT_EQ(run.scans[16].size(), 13860u);
  EXPECT_EQ(run.scans[51].size(), 274u);
  EXPECT_EQ(run.stats.malformed, 0u);
  EXPECT_EQ(run.stats.ignored, 367u);  // position packets (port 8308)
  EXPECT_EQ(run.stats.lost_packets, 0u);
  // VeloView's axes are the sensor's: x = r·cosω·sin(az), y = r·cosω·cos(az); ours are (y, −x).
  const Scan& f = run.scans[16];
  EXPECT_NEAR(f.x[0], 6.04037, 1e-4);
  EXPECT_NEAR(f.y[0], -0.0801272, 1e-4);
  EXPECT_NEAR(f.z[0], -1.61865, 1e-4);
  EXPECT_EQ(f.intensity[0], 4);
  EXPECT_NEAR(f.x[13859], 4.91462, 1e-4);
  EXPECT_NEAR(f.y[13859], 0.0094354, 1e-4);
  EXPECT_NEAR(f.z[13859], 1.31687, 1e-4);
  EXPECT_EQ(f.intensity[13859], 29);
  // 20 Hz: frames 50 ms apart.
  EXPECT_NEAR(toSeconds(run.scans[17].stamp_ns - run.scans[16].stamp_ns), 0.05, 0.002);
}

TEST(VelodyneReference, Hdl32eDecodesCleanly) {
  RIGCAL_REQUIRE_DATA(dir, "velodyne");
  DecoderConfig c = config("HDL-32E", {}, 0.3f, 300.f);  // nominal table
  auto rate_probe = makeVelodyneDecoder(c);
  const DecodeRun run = decodeCapture(dir / "hdl32e_example.pcap", c, VelodyneOptions{}, 0.0);
  EXPECT_EQ(run.stats.malformed, 0u);
  EXPECT_EQ(run.stats.ignored, 100u);  // position packets
  EXPECT_EQ(run.stats.lost_packets, 0u);
  ASSERT_GE(run.scans.size(), 6u);
  // Full sweeps (not the partial first and last): ~11.7 Hz here, 154 packets of 384 slots, a quarter
  // without return.
  for (std::size_t i = 1; i + 1 < run.scans.size(); ++i) {
    EXPECT_GT(run.scans[i].size(), 40000u);
    EXPECT_LT(run.scans[i].size(), 60000u);
    EXPECT_LE(run.scans[i].size(), run.max_points_per_scan);
    if (i > 1) {
      EXPECT_NEAR(toSeconds(run.scans[i].stamp_ns - run.scans[i - 1].stamp_ns), 0.0853, 0.002);
    }
  }
  PcapSource source(dir / "hdl32e_example.pcap");
  DecodedPacket out;
  while (auto p = source.next()) rate_probe->decode(*p, out);
  EXPECT_NEAR(rate_probe->scanRateHz(), 11.72, 0.05);
}

}  // namespace
}  // namespace rigcal::drivers

namespace rigcal::drivers {
namespace {

// Packets removed from a real capture are reported as lost, and only they.
TEST(VelodyneReference, PacketsRemovedFromACaptureAreCountedAsLost) {
  RIGCAL_REQUIRE_DATA(dir, "velodyne");
  struct Case {
    std::string pcap, model, calibration;
  };
  for (const Case& c : {Case{"vlp16_dual.pcap", "VLP-16", ""}, Case{"vlp32c_fov270to90.pcap", "VLP-32C", ""},
                        Case{"vls128_strongest.pcap", "VLS-128", "VLS128.calibration.yaml"},
                        Case{"hdl32e_example.pcap", "HDL-32E", ""}}) {
    DecoderConfig config;
    config.model = c.model;
    if (!c.calibration.empty()) config.calibration = dir / c.calibration;
    auto decoder = makeVelodyneDecoder(config);
    PcapSource source(dir / c.pcap);
    DecodedPacket out;
    std::uint64_t lost = 0, removed = 0, data = 0;
    while (auto p = source.next()) {
      if (p->payload.size() != 1206) continue;
      ++data;
      if (data > 1 && (data % 97 == 0 || data % 251 == 0 || data % 251 == 1)) {  // singles and pairs
        ++removed;
        continue;
      }
      decoder->decode(*p, out);
      lost += out.lost_before;
    }
    EXPECT_GE(removed, 5u);
    EXPECT_EQ(lost, removed) << c.pcap;
  }
}

}  // namespace
}  // namespace rigcal::drivers
