// sensor_msgs/PointCloud2 and tf2_msgs/TFMessage from CDR. A real decoded sweep (PandarXT32 capture) is
// written in the field layouts of the common drivers (ouster t, nebula time_stamp, velodyne time,
// hesai/robosense absolute timestamp, livox offset_time; organised and unorganised, padded rows, NaN
// points) and must read back point for point with its per-point times.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>

#include "cdr_test_writer.hpp"
#include "bag_error_of.hpp"
#include "rigcal/bag/bag_error.hpp"
#include "rigcal/bag/point_cloud2_message.hpp"
#include "rigcal/bag/tf_message.hpp"
#include "rigcal/drivers/packet_decoder.hpp"
#include "rigcal/drivers/pcap_source.hpp"
#include "rigcal/drivers/scan_assembler.hpp"
#include "rigcal/drivers/scan_pump.hpp"
#include "test_data.hpp"

namespace rigcal::bag {
namespace {

using test::bagErrorOf;

using test::CdrWriter;

enum Datatype : std::uint8_t { kUint8 = 2, kUint16 = 4, kUint32 = 6, kFloat32 = 7, kFloat64 = 8 };

struct FieldSpec {
  std::string name;
  std::uint8_t datatype;
  std::function<void(std::uint8_t*, const Point&, TimeNs stamp)> write;
};

template <class T>
void store(std::uint8_t* p, T v) { std::memcpy(p, &v, sizeof v); }

std::size_t sizeOf(std::uint8_t datatype) {
  return datatype == kUint8 ? 1 : datatype == kUint16 ? 2 : datatype == kFloat64 ? 8 : 4;
}

FieldSpec xyz(const char* axis, int i) {
  return {axis, kFloat32, [i](std::uint8_t* p, const Point& q, TimeNs) { store(p, i == 0 ? q.x : i == 1 ? q.y : q.z); }};
}
const FieldSpec kIntensityF32{"intensity", kFloat32, [](std::uint8_t* p, const Point& q, TimeNs) { store(p, q.intensity); }};
const FieldSpec kIntensityU8{"intensity", kUint8, [](std::uint8_t* p, const Point& q, TimeNs) { store(p, std::uint8_t(q.intensity)); }};
const FieldSpec kRingU16{"ring", kUint16, [](std::uint8_t* p, const Point& q, TimeNs) { store(p, q.ring); }};
const FieldSpec kChannelU16{"channel", kUint16, [](std::uint8_t* p, const Point& q, TimeNs) { store(p, q.ring); }};

struct Layout {
  const char* name;
  std::vector<FieldSpec> fields;
  TimeNs time_tolerance_ns;
};

// Writes `points` (and `nan_every`-th point as NaN) as a PointCloud2 of `height` rows, rows padded by 8 bytes.
std::vector<std::uint8_t> writeCloud(const Layout& layout, const std::vector<Point>& points, TimeNs stamp,
                                     std::uint32_t height, std::size_t nan_every, std::size_t* nans) {
  std::uint32_t point_step = 0;
  std::vector<std::uint32_t> offsets;
  for (const auto& f : layout.fields) {
    const auto size = std::uint32_t(sizeOf(f.datatype));
    point_step = (point_step + size - 1) / size * size;
    offsets.push_back(point_step);
    point_step += size;
  }
  point_step = (point_step + 7) / 8 * 8;
  std::vector<Point> cells;
  *nans = 0;
  for (std::size_t i = 0; i < points.size(); ++i) {
    if (nan_every && i % nan_every == 0) {
      Point nan = points[i];
      nan.x = std::nanf("");
      cells.push_back(nan);
      ++*nans;
    }
    cells.push_back(points[i]);
  }
  const std::uint32_t width = std::uint32_t((cells.size() + height - 1) / height);
  while (cells.size() < std::size_t(width) * height) {
    Point nan;
    nan.y = std::nanf("");
    cells.push_back(nan);
    ++*nans;
  }
  const std::uint32_t row_step = width * point_step + 8;
  std::vector<std::uint8_t> data(std::size_t(row_step) * height, 0xEE);
  for (std::size_t i = 0; i < cells.size(); ++i) {
    std::uint8_t* p = data.data() + (i / width) * row_step + (i % width) * point_step;
    for (std::size_t f = 0; f < layout.fields.size(); ++f) layout.fields[f].write(p + offsets[f], cells[i], stamp);
  }
  CdrWriter w;
  w.putHeader(stamp, "lidar_top").put(height).put(width).put(std::uint32_t(layout.fields.size()));
  for (std::size_t f = 0; f < layout.fields.size(); ++f)
    w.putString(layout.fields[f].name).put(offsets[f]).put(layout.fields[f].datatype).put(std::uint32_t(1));
  w.put(std::uint8_t(0)).put(point_step).put(row_step).put(std::uint32_t(data.size())).putBytes(data).put(std::uint8_t(1));
  return w.bytes();
}

std::vector<Point> realSweep() {
  const std::filesystem::path dir = rigcal::test::dataDir() / "hesai";
  drivers::DecoderConfig config;
  config.model = "PandarXT32";
  config.calibration = dir / "PandarXT32.csv";
  auto decoder = drivers::makeDecoder(config);
  drivers::PcapSource source(dir / "xt32_dual.pcap");
  std::vector<Scan> scans;
  drivers::ScanAssembler assembler("xt32", {}, [&](Scan&& s) { scans.push_back(std::move(s)); });
  drivers::pumpScans(source, *decoder, assembler);
  std::vector<Point> out;
  if (scans.size() < 2) return out;
  for (std::size_t i = 0; i < scans[1].size(); ++i) out.push_back(scans[1].point(i));
  return out;
}

std::vector<Layout> driverLayouts() {
  auto relNs = [](const char* name) {
    return FieldSpec{name, kUint32, [](std::uint8_t* p, const Point& q, TimeNs s) { store(p, std::uint32_t(q.time_ns - s)); }};
  };
  const FieldSpec time_f32{"time", kFloat32,
                           [](std::uint8_t* p, const Point& q, TimeNs s) { store(p, float(toSeconds(q.time_ns - s))); }};
  const FieldSpec timestamp_f64{"timestamp", kFloat64,
                                [](std::uint8_t* p, const Point& q, TimeNs) { store(p, toSeconds(q.time_ns)); }};
  return {
      {"ouster t", {xyz("x", 0), xyz("y", 1), xyz("z", 2), kIntensityF32, relNs("t"), kRingU16}, 0},
      {"nebula time_stamp", {xyz("x", 0), xyz("y", 1), xyz("z", 2), kIntensityU8, kChannelU16, relNs("time_stamp")}, 0},
      {"velodyne time", {xyz("x", 0), xyz("y", 1), xyz("z", 2), kIntensityF32, kRingU16, time_f32}, 100},
      {"hesai timestamp", {xyz("x", 0), xyz("y", 1), xyz("z", 2), kIntensityF32, kRingU16, timestamp_f64}, 500},
      {"livox offset_time", {relNs("offset_time"), xyz("x", 0), xyz("y", 1), xyz("z", 2), kIntensityF32}, 0},
  };
}

TEST(PointCloud2Message, DriverLayoutsReadBackPointForPointWithTimes) {
  RIGCAL_REQUIRE_DATA(dir, "hesai/xt32_dual.pcap");
  std::vector<Point> sweep = realSweep();
  ASSERT_GT(sweep.size(), 10000u);
  for (Point& p : sweep) p.intensity = std::round(p.intensity);  // fits the u8 layout too
  TimeNs first = sweep.front().time_ns;
  for (const Point& p : sweep) first = std::min(first, p.time_ns);
  const TimeNs stamp = first - 1000;  // drivers stamp at or before the earliest point
  for (const Layout& layout : driverLayouts()) {
    for (const std::uint32_t height : {1u, 32u}) {
      SCOPED_TRACE(std::string(layout.name) + (height > 1 ? " organised" : " unorganised"));
      std::size_t nans = 0;
      const auto message = writeCloud(layout, sweep, stamp, height, 97, &nans);
      const DecodedCloud cloud = decodePointCloud2(message, "cloud");
      EXPECT_EQ(cloud.frame_id, "lidar_top");
      EXPECT_EQ(cloud.header_stamp_ns, stamp);
      EXPECT_EQ(cloud.dropped_nan, nans);
      ASSERT_EQ(cloud.scan.size(), sweep.size());
      const bool has_ring = std::string(layout.name) != "livox offset_time";
      for (std::size_t i = 0; i < sweep.size(); ++i) {
        const Point got = cloud.scan.point(i);
        ASSERT_EQ(got.x, sweep[i].x) << i;
        ASSERT_EQ(got.y, sweep[i].y) << i;
        ASSERT_EQ(got.z, sweep[i].z) << i;
        ASSERT_EQ(got.intensity, sweep[i].intensity) << i;
        if (has_ring) {
          ASSERT_EQ(got.ring, sweep[i].ring) << i;
        }
        ASSERT_LE(std::abs(got.time_ns - sweep[i].time_ns), layout.time_tolerance_ns) << i;
      }
    }
  }
}

TEST(PointCloud2Message, WithoutATimeFieldEveryPointIsAtTheStamp) {
  const Layout plain{"xyz", {xyz("x", 0), xyz("y", 1), xyz("z", 2)}, 0};
  std::vector<Point> points(3);
  points[1].x = 1.5f;
  points[2].z = -2.f;
  std::size_t nans = 0;
  const auto cloud = decodePointCloud2(writeCloud(plain, points, 42 * kNsPerSec, 1, 0, &nans), "plain");
  ASSERT_EQ(cloud.scan.size(), 3u);
  EXPECT_TRUE(cloud.time_field.empty());
  EXPECT_EQ(cloud.scan.stamp_ns, 42 * kNsPerSec);
  EXPECT_EQ(cloud.scan.x[1], 1.5f);
  EXPECT_EQ(cloud.scan.z[2], -2.f);
  for (auto o : cloud.scan.offset_ns) EXPECT_EQ(o, 0u);
}

TEST(PointCloud2Message, MessagesShorterThanTheirLayoutAreOneLineErrors) {
  const Layout layout{"xyzi", {xyz("x", 0), xyz("y", 1), xyz("z", 2), kIntensityF32}, 0};
  std::vector<Point> points(50);
  std::size_t nans = 0;
  const auto message = writeCloud(layout, points, 0, 5, 0, &nans);
  for (std::size_t cut = 0; cut < message.size() - 1; cut += 7) {  // the trailing is_dense is optional to us
    const std::span<const std::uint8_t> part(message.data(), cut);
    const std::string e = bagErrorOf([&] { decodePointCloud2(part, "/points at 12"); });
    EXPECT_EQ(e.rfind("/points at 12: ", 0), 0u) << e;
  }
  // A consistent message whose data is shorter than height x row_step.
  CdrWriter w;
  w.putHeader(0, "f").put(2u).put(2u).put(3u);
  for (const char* axis : {"x", "y", "z"}) w.putString(axis).put(std::uint32_t(axis[0] - 'x') * 4).put(std::uint8_t(kFloat32)).put(1u);
  w.put(std::uint8_t(0)).put(12u).put(24u).put(40u).putBytes(std::vector<std::uint8_t>(40)).put(std::uint8_t(1));
  const std::string e = bagErrorOf([&] { decodePointCloud2(w.bytes(), "short"); });
  EXPECT_NE(e.find("short: message shorter than its layout: data holds 40 bytes, height 2 x row_step 24 needs 48"),
            std::string::npos) << e;
}

TEST(TfMessage, TransformsReadBackWithFramesAndPose) {
  CdrWriter w;
  w.put(2u);
  w.putHeader(5 * kNsPerSec + 7, "base_link").putString("lidar_top");
  for (double v : {1.0, -2.0, 0.5}) w.put(v);
  const Eigen::Quaterniond q(Eigen::AngleAxisd(0.3, Eigen::Vector3d(0.2, 0.1, 1).normalized()));
  for (double v : {q.x(), q.y(), q.z(), q.w()}) w.put(v);
  w.putHeader(5 * kNsPerSec, "lidar_top").putString("lidar_left");
  for (double v : {0.0, 0.25, 0.0, 0.0, 0.0, 0.0, 1.0}) w.put(v);
  const auto transforms = decodeTfMessage(w.bytes(), "/tf_static");
  ASSERT_EQ(transforms.size(), 2u);
  EXPECT_EQ(transforms[0].parent_frame, "base_link");
  EXPECT_EQ(transforms[0].child_frame, "lidar_top");
  EXPECT_EQ(transforms[0].stamp_ns, 5 * kNsPerSec + 7);
  EXPECT_TRUE(transforms[0].T_parent_child.translation().isApprox(Eigen::Vector3d(1, -2, 0.5)));
  EXPECT_TRUE(Eigen::Quaterniond(transforms[0].T_parent_child.linear()).isApprox(q, 1e-12));
  EXPECT_EQ(transforms[1].child_frame, "lidar_left");
  EXPECT_TRUE(transforms[1].T_parent_child.translation().isApprox(Eigen::Vector3d(0, 0.25, 0)));
  const auto part = std::span<const std::uint8_t>(w.bytes()).first(w.bytes().size() - 8);
  const std::string e = bagErrorOf([&] { decodeTfMessage(part, "/tf_static"); });
  EXPECT_NE(e.find("/tf_static: message shorter than its layout: field transforms[].transform.rotation"),
            std::string::npos) << e;
}

}  // namespace
}  // namespace rigcal::bag
