// Our PCD reader against files written by PCL 1.13 itself (an independent writer) in every layout:
// ascii, binary and binary_compressed (LZF), with mixed field types, COUNT > 1, an unusual field order
// and organised clouds with NaN points.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <random>

#include <pcl/PCLPointCloud2.h>
#include <pcl/io/pcd_io.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include "rigcal/core/pcd_io.hpp"
#include "rigcal/core/point_cloud_file.hpp"
#include "test_data.hpp"

namespace rigcal {
namespace {

enum class Layout { kAscii, kBinary, kCompressed };

void writeWithPcl(const std::filesystem::path& path, const pcl::PCLPointCloud2& cloud, Layout layout) {
  pcl::PCDWriter w;
  int rc = 0;
  if (layout == Layout::kAscii) rc = w.writeASCII(path.string(), cloud, Eigen::Vector4f::Zero(),
                                                   Eigen::Quaternionf::Identity(), 9);
  if (layout == Layout::kBinary) rc = w.writeBinary(path.string(), cloud);
  if (layout == Layout::kCompressed) rc = w.writeBinaryCompressed(path.string(), cloud);
  ASSERT_EQ(rc, 0) << path;
}

struct FieldSpec {
  const char* name;
  std::uint8_t datatype;  // pcl::PCLPointField::PointFieldTypes
  int size;
  int count;
};

// Mixed types in an order no point type of ours uses; x, y, z in the middle.
const std::vector<FieldSpec> kFields = {
    {"intensity", pcl::PCLPointField::FLOAT64, 8, 1}, {"ring", pcl::PCLPointField::UINT16, 2, 1},
    {"x", pcl::PCLPointField::FLOAT32, 4, 1},         {"flag", pcl::PCLPointField::UINT8, 1, 1},
    {"y", pcl::PCLPointField::FLOAT32, 4, 1},         {"t", pcl::PCLPointField::INT32, 4, 1},
    {"z", pcl::PCLPointField::FLOAT32, 4, 1},         {"hist", pcl::PCLPointField::FLOAT32, 4, 3},
    {"i1", pcl::PCLPointField::INT8, 1, 1},           {"i2", pcl::PCLPointField::INT16, 2, 1},
    {"u4", pcl::PCLPointField::UINT32, 4, 1},
};

// The value of field f, element k, at point i: repetitive in places so LZF finds back-references.
double valueOf(std::size_t f, int k, std::size_t i, std::mt19937& rng) {
  const std::string name = kFields[f].name;
  if (name == "x") return float(0.01 * double(i % 200) + 0.5);
  if (name == "y") return float(std::uniform_real_distribution<double>(-50, 50)(rng));
  if (name == "z") return float(-1.7);
  if (name == "intensity") return 0.1 * double(i);
  if (name == "ring") return double(i % 128);
  if (name == "flag") return double(i % 3 == 0 ? 255 : 0);
  if (name == "t") return -100000.0 + 37.0 * double(i);
  if (name == "hist") return float(k + 0.25 * double(i % 5));
  if (name == "i1") return double(int(i % 256) - 128);
  if (name == "i2") return -30000.0 + double(i);
  return 4000000000.0 - double(i);  // u4
}

template <class T>
void put(std::uint8_t* p, double v) {
  const T t = static_cast<T>(v);
  std::memcpy(p, &t, sizeof t);
}

void putValue(std::uint8_t* p, std::uint8_t type, double v) {
  switch (type) {
    case pcl::PCLPointField::INT8: return put<std::int8_t>(p, v);
    case pcl::PCLPointField::UINT8: return put<std::uint8_t>(p, v);
    case pcl::PCLPointField::INT16: return put<std::int16_t>(p, v);
    case pcl::PCLPointField::UINT16: return put<std::uint16_t>(p, v);
    case pcl::PCLPointField::INT32: return put<std::int32_t>(p, v);
    case pcl::PCLPointField::UINT32: return put<std::uint32_t>(p, v);
    case pcl::PCLPointField::FLOAT32: return put<float>(p, v);
    default: return put<double>(p, v);
  }
}

// The cloud and, per column as we name them (hist_0..hist_2), the values written.
pcl::PCLPointCloud2 mixedCloud(std::size_t n, std::vector<std::pair<std::string, std::vector<double>>>& expected) {
  pcl::PCLPointCloud2 c;
  std::uint32_t offset = 0;
  for (const auto& f : kFields) {
    pcl::PCLPointField pf;
    pf.name = f.name;
    pf.offset = offset;
    pf.datatype = f.datatype;
    pf.count = std::uint32_t(f.count);
    c.fields.push_back(pf);
    offset += std::uint32_t(f.size * f.count);
    for (int k = 0; k < f.count; ++k)
      expected.emplace_back(f.count == 1 ? f.name : std::string(f.name) + "_" + std::to_string(k), std::vector<double>{});
  }
  c.point_step = offset;
  c.width = std::uint32_t(n);
  c.height = 1;
  c.row_step = c.point_step * c.width;
  c.is_dense = true;
  c.data.resize(std::size_t(c.row_step));
  std::mt19937 rng(7);
  for (std::size_t i = 0; i < n; ++i) {
    std::size_t column = 0;
    for (std::size_t f = 0; f < kFields.size(); ++f)
      for (int k = 0; k < kFields[f].count; ++k, ++column) {
        const double v = valueOf(f, k, i, rng);
        putValue(c.data.data() + i * c.point_step + c.fields[f].offset + std::size_t(k * kFields[f].size),
                 kFields[f].datatype, v);
        expected[column].second.push_back(v);
      }
  }
  return c;
}

class PcdLayouts : public ::testing::TestWithParam<Layout> {
 protected:
  test::TempDir dir;
};

TEST_P(PcdLayouts, ReadsPclsFileWithMixedTypesCountAndFieldOrderExactly) {
  std::vector<std::pair<std::string, std::vector<double>>> expected;
  const auto cloud = mixedCloud(3000, expected);
  writeWithPcl(dir / "m.pcd", cloud, GetParam());
  const PointTable t = readPcd(dir / "m.pcd");
  ASSERT_EQ(t.size(), 3000u);
  ASSERT_EQ(t.fields().size(), expected.size());
  for (std::size_t c = 0; c < expected.size(); ++c) {
    EXPECT_EQ(t.fields()[c].name, expected[c].first);
    const auto& got = t.column(expected[c].first);
    // Exact, but PCL writes ascii doubles with the precision it is given (9 digits here).
    const double tolerance = GetParam() == Layout::kAscii ? 1e-8 : 0.0;
    for (std::size_t i = 0; i < got.size(); ++i)
      ASSERT_LE(std::abs(got[i] - expected[c].second[i]), tolerance * std::max(1.0, std::abs(got[i])))
          << expected[c].first << " point " << i;
  }
  // The format is told by content, not name: the same file read through the generic entry point.
  EXPECT_EQ(readPointCloudFile(dir / "m.pcd").column("u4"), t.column("u4"));
}

TEST_P(PcdLayouts, ReadsPclsOrganisedCloudWithNanPoints) {
  pcl::PointCloud<pcl::PointXYZI> c(40, 16);
  for (std::size_t i = 0; i < c.size(); ++i) {
    auto& p = c[i];
    const bool invalid = i % 7 == 3;
    const float nan = std::numeric_limits<float>::quiet_NaN();
    p.x = invalid ? nan : 0.5f * float(i % 40);
    p.y = invalid ? nan : 0.25f * float(i / 40);
    p.z = invalid ? nan : 1.0f;
    p.intensity = float(i % 100);
  }
  c.is_dense = false;
  pcl::PCLPointCloud2 c2;
  pcl::toPCLPointCloud2(c, c2);
  writeWithPcl(dir / "o.pcd", c2, GetParam());
  const PointTable t = readPcd(dir / "o.pcd");
  ASSERT_EQ(t.size(), c.size());
  for (std::size_t i = 0; i < c.size(); ++i) {
    if (i % 7 == 3) {
      ASSERT_TRUE(std::isnan(t.column("x")[i])) << i;
    } else {
      ASSERT_EQ(t.column("x")[i], c[i].x) << i;
      ASSERT_EQ(t.column("y")[i], c[i].y) << i;
    }
    ASSERT_EQ(t.column("intensity")[i], c[i].intensity) << i;
  }
}

INSTANTIATE_TEST_SUITE_P(AllLayouts, PcdLayouts,
                         ::testing::Values(Layout::kAscii, Layout::kBinary, Layout::kCompressed),
                         [](const auto& p) {
                           return std::string(p.param == Layout::kAscii    ? "Ascii"
                                              : p.param == Layout::kBinary ? "Binary"
                                                                              : "BinaryCompressed");
                         });

TEST(PcdCompressed, PclsSaveBinaryCompressedOfAPointTypeReadsBack) {
  test::TempDir dir;
  pcl::PointCloud<pcl::PointXYZI> c;
  std::mt19937 rng(3);
  std::normal_distribution<float> noise(0.0f, 5.0f);
  for (int i = 0; i < 20000; ++i) c.push_back(pcl::PointXYZI(noise(rng), noise(rng), float(i % 10), float(i % 7)));
  ASSERT_EQ(pcl::io::savePCDFileBinaryCompressed((dir / "c.pcd").string(), c), 0);
  const PointTable t = readPcd(dir / "c.pcd");
  ASSERT_EQ(t.size(), c.size());
  for (std::size_t i = 0; i < c.size(); ++i) {
    ASSERT_EQ(t.column("x")[i], c[i].x);
    ASSERT_EQ(t.column("z")[i], c[i].z);
    ASSERT_EQ(t.column("intensity")[i], c[i].intensity);
  }
}

}  // namespace
}  // namespace rigcal
