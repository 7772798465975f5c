#include <gtest/gtest.h>

#include <filesystem>
#include <map>
#include <set>

#include "rigcal/drivers/ouster/ouster_metadata.hpp"
#include "test_data.hpp"

namespace rigcal::drivers::ouster {
namespace {

namespace fs = std::filesystem;

std::vector<fs::path> jsonFiles(const fs::path& dir) {
  std::vector<fs::path> out;
  for (const auto& e : fs::directory_iterator(dir))
    if (e.is_regular_file() && e.path().extension() == ".json" &&
        e.path().filename().string().find("_digest") == std::string::npos)
      out.push_back(e.path());
  std::sort(out.begin(), out.end());
  return out;
}

TEST(OusterMetadata, EveryFirmwareLayoutParses) {
  RIGCAL_REQUIRE_DATA(dir, "ouster/metadata");
  std::vector<fs::path> files = jsonFiles(dir);
  for (const auto& f : jsonFiles(dir.parent_path())) files.push_back(f);
  ASSERT_GE(files.size(), 30u);
  std::set<std::string> layouts;
  for (const auto& f : files) {
    SCOPED_TRACE(f.filename().string());
    Metadata m;
    ASSERT_NO_THROW(m = parseMetadataFile(f));
    EXPECT_EQ(m.beam_altitude_deg.size(), std::size_t(m.pixels_per_column));
    EXPECT_EQ(m.beam_azimuth_deg.size(), std::size_t(m.pixels_per_column));
    EXPECT_EQ(m.pixel_shift_by_row.size(), std::size_t(m.pixels_per_column));
    EXPECT_TRUE(m.columns_per_frame == 512 || m.columns_per_frame == 1024 || m.columns_per_frame == 2048);
    EXPECT_EQ(m.columns_per_frame % m.columns_per_packet, 0);
    EXPECT_GT(m.frames_per_second, 0);
    EXPECT_GT(m.lidar_origin_to_beam_origin_mm, 0);
    EXPECT_EQ(m.lidar_to_sensor[15], 1.0);
    layouts.insert(m.nested_layout ? "nested" : "flat");
  }
  EXPECT_EQ(layouts.size(), 2u);
}

TEST(OusterMetadata, ReadsTheFieldsOfEachLayout) {
  RIGCAL_REQUIRE_DATA(dir, "ouster");
  {  // flat layout, firmware 2.0, column window, 2048 columns
    const Metadata m = parseMetadataFile(dir / "metadata/2_0_0_os1-992008000494-128_col_win_legacy.json");
    EXPECT_FALSE(m.nested_layout);
    EXPECT_EQ(m.columns_per_frame, 2048);
    EXPECT_EQ(m.pixels_per_column, 128);
    EXPECT_EQ(m.column_window_first, 2014);
    EXPECT_EQ(m.column_window_last, 2036);
    EXPECT_EQ(m.profile, UdpProfile::kLegacy);
    EXPECT_EQ(m.prod_line, "OS-1-128");
    EXPECT_TRUE(m.slotInWindow(2014 / 16));
    EXPECT_FALSE(m.slotInWindow(0));
  }
  {  // nested layout, firmware 1.12: lidar_data_format was "error: Command not recognized."
    const Metadata m = parseMetadataFile(dir / "metadata/1_12_os1-991913000010-64.json");
    EXPECT_TRUE(m.nested_layout);
    EXPECT_EQ(m.pixels_per_column, 64);
    EXPECT_EQ(m.columns_per_packet, 16);
    EXPECT_EQ(m.lidar_mode, "1024x10");
    EXPECT_DOUBLE_EQ(m.lidar_origin_to_beam_origin_mm, 15.806);  // OS-1 default before fw 1.14
  }
  {  // firmware 3.2 nested layout with fps and a CRC footer, 512 columns, low data rate profile
    const Metadata m = parseMetadataFile(dir / "crc_test.json");
    EXPECT_EQ(m.profile, UdpProfile::kRng15Rfl8Nir8);
    EXPECT_EQ(m.columns_per_frame, 512);
    EXPECT_EQ(m.firmware, "v3.2.0");
    EXPECT_TRUE(m.crcFooter());
    EXPECT_EQ(m.init_id, 11394290u);
    EXPECT_EQ(m.serial, 122247000785ull);
    EXPECT_DOUBLE_EQ(m.beam_to_lidar[3], 27.116);
    EXPECT_DOUBLE_EQ(m.lidar_to_sensor[11], 38.195);
  }
  {  // FUSA dual profile
    const Metadata m = parseMetadataFile(dir / "same_ports.1.json");
    EXPECT_EQ(m.profile, UdpProfile::kFusaRng15Rfl8Nir8Dual);
    EXPECT_FALSE(m.crcFooter());
    EXPECT_EQ(m.firmware, "v3.1.0");
  }
  {  // a reduced config: angles and lidar_mode only; everything else defaults
    const Metadata m = parseMetadataFile(dir / "OS-1-64_sensor_config_reduced.json");
    EXPECT_EQ(m.pixels_per_column, 64);
    EXPECT_EQ(m.columns_per_frame, 1024);
    EXPECT_EQ(m.profile, UdpProfile::kLegacy);
    EXPECT_EQ(m.lidar_to_sensor[0], -1.0);
    EXPECT_EQ(m.lidar_to_sensor[11], 36.18);
    EXPECT_EQ(m.column_window_last, 1023);
  }
}

TEST(OusterMetadata, MalformedFilesAreRejectedWithOneLineNamingFileAndField) {
  RIGCAL_REQUIRE_DATA(dir, "ouster/metadata/malformed");
  const std::map<std::string, std::string> expected_field = {
      {"complete_but_all_zeros_legacy.json", "beam_altitude_angles"},
      {"garbled_legacy_and_nonlegacy.json", "sensor_info"},
      {"incomplete_data_format_legacy.json", "data_format.columns_per_frame"},
      {"incomplete_data_format_nonlegacy.json", "lidar_data_format.pixels_per_column"},
      {"incomplete_no_calref_nonlegacy.json", "calibration_status"},
      {"incomplete_no_sensor_info_nonlegacy.json", "sensor_info"},
      {"incorrect_nbeam_angles_legacy_113.json", "beam_azimuth_angles"},
      {"legacy_with_calibration_status.json", "sensor_info"},
  };
  std::size_t n = 0;
  for (const auto& f : jsonFiles(dir)) {
    SCOPED_TRACE(f.filename().string());
    ++n;
    try {
      parseMetadataFile(f);
      ADD_FAILURE() << "accepted";
    } catch (const std::runtime_error& e) {
      const std::string msg = e.what();
      EXPECT_NE(msg.find(f.filename().string()), std::string::npos) << msg;
      EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;
      const auto it = expected_field.find(f.filename().string());
      if (it != expected_field.end()) {
        EXPECT_NE(msg.find(it->second + ":"), std::string::npos) << msg;
      }
    }
  }
  EXPECT_EQ(n, expected_field.size());
}

TEST(OusterMetadata, RejectsBadTextNamingTheField) {
  auto message = [](const std::string& text) {
    try {
      parseMetadata(text, "m.json");
    } catch (const std::runtime_error& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  EXPECT_EQ(message("{not json"), "m.json: (file): not valid JSON");
  EXPECT_EQ(message("[1, 2]"), "m.json: (file): not a JSON object");
  const std::string angles = R"("beam_altitude_angles": [1, -1], "beam_azimuth_angles": [0, 0])";
  EXPECT_EQ(message("{" + angles + "}"), "accepted");
  EXPECT_NE(message("{" + angles + R"(, "lidar_mode": "1000x7"})").find("m.json: lidar_mode:"), std::string::npos);
  EXPECT_NE(message("{" + angles +
                    R"(, "data_format": {"pixels_per_column": 2, "columns_per_packet": 16, "columns_per_frame": 1024,
                        "pixel_shift_by_row": [0, 0], "udp_profile_lidar": "RNG99"}})")
                .find("data_format.udp_profile_lidar: unknown profile"),
            std::string::npos);
  EXPECT_NE(message(R"({"beam_altitude_angles": [1, "x"], "beam_azimuth_angles": [0, 0]})")
                .find("beam_altitude_angles[1]: not a number"),
            std::string::npos);
  EXPECT_NE(message("{" + angles + R"(, "lidar_to_sensor_transform": [1, 0, 0]})").find("lidar_to_sensor_transform:"),
            std::string::npos);
  EXPECT_THROW(parseMetadataFile("/nonexistent/meta.json"), std::runtime_error);
}

}  // namespace
}  // namespace rigcal::drivers::ouster
