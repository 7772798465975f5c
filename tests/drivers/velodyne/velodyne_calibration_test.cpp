#include <gtest/gtest.h>

#include <fstream>
#include <numbers>

#include "rigcal/drivers/velodyne/velodyne_calibration.hpp"
#include "rigcal/drivers/velodyne/velodyne_decoder.hpp"
#include "test_data.hpp"

namespace rigcal::drivers::velodyne {
namespace {

using rigcal::test::fileContents;

std::filesystem::path writeText(const test::TempDir& dir, const std::string& name, const std::string& text) {
  const auto path = dir / name;
  std::ofstream(path, std::ios::binary) << text;
  return path;
}

// The message of loadCalibration's exception, checked to be one line naming the file and field.
std::string loadError(const std::filesystem::path& file, Model model) {
  try {
    loadCalibration(file, model);
  } catch (const std::runtime_error& e) {
    const std::string what = e.what();
    EXPECT_EQ(what.find('\n'), std::string::npos) << what;
    EXPECT_NE(what.find(file.string()), std::string::npos) << what;
    return what;
  }
  ADD_FAILURE() << file << " was accepted";
  return {};
}

// `text` with the first occurrence of `from` replaced by `to` (the text must contain it).
std::string replaceFirst(std::string text, const std::string& from, const std::string& to) {
  const auto at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  if (at != std::string::npos) text.replace(at, from.size(), to);
  return text;
}

void expectSame(const Calibration& a, const Calibration& b, double tolerance) {
  ASSERT_EQ(a.lasers.size(), b.lasers.size());
  for (std::size_t i = 0; i < a.lasers.size(); ++i) {
    EXPECT_NEAR(a.lasers[i].vert_correction_rad, b.lasers[i].vert_correction_rad, tolerance) << i;
    EXPECT_NEAR(a.lasers[i].rot_correction_rad, b.lasers[i].rot_correction_rad, tolerance) << i;
    EXPECT_NEAR(a.lasers[i].dist_correction_m, b.lasers[i].dist_correction_m, tolerance) << i;
  }
}

TEST(VelodyneCalibration, ReadsTheSampleYamlFiles) {
  RIGCAL_REQUIRE_DATA(dir, "velodyne");
  const Calibration vlp16 = loadCalibration(dir / "VLP16.calibration.yaml", Model::kVlp16);
  ASSERT_EQ(vlp16.lasers.size(), 16u);
  EXPECT_NEAR(vlp16.lasers[0].vert_correction_rad, -15 * std::numbers::pi / 180, 1e-12);
  EXPECT_NEAR(vlp16.lasers[15].vert_correction_rad, 15 * std::numbers::pi / 180, 1e-12);
  const Calibration vlp32 = loadCalibration(dir / "VLP32.calibration.yaml", Model::kVlp32c);
  ASSERT_EQ(vlp32.lasers.size(), 32u);
  EXPECT_NEAR(vlp32.lasers[0].rot_correction_rad, -0.024434609527920613, 1e-15);
  EXPECT_EQ(loadCalibration(dir / "HDL32.calibration.yaml", Model::kHdl32e).lasers.size(), 32u);
  EXPECT_EQ(loadCalibration(dir / "VLS128.calibration.yaml", Model::kVls128).lasers.size(), 128u);
}

TEST(VelodyneCalibration, VeloViewXmlAgreesWithTheYaml) {
  RIGCAL_REQUIRE_DATA(dir, "velodyne");
  // VeloView stores degrees and centimetres; the 64-slot table has only the sensor's lasers enabled.
  expectSame(loadCalibration(dir / "VLP-16.xml", Model::kVlp16),
             loadCalibration(dir / "VLP16.calibration.yaml", Model::kVlp16), 1e-6);
  expectSame(loadCalibration(dir / "HDL-32.xml", Model::kHdl32e),
             loadCalibration(dir / "HDL32.calibration.yaml", Model::kHdl32e), 1e-6);
}

TEST(VelodyneCalibration, NominalTablesMatchTheVendorFiles) {
  RIGCAL_REQUIRE_DATA(dir, "velodyne");
  // Degrees given to three decimals in the manuals: 0.0005° ≈ 1e-5 rad.
  expectSame(*nominalCalibration(Model::kVlp16), loadCalibration(dir / "VLP16.calibration.yaml", Model::kVlp16), 1e-5);
  expectSame(*nominalCalibration(Model::kVlp32c), loadCalibration(dir / "VLP32.calibration.yaml", Model::kVlp32c), 1e-5);
  expectSame(*nominalCalibration(Model::kHdl32e), loadCalibration(dir / "HDL32.calibration.yaml", Model::kHdl32e), 1e-5);
  EXPECT_FALSE(nominalCalibration(Model::kVls128));
}

TEST(VelodyneCalibration, Vls128WithoutAFileIsRefusedClearly) {
  DecoderConfig config;
  config.model = "VLS-128";
  try {
    makeVelodyneDecoder(config);
    FAIL() << "accepted";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("VLS-128"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("calibration"), std::string::npos) << e.what();
  }
  config.model = "VLP-16";
  EXPECT_NO_THROW(makeVelodyneDecoder(config));  // nominal table
}

TEST(VelodyneCalibration, UnknownModelIsNamed) {
  DecoderConfig config;
  config.model = "HDL-64E";
  try {
    makeVelodyneDecoder(config);
    FAIL() << "accepted";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("HDL-64E"), std::string::npos) << e.what();
  }
}

TEST(VelodyneCalibration, MalformedYamlIsRejectedNamingFileAndField) {
  RIGCAL_REQUIRE_DATA(dir, "velodyne");
  const test::TempDir tmp;
  const std::string good = fileContents(dir / "VLP16.calibration.yaml");

  // A laser without its elevation.
  std::string missing = good;
  {
    const std::string key = "vert_correction: 0.05235987755982989,";  // laser 3 (3°)
    const auto at = missing.find(key);
    ASSERT_NE(at, std::string::npos);
    missing.erase(at, key.size());
  }
  EXPECT_NE(loadError(writeText(tmp, "missing.yaml", missing), Model::kVlp16).find("lasers[3].vert_correction: missing"),
            std::string::npos);

  // The VLP-16 table for a 32-laser sensor.
  EXPECT_NE(loadError(dir / "VLP16.calibration.yaml", Model::kVlp32c).find("lasers: 16 entries, VLP-32C has 32 lasers"),
            std::string::npos);

  // Not YAML at all / not a calibration / broken syntax / empty.
  EXPECT_NE(loadError(writeText(tmp, "garbage.yaml", std::string("\x01\x02\xff\xfe garbage: [", 16)), Model::kVlp16)
                .find("YAML"),
            std::string::npos);
  EXPECT_NE(loadError(writeText(tmp, "other.yaml", "sensors:\n  - a\n"), Model::kVlp16).find("lasers: missing"),
            std::string::npos);
  EXPECT_NE(loadError(writeText(tmp, "broken.yaml", "lasers:\n  - {laser_id: 0, rot_correction: 0\n"), Model::kVlp16)
                .find("YAML"),
            std::string::npos);
  EXPECT_NE(loadError(writeText(tmp, "empty.yaml", ""), Model::kVlp16).find("lasers"), std::string::npos);

  // A value that is not a number, a duplicate id, degrees in a radians file, a wrong num_lasers.
  std::string text = replaceFirst(good, "rot_correction: 0.0,", "rot_correction: abc,");
  EXPECT_NE(loadError(writeText(tmp, "nan.yaml", text), Model::kVlp16).find("lasers[0].rot_correction: not a number"),
            std::string::npos);
  text = replaceFirst(good, "laser_id: 5,", "laser_id: 4,");
  EXPECT_NE(loadError(writeText(tmp, "dup.yaml", text), Model::kVlp16).find("laser_id: duplicate id 4"),
            std::string::npos);
  text = replaceFirst(good, "vert_correction: -0.2617993877991494,", "vert_correction: -15,");
  EXPECT_NE(loadError(writeText(tmp, "degrees.yaml", text), Model::kVlp16).find("lasers[0].vert_correction"),
            std::string::npos);
  text = replaceFirst(good, "num_lasers: 16", "num_lasers: 32");
  EXPECT_NE(loadError(writeText(tmp, "count.yaml", text), Model::kVlp16).find("num_lasers: 32 lasers, VLP-16 has 16"),
            std::string::npos);
  // A file that does not exist.
  EXPECT_NE(loadError(tmp / "absent.yaml", Model::kVlp16).find("cannot be opened"), std::string::npos);
}

TEST(VelodyneCalibration, MalformedXmlIsRejectedNamingFileAndField) {
  RIGCAL_REQUIRE_DATA(dir, "velodyne");
  const test::TempDir tmp;
  const std::string good = fileContents(dir / "VLP-16.xml");

  // One laser entry without its elevation.
  std::string missing = good;
  {
    const auto px = missing.find("<id_>5</id_>");
    ASSERT_NE(px, std::string::npos);
    const auto open = missing.find("<vertCorrection_>", px);
    const auto close = missing.find("</vertCorrection_>", open);
    missing.erase(open, close + std::string("</vertCorrection_>").size() - open);
  }
  EXPECT_NE(loadError(writeText(tmp, "missing.xml", missing), Model::kVlp16).find("points_[5].vertCorrection_: missing"),
            std::string::npos);

  // The VLP-16 table (16 enabled lasers) for an HDL-32E.
  EXPECT_NE(loadError(dir / "VLP-16.xml", Model::kHdl32e).find("enabled_: 16 lasers enabled, HDL-32E has 32 lasers"),
            std::string::npos);

  // Truncated, garbage, not a VeloView file, a value that is not a number.
  EXPECT_NE(loadError(writeText(tmp, "cut.xml", good.substr(0, good.size() / 2)), Model::kVlp16).find("XML:"),
            std::string::npos);
  EXPECT_NE(loadError(writeText(tmp, "garbage.xml", "<<<>>>\x01\x02"), Model::kVlp16).find("XML:"), std::string::npos);
  EXPECT_NE(loadError(writeText(tmp, "other.xml", "<?xml version=\"1.0\"?><root><a>1</a></root>"), Model::kVlp16)
                .find("DB: missing"),
            std::string::npos);
  const std::string nan =
      replaceFirst(good, "<rotCorrection_>0</rotCorrection_>", "<rotCorrection_>zero</rotCorrection_>");
  EXPECT_NE(loadError(writeText(tmp, "nan.xml", nan), Model::kVlp16).find("points_[0].rotCorrection_: not a number"),
            std::string::npos);
}

TEST(VelodyneCalibration, FactoryReportsTheBadFile) {
  RIGCAL_REQUIRE_DATA(dir, "velodyne");
  DecoderConfig config;
  config.model = "VLP-32C";
  config.calibration = dir / "VLP16.calibration.yaml";
  try {
    makeVelodyneDecoder(config);
    FAIL() << "accepted";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("VLP16.calibration.yaml: lasers:"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace rigcal::drivers::velodyne
