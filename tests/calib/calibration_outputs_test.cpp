// The calibration outputs on a small hand-made rig: calibration.yaml, report.json, the PCD clouds,
// overview.png and the stdout summary, each read back and checked.
#include <gtest/gtest.h>
#include <png.h>
#include <yaml-cpp/yaml.h>

#include <cstdio>
#include <fstream>
#include <memory>
#include <nlohmann/json.hpp>

#include "rigcal/calib/outputs/calibration_outcome.hpp"
#include "rigcal/calib/outputs/calibration_yaml_writer.hpp"
#include "rigcal/calib/outputs/cloud_writers.hpp"
#include "rigcal/calib/outputs/overview_png_writer.hpp"
#include "rigcal/calib/outputs/report_json_writer.hpp"
#include "rigcal/calib/outputs/summary_table.hpp"
#include "rigcal/core/pcd_io.hpp"
#include "test_data.hpp"

namespace rigcal::calib {
namespace {

/// A room-corner scene (floor and two walls) seen by the mapping lidar at the origin; one calibration
/// lidar whose frame sees the same points through the true extrinsic.
CalibrationOutcome makeOutcome() {
  CalibrationOutcome o;
  o.rig_name = "test-rig";
  o.mapping_sensor = "top";
  o.version = "0.0-test";
  o.deadline_s = 10.0;
  o.initial_T_base_sensor["top"] = fromXyzRpy({1.0, 0.0, 2.0, 0.0, 0.0, 0.0});
  o.initial_T_base_sensor["left"] = fromXyzRpy({2.0, 0.8, 1.0, 0.0, 0.1, 0.7});
  auto scene = std::make_shared<Scan>();
  for (int i = 0; i < 60; ++i)
    for (int j = 0; j < 60; ++j) {
      const float a = -6.0F + 0.2F * float(i), b = -6.0F + 0.2F * float(j);
      scene->x.push_back(a), scene->y.push_back(b), scene->z.push_back(-2.0F);  // floor
      scene->x.push_back(6.0F), scene->y.push_back(a), scene->z.push_back(-2.0F + 0.06F * float(j));  // wall
      scene->x.push_back(a), scene->y.push_back(6.0F), scene->z.push_back(-2.0F + 0.06F * float(j));  // wall
    }
  scene->intensity.assign(scene->x.size(), 0.0F);
  scene->ring.assign(scene->x.size(), 0);
  scene->offset_ns.assign(scene->x.size(), 0);
  scene->return_index.assign(scene->x.size(), 0);

  const Pose truth = fromXyzRpy({1.0, 0.8, -1.0, 0.0, 0.1, 0.7});
  pipeline::CalibrationDataset d;
  d.mapping_sensor = "top";
  d.calibration_sensor = "left";
  d.T_mapping_calib_guess = fromXyzRpy({1.2, 0.6, -0.9, 0.05, 0.05, 0.75});
  pipeline::MappingFrame kf;
  kf.sequence = 1;
  kf.kind = pipeline::FrameKind::kKeyframe;
  kf.keyframe_index = 0;
  d.trajectory = {kf};
  d.mapping_clouds = {{kf, scene}};
  auto in_calib = std::make_shared<Scan>(*scene);
  const Pose inv = truth.inverse();
  for (std::size_t i = 0; i < in_calib->size(); ++i) {
    const Eigen::Vector3d p = inv * Eigen::Vector3d(scene->x[i], scene->y[i], scene->z[i]);
    in_calib->x[i] = float(p.x()), in_calib->y[i] = float(p.y()), in_calib->z[i] = float(p.z());
  }
  pipeline::CalibrationFrame f;
  f.raw = in_calib;
  f.deskewed = in_calib;
  d.frames = {f};
  pipeline::Pairing rejected;
  rejected.scan_sequence = 42;
  d.candidates = {f.pairing, rejected};
  d.rejected = {{1, "information 0.12 < calibration_min_pca_eigenvalue 0.25"}};
  o.datasets = {d};

  LidarLidarResult r;
  r.mapping_sensor = "top";
  r.calibration_sensor = "left";
  r.ok = true;
  r.T_mapping_calib_guess = d.T_mapping_calib_guess;
  r.T_mapping_calib = truth;
  r.initial_score.value = 0.008;
  r.final_score.value = 0.0004;
  r.final_score.rmse = 0.02;
  r.final_score.inlier_ratio = 0.97;
  r.frames_used = {0};
  RegistratorRun run;
  run.frame = 0;
  run.registrator = "gicp";
  run.seconds = 0.05;
  run.score = 0.0004;
  r.runs = {run, run};
  o.lidars = {r};
  BaseLidarResult base;
  base.ok = true;
  base.T_base_lidar = fromXyzRpy({1.0, 0.0, 1.98, 0.01, -0.02, 0.0});
  base.plane.inliers = 3600;
  o.base = base;
  o.stage_seconds = {{"calibration", 1.5}};
  o.input_summary = {{"source", "test"}};
  return o;
}

TEST(CalibrationOutputs, YamlHasEveryPairAndEverySensorInBase) {
  const auto o = makeOutcome();
  test::TempDir dir;
  writeCalibrationYaml(dir / "calibration.yaml", o);
  const YAML::Node y = YAML::LoadFile((dir / "calibration.yaml").string());
  EXPECT_NEAR(y["base_link"]["top"]["z"].as<double>(), 1.98, 1e-6);
  EXPECT_NEAR(y["base_link"]["top"]["roll"].as<double>(), 0.01, 1e-6);
  EXPECT_NEAR(y["top"]["left"]["x"].as<double>(), 1.0, 1e-6);
  EXPECT_NEAR(y["top"]["left"]["yaw"].as<double>(), 0.7, 1e-6);
  // T_base_left = T_base_top(calibrated) · T_top_left(calibrated)
  const Pose want = o.base->T_base_lidar * o.lidars[0].T_mapping_calib;
  const XyzRpy v = toXyzRpy(want);
  EXPECT_NEAR(y["T_base_sensor"]["left"]["x"].as<double>(), v.x, 1e-6);
  EXPECT_NEAR(y["T_base_sensor"]["left"]["pitch"].as<double>(), v.pitch, 1e-6);
  EXPECT_TRUE(y["T_base_sensor"]["top"]);
  EXPECT_THROW(writeCalibrationYaml(dir / "missing" / "x.yaml", o), std::runtime_error);
}

TEST(CalibrationOutputs, ReportListsSelectionRejectionsRunsAndVersion) {
  const auto o = makeOutcome();
  test::TempDir dir;
  writeReportJson(dir / "report.json", o);
  std::ifstream in(dir / "report.json");
  const auto j = nlohmann::json::parse(in);
  EXPECT_EQ(j["version"], "0.0-test");
  EXPECT_EQ(j["deadline_s"], 10.0);
  ASSERT_EQ(j["lidars"].size(), 1u);
  const auto& l = j["lidars"][0];
  EXPECT_EQ(l["sensor"], "left");
  EXPECT_EQ(l["selected_frames"].size(), 1u);
  EXPECT_TRUE(l["selected_frames"][0]["used"].get<bool>());
  ASSERT_EQ(l["rejections"].size(), 1u);
  EXPECT_NE(l["rejections"][0]["reason"].get<std::string>().find("calibration_min_pca_eigenvalue"), std::string::npos);
  EXPECT_EQ(l["rejections"][0]["pairing"]["scan_sequence"], 42);
  EXPECT_EQ(l["per_registrator"]["gicp"]["runs"], 2);
  EXPECT_NEAR(l["per_registrator"]["gicp"]["seconds"].get<double>(), 0.1, 1e-12);
  EXPECT_TRUE(l["ok"].get<bool>());
  EXPECT_EQ(j["stage_seconds"]["calibration"], 1.5);
  EXPECT_EQ(j["input"]["source"], "test");
  EXPECT_TRUE(j["base_lidar"]["ok"].get<bool>());
}

TEST(CalibrationOutputs, CloudsAreInTheMapFrameAndTheAfterCloudLiesOnTheMap) {
  const auto o = makeOutcome();
  test::TempDir dir;
  writeCalibrationClouds(dir.path(), o, 0.0);
  const auto map = readPcd(dir / "map.pcd");
  const auto before = readPcd(dir / "left_before.pcd");
  const auto after = readPcd(dir / "left_after.pcd");
  ASSERT_EQ(map.size(), o.datasets[0].mapping_clouds[0].cloud->size());
  ASSERT_EQ(after.size(), map.size());
  ASSERT_EQ(before.size(), map.size());
  double after_err = 0, before_err = 0;
  for (std::size_t i = 0; i < map.size(); ++i) {
    for (const char* c : {"x", "y", "z"}) {
      after_err = std::max(after_err, std::abs(after.column(c)[i] - map.column(c)[i]));
      before_err = std::max(before_err, std::abs(before.column(c)[i] - map.column(c)[i]));
    }
  }
  EXPECT_LT(after_err, 1e-4);  // the calibrated extrinsic puts every point back on its map point
  EXPECT_GT(before_err, 0.1);
}

TEST(CalibrationOutputs, OverviewPngShowsBothPanelsInTheLidarsColour) {
  const auto o = makeOutcome();
  test::TempDir dir;
  writeOverviewPng(dir / "overview.png", o, 400);
  // Read it back with libpng.
  FILE* f = std::fopen((dir / "overview.png").c_str(), "rb");
  ASSERT_NE(f, nullptr);
  png_structp png = png_create_read_struct(PNG_LIBPNG_VER_STRING, nullptr, nullptr, nullptr);
  png_infop info = png_create_info_struct(png);
  png_init_io(png, f);
  png_read_png(png, info, PNG_TRANSFORM_IDENTITY, nullptr);
  const int w = int(png_get_image_width(png, info)), h = int(png_get_image_height(png, info));
  png_bytepp rows = png_get_rows(png, info);
  int left_red = 0, right_red = 0;
  for (int y = 60; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const png_bytep p = rows[y] + 3 * x;
      if (p[0] == 255 && p[1] == 70 && p[2] == 70) ++(x < w / 2 ? left_red : right_red);
    }
  png_destroy_read_struct(&png, &info, nullptr);
  std::fclose(f);
  EXPECT_EQ(w, 810);
  EXPECT_EQ(h, 456);
  EXPECT_GT(left_red, 100);
  EXPECT_GT(right_red, 100);
  EXPECT_THROW(writeOverviewPng(dir / "missing" / "o.png", o, 100), std::runtime_error);
}

TEST(CalibrationOutputs, SummaryTableNamesEachPairWithResultChangeScoreAndFrames) {
  auto o = makeOutcome();
  const std::string table = summaryTable(o);
  EXPECT_NE(table.find("base_link -> top"), std::string::npos) << table;
  EXPECT_NE(table.find("top -> left"), std::string::npos) << table;
  EXPECT_NE(table.find("1/1"), std::string::npos) << table;
  EXPECT_NE(table.find("0.0200, 0.97"), std::string::npos) << table;
  o.lidars[0].ok = false;
  o.lidars[0].failure = "no registration beat the initial guess's score";
  EXPECT_NE(summaryTable(o).find("FAILED"), std::string::npos);
  EXPECT_NE(summaryTable(o).find("left: no registration beat"), std::string::npos);
}

}  // namespace
}  // namespace rigcal::calib
