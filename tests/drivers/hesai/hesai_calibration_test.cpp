// The angle-correction CSV (hesai_calibration.hpp).
#include <gtest/gtest.h>

#include <fstream>

#include "rigcal/drivers/hesai/hesai_calibration.hpp"
#include "test_data.hpp"

namespace rigcal::drivers::hesai {
namespace {

std::string errorOf(const std::string& text, std::size_t channels) {
  try {
    parseCalibrationCsv(text, "cal.csv", channels);
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  return "(no error)";
}

std::string rows(int n, int start = 1) {
  std::string s;
  for (int i = start; i < start + n; ++i) s += std::to_string(i) + "," + std::to_string(15 - i) + ",0.5\n";
  return s;
}

TEST(HesaiCalibration, ReadsTheSampleFiles) {
  RIGCAL_REQUIRE_DATA(xt32, "hesai/PandarXT32.csv");
  RIGCAL_REQUIRE_DATA(xt16, "hesai/PandarXT16.csv");
  RIGCAL_REQUIRE_DATA(qt128, "hesai/PandarQT128.csv");
  const Calibration a = readCalibrationCsv(xt32, 32);
  ASSERT_EQ(a.channels(), 32u);
  EXPECT_DOUBLE_EQ(a.elevation_deg[0], 14.972363);
  EXPECT_DOUBLE_EQ(a.azimuth_offset_deg[0], 0.082385);
  EXPECT_EQ(readCalibrationCsv(xt16, 16).elevation_deg[15], -15.0);
  const Calibration q = readCalibrationCsv(qt128, 128);
  EXPECT_DOUBLE_EQ(q.elevation_deg[0], -52.62676282);
  EXPECT_DOUBLE_EQ(q.azimuth_offset_deg[0], 10.10830596);
}

TEST(HesaiCalibration, ToleratesCrlfBlankLinesAndTrailingCommas) {
  const Calibration c = parseCalibrationCsv("Laser id,Elevation,Azimuth\r\n1, 15 ,0\r\n\r\n2,13,-0.25,\r\n", "x", 2);
  ASSERT_EQ(c.channels(), 2u);
  EXPECT_EQ(c.elevation_deg[0], 15.0);
  EXPECT_EQ(c.azimuth_offset_deg[1], -0.25);
}

TEST(HesaiCalibration, MalformedFilesNameFileAndLine) {
  EXPECT_EQ(errorOf("Channel,Elevation,Azimuth\n1,15,0\n2,13\n", 2),
            "cal.csv:3: expected 3 columns (channel, elevation, azimuth), got 2");
  EXPECT_EQ(errorOf("Channel,Elevation,Azimuth\n1,15,0,7\n", 1),
            "cal.csv:2: expected 3 columns (channel, elevation, azimuth), got 4");
  EXPECT_EQ(errorOf("Channel,Elevation,Azimuth\n" + rows(16), 32),
            "cal.csv:17: file ends after 16 channel rows, expected 32");
  EXPECT_EQ(errorOf("Channel,Elevation,Azimuth\n" + rows(17), 16), "cal.csv:18: channel 17 beyond the model's 16 channels");
  EXPECT_EQ(errorOf("Channel,Elevation,Azimuth\n1,abc,0\n", 1), "cal.csv:2: elevation 'abc' is not a number");
  EXPECT_EQ(errorOf("Channel,Elevation,Azimuth\n1,1,0x\n", 1), "cal.csv:2: azimuth '0x' is not a number");
  EXPECT_EQ(errorOf("Channel,Elevation,Azimuth\n1,1,nan\n", 1), "cal.csv:2: azimuth 'nan' is not a number");
  EXPECT_EQ(errorOf("Channel,Elevation,Azimuth\n1,95,0\n", 1), "cal.csv:2: elevation 95 deg outside [-90, 90]");
  EXPECT_EQ(errorOf("Channel,Elevation,Azimuth\n1,5,200\n", 1), "cal.csv:2: azimuth offset 200 deg outside [-180, 180]");
  EXPECT_EQ(errorOf("Channel,Elevation,Azimuth\n1,5,0\n3,5,0\n", 2), "cal.csv:3: channel '3', expected 2");
  EXPECT_EQ(errorOf("Channel,Elevation,Azimuth\n1,5,0\nfoo,5,0\n", 2), "cal.csv:3: channel 'foo' is not a number");
  EXPECT_EQ(errorOf("", 16), "cal.csv:1: file ends after 0 channel rows, expected 16");
  // Garbage: a binary blob.
  std::string garbage;
  for (int i = 0; i < 300; ++i) garbage += static_cast<char>((i * 37) % 256);
  const std::string e = errorOf(garbage, 32);
  EXPECT_EQ(e.rfind("cal.csv:", 0), 0u) << e;
  EXPECT_EQ(e.find('\n'), std::string::npos) << e;
}

TEST(HesaiCalibration, MissingFileIsNamed) {
  test::TempDir dir;
  try {
    readCalibrationCsv(dir / "nope.csv", 32);
    FAIL();
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("nope.csv: cannot open"), std::string::npos) << e.what();
  }
  std::ofstream(dir / "short.csv") << "Channel,Elevation,Azimuth\n1,15,0\n";
  try {
    readCalibrationCsv(dir / "short.csv", 32);
    FAIL();
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("short.csv:2: file ends after 1 channel rows, expected 32"), std::string::npos)
        << e.what();
  }
}

TEST(HesaiCalibration, NominalAnglesForXtOnly) {
  const Calibration xt32 = nominalCalibration(*findModel("PandarXT32"));
  ASSERT_EQ(xt32.channels(), 32u);
  EXPECT_EQ(xt32.elevation_deg.front(), 15.0);
  EXPECT_EQ(xt32.elevation_deg.back(), -16.0);
  const Calibration xt16 = nominalCalibration(*findModel("PandarXT16"));
  EXPECT_EQ(xt16.elevation_deg.back(), -15.0);
  EXPECT_THROW(nominalCalibration(*findModel("PandarQT128")), std::runtime_error);
}

}  // namespace
}  // namespace rigcal::drivers::hesai
