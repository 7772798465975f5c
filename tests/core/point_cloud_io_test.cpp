#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <random>

#include "rigcal/core/lzf.hpp"
#include "rigcal/core/pcd_io.hpp"
#include "rigcal/core/point_cloud_file.hpp"
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

// A binary_compressed PCD whose LZF body is `body` (x as the only F4 field, `points` points).
void writeCompressedPcd(const std::filesystem::path& path, std::size_t points, std::uint32_t uncompressed,
                        const std::vector<std::uint8_t>& body) {
  std::ofstream out(path, std::ios::binary);
  out << "VERSION 0.7\nFIELDS x\nSIZE 4\nTYPE F\nCOUNT 1\nWIDTH " << points << "\nHEIGHT 1\nPOINTS " << points
      << "\nDATA binary_compressed\n";
  const std::uint32_t sizes[2] = {std::uint32_t(body.size()), uncompressed};
  out.write(reinterpret_cast<const char*>(sizes), sizeof sizes);
  out.write(reinterpret_cast<const char*>(body.data()), std::streamsize(body.size()));
}

std::string errorOf(const std::filesystem::path& path) {
  try {
    readPcd(path);
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  return "(no error)";
}

TEST_F(PointCloudIo, CorruptCompressedAndGarbageFilesAreRefusedClearly) {
  std::ofstream(dir / "c.pcd") << "VERSION 0.7\nFIELDS x\nSIZE 4\nTYPE F\nCOUNT 1\nWIDTH 1\nHEIGHT 1\n"
                                  "POINTS 1\nDATA binary_compressed\n";
  std::string msg = errorOf(dir / "c.pcd");
  EXPECT_NE(msg.find("binary_compressed"), std::string::npos) << msg;
  EXPECT_NE(msg.find("c.pcd"), std::string::npos) << msg;

  // Two floats 1.0f: a literal run of 4 bytes then a back-reference of 4 bytes at distance 4.
  const std::vector<std::uint8_t> good = {3, 0x00, 0x00, 0x80, 0x3f, (4 - 2) << 5, 3};
  writeCompressedPcd(dir / "ok.pcd", 2, 8, good);
  EXPECT_EQ(readPcd(dir / "ok.pcd").column("x"), (std::vector<double>{1.0, 1.0}));

  writeCompressedPcd(dir / "far.pcd", 2, 8, {3, 0, 0, 0x80, 0x3f, (4 - 2) << 5, 9});  // reaches before the start
  msg = errorOf(dir / "far.pcd");
  EXPECT_NE(msg.find("far.pcd: binary_compressed: corrupt LZF data at compressed byte 5"), std::string::npos) << msg;
  writeCompressedPcd(dir / "size.pcd", 3, 8, good);  // header's point count disagrees with the sizes
  EXPECT_NE(errorOf(dir / "size.pcd").find("3 points of 4 bytes need 12"), std::string::npos) << errorOf(dir / "size.pcd");
  writeCompressedPcd(dir / "short.pcd", 2, 8, {3, 0, 0, 0x80});  // literal run past the end
  EXPECT_NE(errorOf(dir / "short.pcd").find("past the end"), std::string::npos) << errorOf(dir / "short.pcd");
  writeCompressedPcd(dir / "huge.pcd", 1000000, 4000000, good);  // 7 bytes cannot hold 4 MB: refused before allocating
  EXPECT_NE(errorOf(dir / "huge.pcd").find("cannot expand to 4000000"), std::string::npos) << errorOf(dir / "huge.pcd");
  for (const char* name : {"far.pcd", "size.pcd", "short.pcd", "huge.pcd"})
    EXPECT_EQ(errorOf(dir / name).find('\n'), std::string::npos) << "one line: " << errorOf(dir / name);

  std::ofstream(dir / "g.ply") << "this is not a ply\n";
  EXPECT_THROW(readPly(dir / "g.ply"), std::runtime_error);
  EXPECT_THROW(readPcd(dir / "missing.pcd"), std::runtime_error);
  EXPECT_THROW(readPointCloudFile(dir / "missing.pcd"), std::runtime_error);
  EXPECT_THROW(readPointCloudFile(dir.path()), std::runtime_error);
}

TEST(Lzf, RandomStreamsEitherDecodeToTheExactSizeOrThrow) {
  std::mt19937 rng(11);
  int decoded = 0;
  for (int trial = 0; trial < 2000; ++trial) {
    std::vector<std::uint8_t> in(std::size_t(rng() % 64));
    for (auto& b : in) b = std::uint8_t(rng());
    const std::size_t size = rng() % 128;
    try {
      EXPECT_EQ(lzfDecompress(in, size).size(), size);
      ++decoded;
    } catch (const std::runtime_error& e) {
      EXPECT_NE(std::string(e.what()).find("corrupt LZF data"), std::string::npos);
    }
  }
  RecordProperty("decoded", decoded);
  EXPECT_TRUE(lzfDecompress({}, 0).empty());
}

TEST(Lzf, OverlappingBackReferenceRepeatsARun) {
  // "ab" then a reference of length 6 + 2 = 8 at distance 2: it reads bytes it writes.
  const std::vector<std::uint8_t> in = {1, 'a', 'b', (6 << 5), 1};
  const auto out = lzfDecompress(in, 10);
  EXPECT_EQ(std::string(out.begin(), out.end()), "ababababab");
  const std::vector<std::uint8_t> long_ref = {0, 'z', (7 << 5), 10, 0};  // length 7 + 10 + 2 = 19
  const auto run = lzfDecompress(long_ref, 20);
  EXPECT_EQ(std::string(run.begin(), run.end()), std::string(20, 'z'));
}

TEST_F(PointCloudIo, AsciiPcdWithNanAndPlyMeshWithFacesRead) {
  std::ofstream(dir / "n.pcd") << "VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nWIDTH 2\n"
                                  "HEIGHT 1\nPOINTS 2\nDATA ascii\nnan nan nan\n1 2 3\n";
  const PointTable n = readPcd(dir / "n.pcd");
  ASSERT_EQ(n.size(), 2u);
  EXPECT_TRUE(std::isnan(n.column("x")[0]));
  EXPECT_EQ(n.column("z")[1], 3.0);
  std::ofstream(dir / "bad.pcd") << "VERSION 0.7\nFIELDS x\nSIZE 4\nTYPE F\nCOUNT 1\nWIDTH 1\n"
                                    "HEIGHT 1\nPOINTS 1\nDATA ascii\n1.5abc\n";
  EXPECT_NE(errorOf(dir / "bad.pcd").find("'1.5abc' is not a number at point 0 field x"), std::string::npos)
      << errorOf(dir / "bad.pcd");

  std::ofstream(dir / "mesh.ply") << "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
                                     "property float z\nelement face 1\nproperty list uchar int vertex_indices\n"
                                     "end_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
  const PointTable m = readPointCloudFile(dir / "mesh.ply");  // sniffed as PLY by its first bytes
  ASSERT_EQ(m.size(), 3u);
  EXPECT_EQ(m.column("y")[2], 1.0);
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
