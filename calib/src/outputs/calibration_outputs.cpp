#include "rigcal/calib/outputs/calibration_outputs.hpp"

#include <chrono>

#include "rigcal/calib/outputs/calibration_yaml_writer.hpp"
#include "rigcal/calib/outputs/cloud_writers.hpp"
#include "rigcal/calib/outputs/overview_png_writer.hpp"
#include "rigcal/calib/outputs/report_json_writer.hpp"

namespace rigcal::calib {

void writeCalibrationOutputs(const std::filesystem::path& out, CalibrationOutcome& outcome) {
  const auto start = std::chrono::steady_clock::now();
  writeCalibrationYaml(out / "calibration.yaml", outcome);
  if (!outcome.datasets.empty()) {
    writeCalibrationClouds(out, outcome);
    writeOverviewPng(out / "overview.png", outcome);
  }
  outcome.stage_seconds.emplace_back("outputs",
                                     std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
  writeReportJson(out / "report.json", outcome);
}

}  // namespace rigcal::calib
