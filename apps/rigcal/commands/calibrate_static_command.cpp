// `rigcal calibrate --static --config RIG (--pcap F | --bag B [--topic S=T]... | --live | --shm) [--out DIR]
// [--deadline S]`: a parked vehicle. Once the mapping lidar's sweeps agreed for 0.5 s, every lidar's sweeps
// over static_capture_s are accumulated (static_capture.cpp); the mapping lidar's sweeps must agree with
// the capture's first (else refused: when and how much it moved); each calibration lidar's cloud is
// registered to the mapping lidar's with `rigcal register`'s global stage and ensemble, then refined on
// the shared floor (calib/static_calibration.cpp); base-lidar from the ground; the outputs and exit codes
// of `calibrate`.
#include <chrono>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <sstream>

#include "../bag_extrinsics.hpp"
#include "../calibrate_static.hpp"
#include "../commands.hpp"
#include "../exit_codes.hpp"
#include "../output_folder.hpp"
#include "../rig_loading.hpp"
#include "../static_capture.hpp"
#include "../stop_signals.hpp"
#include "rigcal/calib/lidar_lidar/static_calibration.hpp"
#include "rigcal/calib/outputs/calibration_outputs.hpp"
#include "rigcal/calib/outputs/summary_table.hpp"
#include "rigcal/core/text_format.hpp"

namespace rigcal::app {
namespace {

using Clock = std::chrono::steady_clock;

double since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

}  // namespace

void runCalibrateStatic(const std::string& config, const PipelineCliOptions& input, const std::string& out_dir,
                        double deadline) {
  const auto t_start = Clock::now();
  config::RigConfig rig = loadRig(config);
  if (deadline >= 0) rig.parameters.calibration_deadline_s = deadline;
  pipeline::PipelineOptions po = toPipelineOptions(input);
  applyExtrinsicsFromBag(rig, po);  // `initial_extrinsics: from_bag`: the bag's tf tree
  prepareOutputFolder(out_dir);
  const std::filesystem::path out(out_dir);

  StopSignals signals;
  StaticCaptureResult cap;
  try {
    cap = captureStatic(rig, po, rig.parameters.static_capture_s, StopSignals::flag());
  } catch (const std::exception& e) {
    throw CommandFailed(kExitInput, e.what());
  }
  const double capture_seconds = since(t_start);
  const bool interrupted = StopSignals::requested();

  calib::StaticCalibrationOptions so;
  so.deadline_s = rig.parameters.calibration_deadline_s;
  calib::StaticCalibration sc;
  std::string shortfall;
  if (!cap.settled && !cap.never_still.empty() && !interrupted) {
    shortfall = "static: " + cap.never_still;
  } else if (cap.capture.mapping.empty()) {
    shortfall = "no complete sweep of the mapping lidar " + rig.roles.mapping_lidar + " in the input";
  } else {
    sc = calib::calibrateStatic(cap.capture, rig, so);
  }
  calib::CalibrationOutcome& outcome = sc.outcome;
  if (!shortfall.empty()) {
    outcome.rig_name = rig.name;
    outcome.base_frame = rig.roles.base_frame;
    outcome.mapping_sensor = rig.roles.mapping_lidar;
    outcome.initial_T_base_sensor = rig.initial_T_base_sensor;
    outcome.deadline_s = rig.parameters.calibration_deadline_s;
    outcome.failure = shortfall;
  }
  outcome.version = RIGCAL_VERSION;
  const std::string source = po.input == pipeline::InputKind::kPcap ? po.pcap.string()
                             : po.input == pipeline::InputKind::kBag  ? po.bag.string()
                             : po.input == pipeline::InputKind::kLive ? std::string("live")
                                                                       : std::string("shm");
  std::vector<std::pair<std::string, std::string>> summary = {
      {"source", source},
      {"mode", "static"},
      {"static_capture_s", fixed(rig.parameters.static_capture_s, 2)},
      {"captured_s", fixed(cap.capture.capture_s, 2)},
      {"capture_complete", cap.complete ? "yes" : "no (the input ended first)"},
      {"mapping_sweeps", std::to_string(cap.capture.mapping.size())},
      {"waited_for_stillness_s", fixed(cap.waited_s, 2)},
      {"still", cap.settled && sc.stillness.still ? "yes" : "no"},
      {"max_motion_m", fixed(sc.stillness.largest.metres, 4)},
      {"max_motion_deg", fixed(sc.stillness.largest.degrees, 3)},
      {"interrupted", interrupted ? "yes" : "no"}};
  outcome.input_summary.insert(outcome.input_summary.begin(), summary.begin(), summary.end());
  outcome.stage_seconds.insert(outcome.stage_seconds.begin(), {"capture", capture_seconds});
  for (const auto& in : cap.inputs) {
    outcome.input_summary.emplace_back(in.sensor + "_packets_lost", std::to_string(in.lost_packets));
    outcome.input_summary.emplace_back(in.sensor + "_packets_malformed", std::to_string(in.malformed));
    if (in.damaged()) {
      std::ostringstream w;
      w << in.sensor << ": " << in.lost_packets << " of " << (in.packets + in.lost_packets) << " packets lost, "
        << in.malformed << " malformed, " << in.late_dropped << " too late";
      if (!in.last_error.empty()) w << " (last malformed: " << in.last_error << ")";
      if (!in.warning.empty()) w << "; damaged capture: " << in.warning;
      outcome.warnings.push_back(w.str());
      std::cerr << "warning: " << w.str() << "\n";
    }
  }
  if (!cap.complete && sc.stillness.still && shortfall.empty()) {
    const std::string w = "the input ended after " + fixed(cap.capture.capture_s, 2) + " s of the " +
                          fixed(rig.parameters.static_capture_s, 2) + " s static_capture_s: calibrated with what there was";
    outcome.warnings.push_back(w);
    std::cerr << "warning: " << w << "\n";
  }

  try {
    calib::writeCalibrationOutputs(out, outcome);
  } catch (const std::exception& e) {
    throw CommandFailed(kExitFailure, e.what());
  }
  std::cout << calib::summaryTable(outcome) << "outputs in " << out.string() << "\n";

  const std::string partial = " (partial report in " + (out / "report.json").string() + ")";
  if (!shortfall.empty()) throw CommandFailed(interrupted ? kExitInterrupted : kExitNotEnoughData, shortfall + partial);
  if (!sc.stillness.still) throw CommandFailed(kExitNotEnoughData, "static: " + sc.stillness.message + partial);
  if (outcome.lidars.empty() && !rig.roles.calibration_lidars.empty())
    throw CommandFailed(interrupted ? kExitInterrupted : kExitNotEnoughData, outcome.failure + partial);
  for (const auto& r : outcome.lidars)
    if (!r.ok) throw CommandFailed(kExitFailure, r.calibration_sensor + ": " + r.failure);
  if (!outcome.failure.empty()) throw CommandFailed(kExitNotEnoughData, outcome.failure + partial);
  if (outcome.base && !outcome.base->ok) throw CommandFailed(kExitFailure, "base-lidar: " + outcome.base->failure);
  for (const auto& r : outcome.lidars)
    if (r.verdict == calib::Verdict::kUnverified)
      throw CommandFailed(kExitUnverified, r.calibration_sensor + ": unverified: " + r.doubt);
}

}  // namespace rigcal::app
