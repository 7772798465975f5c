#include <gtest/gtest.h>

#include <cmath>
#include <fstream>

#include "rigcal/core/pcd_io.hpp"
#include "rigcal/core/ply_io.hpp"
#include "rigcal/core/point_table.hpp"
#include "test_data.hpp"

namespace rigcal {
namespace {

Scan sampleScan() {
  Scan s;
  s.stamp_ns = 5;
  for (int i = 0; i < 100; ++i)
    s.push_back(Point{0.001f * i, -1.5f + 0.01f * i, 3.14159f, float(i % 256), std::uint16_t(i % 128),
                      s.stamp_ns + 12345 * i, std::uint8_t(i % 2)});
  return s;
}

void expectSameScan(const Scan& a, const Scan& b) {
  ASSERT_EQ(a.size(), b.size());
  EXPECT_EQ(a.x, b.x);
  EXPECT_EQ(a.y, b.y);
  EXPECT_EQ(a.z, b.z);
  EXPECT_EQ(a.intensity, b.intensity);
  EXPECT_EQ(a.ring, b.ring);
  EXPECT_EQ(a.offset_ns, b.offset_ns);
  EXPECT_EQ(a.return_index, b.return_index);
}

class PointCloudIo : public ::testing::Test {
 protected:
  test::TempDir dir;
};

TEST_F(PointCloudIo, PcdBinaryAndAsciiRoundTripExactly) {
  const Scan s = sampleScan();
  writePcd(dir / "b.pcd", toTable(s), PcdEncoding::kBinary);
  writePcd(dir / "a.pcd", toTable(s), PcdEncoding::kAscii);
  expectSameScan(toScan(readPcd(dir / "b.pcd")), s);
  expectSameScan(toScan(readPcd(dir / "a.pcd")), s);
}

TEST_F(PointCloudIo, PlyBinaryAndAsciiRoundTripExactly) {
  const Scan s = sampleScan();
  PointTable t = toTable(s);
  t.add("time", FieldType::kF64, std::vector<double>(s.size(), 1.7e9 + 0.123456789));
  writePly(dir / "b.ply", t, PlyEncoding::kBinaryLittleEndian);
  writePly(dir / "a.ply", t, PlyEncoding::kAscii);
  for (const char* name : {"a.ply", "b.ply"}) {
    const PointTable r = readPly(dir / name);
    expectSameScan(toScan(r), s);
    EXPECT_EQ(r.column("time")[7], 1.7e9 + 0.123456789) << name;
  }
}

TEST_F(PointCloudIo, TruncatedPcdNamesFileAndPoint) {
  writePcd(dir / "t.pcd", toTable(sampleScan()));
  std::filesystem::resize_file(dir / "t.pcd", std::filesystem::file_size(dir / "t.pcd") - 10);
  try {
    readPcd(dir / "t.pcd");
    FAIL() << "expected an error";
  } catch (const std::runtime_error& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("t.pcd"), std::string::npos) << msg;
    EXPECT_NE(msg.find("point 99 of 100"), std::string::npos) << msg;
    EXPECT_EQ(msg.find('\n'), std::string::npos) << "one line: " << msg;
  }
}

TEST_F(PointCloudIo, CompressedAndGarbageFilesAreRefusedClearly) {
  std::ofstream(dir / "c.pcd") << "VERSION 0.7\nFIELDS x\nSIZE 4\nTYPE F\nCOUNT 1\nWIDTH 1\nHEIGHT 1\n"
                                  "POINTS 1\nDATA binary_compressed\n";
  EXPECT_THROW(
      {
        try {
          readPcd(dir / "c.pcd");
        } catch (const std::runtime_error& e) {
          EXPECT_NE(std::string(e.what()).find("binary_compressed"), std::string::npos);
          throw;
        }
      },
      std::runtime_error);
  std::ofstream(dir / "g.ply") << "this is not a ply\n";
  EXPECT_THROW(readPly(dir / "g.ply"), std::runtime_error);
  EXPECT_THROW(readPcd(dir / "missing.pcd"), std::runtime_error);
}

TEST(PointCloudIoReference, ReadsNebulaReferencePcdWithMixedFieldTypes) {
  RIGCAL_REQUIRE_DATA(path, "velodyne/vlp16_dual.reference.pcd");
  const PointTable t = readPcd(path);
  EXPECT_EQ(t.size(), 14831u);
  ASSERT_TRUE(t.has("channel"));
  for (double c : t.column("channel")) ASSERT_LT(c, 16.0);
  // Every reference point lies within the 0.3-300 m range filter.
  const auto &x = t.column("x"), &y = t.column("y"), &z = t.column("z");
  for (std::size_t i = 0; i < t.size(); ++i) {
    const double r = std::sqrt(x[i] * x[i] + y[i] * y[i] + z[i] * z[i]);
    ASSERT_GT(r, 0.29);
    ASSERT_LT(r, 300.0);
  }
}

}  // namespace
}  // namespace rigcal
