// `rigcal calibrate --config RIG (--pcap F | --bag B [--topic S=T]...) [--rate R] | --live | --shm) [--out DIR] [--deadline S] [--realtime]
// [--stats FILE.json] [--pin] [--cores 0,1]`: the main job (input, pinning and stats options as `rigcal map`).
// Mapping starts at once; each calibration lidar is calibrated (on its own thread, while mapping goes on) as
// soon as its frame budget is full, the others at the end of input, all within one calibration_deadline_s
// of calibration time (calib::LidarLidarWorker); then base-lidar calibration, the outputs
// in --out, and a summary table. Ctrl-C ends the input early and calibrates what has enough
// frames; a lidar without enough frames is named with what is missing (exit 5, partial report).
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <optional>
#include <sstream>
#include <thread>

#include "../bag_extrinsics.hpp"
#include "../calibrate_static.hpp"
#include "../commands.hpp"
#include "../exit_codes.hpp"
#include "../rig_loading.hpp"
#include "../output_folder.hpp"
#include "../pipeline_options.hpp"
#include "../stop_signals.hpp"
#include "../time_offsets.hpp"
#include "../view_option.hpp"
#include "rigcal/calib/base_lidar/base_from_motion.hpp"
#include "rigcal/calib/base_lidar/base_lidar_calibration.hpp"
#include "rigcal/calib/base_lidar/base_lidar_multi.hpp"
#include "rigcal/calib/lidar_lidar/lidar_lidar_calibration.hpp"
#include "rigcal/calib/lidar_lidar/lidar_lidar_verdict.hpp"
#include "rigcal/calib/lidar_lidar/lidar_lidar_worker.hpp"
#include "rigcal/calib/outputs/calibration_outcome.hpp"
#include "rigcal/calib/outputs/calibration_outputs.hpp"
#include "rigcal/calib/outputs/summary_table.hpp"
#include "rigcal/config/config_error.hpp"
#include "rigcal/config/rig_config.hpp"
#include "rigcal/core/heap_release.hpp"
#include "rigcal/pipeline/clock_offset_estimate.hpp"
#include "rigcal/pipeline/pipeline.hpp"

namespace rigcal::app {
namespace {

using Clock = std::chrono::steady_clock;

struct CalibrateOptions {
  std::string config, out = "rigcal-out";
  PipelineCliOptions pipeline;
  double deadline = -1.0;  // < 0: the rig's calibration_deadline_s
  bool static_vehicle = false;  // --static: a parked vehicle (calibrate_static_command.cpp)
  ViewCliOptions view;
};

/// Packet clocks further apart than this (each against the capture time) make a result unverified: at
/// 5 km/h the vehicle moves 1.4 cm in 10 ms. Measured between an OS1-64 and a VLP-16 with agreeing
/// clocks: see calibrate_degraded_test.cpp.
constexpr double kClockOffsetLimitMs = 10.0;

double since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

/// The pipeline's progress line and how full the calibration lidars' frame budgets are.
std::string progressLine(const pipeline::PipelineProgress& p) {
  std::ostringstream o;
  o << p.line() << " | budget " << std::fixed << std::setprecision(0) << 100.0 * p.budgetFill() << '%';
  return o.str();
}

void run(const CalibrateOptions& o) {
  const auto t_start = Clock::now();
  limitHeapRetention();  // issue #18: peak memory on embedded targets
  config::RigConfig rig = loadRig(o.config);
  if (o.deadline >= 0) rig.parameters.calibration_deadline_s = o.deadline;
  pipeline::PipelineOptions po = toPipelineOptions(o.pipeline);
  applyExtrinsicsFromBag(rig, po);
  const bool realtime = po.mode == pipeline::PipelineMode::kRealtime;
  prepareOutputFolder(o.out);
  std::vector<std::string> time_offset_lines;
  try {
    time_offset_lines = applyTimeOffsets(
        rig, po.input == pipeline::InputKind::kPcap ? std::optional<std::filesystem::path>(po.pcap) : std::nullopt);
  } catch (const std::exception& e) {
    throw CommandFailed(kExitInput, e.what());
  }
  for (const auto& line : time_offset_lines) std::cerr << line << "\n";
  CommandView view(o.view, "calibrate", rig);
  view.attach(po);

  StopSignals signals;
  // Every calibration lidar shares one calibration_deadline_s, whenever its dataset comes (budget full
  // during the drive, or end of input).
  calib::LidarLidarOptions lidar_lidar;
  lidar_lidar.trajectory_clock = true;  // the clock check that needs no capture time (live, shm)
  // The outputs' map comes from the pipeline (MappingResult::map_cloud): the datasets' mapping clouds go
  // once each lidar is calibrated.
  calib::LidarLidarWorker worker(rig.parameters, rig.roles.calibration_lidars.size(), lidar_lidar, nullptr,
                                 /*keep_mapping_clouds=*/false);
  std::unique_ptr<pipeline::Pipeline> pipe;
  try {
    pipe = std::make_unique<pipeline::Pipeline>(rig, po, [&](std::shared_ptr<const pipeline::CalibrationDataset> d) {
      worker.add(std::move(d));
      // Offline (a pcap as fast as possible) nothing is lost by waiting: mapping pauses while a lidar is
      // calibrated, which then has both cores for its share of the deadline.
      if (!realtime) worker.waitIdle();
    });
  } catch (const std::exception& e) {
    throw CommandFailed(kExitInput, e.what());
  }
  const auto view_follows = view.follow(*pipe);
  // A one-line progress display, on a terminal only.
  std::atomic<bool> input_done{false};
  std::thread progress;
  if (::isatty(STDERR_FILENO) != 0)
    progress = std::thread([&] {
      while (!input_done.load()) {
        std::fprintf(stderr, "\r\033[K%s", progressLine(pipe->progress()).c_str());
        std::fflush(stderr);
        for (int i = 0; i < 5 && !input_done.load(); ++i) std::this_thread::sleep_for(std::chrono::milliseconds(100));
      }
      std::fprintf(stderr, "\r\033[K");
    });
  try {
    pipe->run(StopSignals::flag());
  } catch (const std::exception& e) {
    input_done = true;
    if (progress.joinable()) progress.join();
    throw CommandFailed(kExitInput, e.what());
  }
  input_done = true;
  if (progress.joinable()) progress.join();
  view.finish();
  const double pipeline_seconds = since(t_start);
  const bool interrupted = StopSignals::requested();
  if (interrupted) std::cerr << "interrupted: input ended early; calibrating the lidars that have enough frames\n";
  worker.finish();

  // The mapper's snapshot (trajectory, the whole map voxelised, the dense cloud): seconds on a long drive.
  const auto t_map = Clock::now();
  const pipeline::MappingResult mapping = pipe->mapping();
  const double map_seconds = since(t_map);
  calib::CalibrationOutcome outcome;
  outcome.rig_name = rig.name;
  outcome.base_frame = rig.roles.base_frame;
  outcome.mapping_sensor = rig.roles.mapping_lidar;
  outcome.version = RIGCAL_VERSION;
  outcome.initial_T_base_sensor = rig.initial_T_base_sensor;
  outcome.deadline_s = rig.parameters.calibration_deadline_s;
  outcome.datasets = worker.datasets;
  outcome.lidars = worker.results;
  outcome.map_cloud = mapping.map_cloud;

  // Base-lidar: the ground fitted at keyframes spread along the path (the map in each keyframe's lidar
  // frame) and combined: on bumpy ground one keyframe's plane carries the body's tilt at that spot.
  const auto t_base = Clock::now();
  if (rig.parameters.calibrate_base_frame && mapping.map_cloud != nullptr && mapping.last_keyframe_frame >= 0) {
    std::vector<Pose> keyframes;
    for (const auto& f : mapping.trajectory)
      if (f.keyframe_index >= 0 && !f.lost) keyframes.push_back(f.T_map_lidar);
    std::vector<Eigen::Vector3d> points;
    const Scan& s = *mapping.map_cloud;
    points.reserve(s.size());
    for (std::size_t i = 0; i < s.size(); ++i) points.emplace_back(s.x[i], s.y[i], s.z[i]);
    outcome.base = calib::calibrateBaseLidarMulti(points, keyframes, mapping.T_base_mapping, rig.parameters);
    // Then yaw (and x) from the drive, levelled by the ground's roll and pitch (base_link_from_motion).
    const auto motion_mode = calib::parseBaseFromMotionMode(rig.parameters.base_link_from_motion);
    if (outcome.base->ok && motion_mode != calib::BaseFromMotionMode::kOff) {
      std::vector<TimeNs> stamps;
      std::vector<Pose> poses;
      std::vector<bool> usable;
      for (const auto& f : mapping.trajectory) {
        if (!stamps.empty() && f.stamp_ns <= stamps.back()) continue;
        stamps.push_back(f.stamp_ns);
        poses.push_back(f.T_map_lidar);
        usable.push_back(!f.lost);
      }
      outcome.base_motion =
          calib::estimateBaseFromMotion(stamps, poses, usable, outcome.base->T_base_lidar, motion_mode);
      outcome.base->T_base_lidar = outcome.base_motion->T_base_lidar;
    }
  } else if (!rig.parameters.calibrate_base_frame) {
    outcome.base_skipped = "calibrate_base_frame: false in the rig's parameters";
  } else {
    outcome.base_skipped = "no map: the mapping lidar made no keyframe";
  }
  if (!rig.parameters.calibrate_base_frame && rig.parameters.base_link_from_motion != "off")
    std::cerr << "base_link_from_motion needs calibrate_base_frame: true (roll and pitch from the ground); ignored\n";
  const double base_seconds = since(t_base);

  const auto progress_now = pipe->progress();
  const std::string source = po.input == pipeline::InputKind::kPcap ? po.pcap.string()
                             : po.input == pipeline::InputKind::kBag  ? po.bag.string()
                             : po.input == pipeline::InputKind::kLive ? std::string("live")
                                                                       : std::string("shm");
  outcome.input_summary = {{"source", source},
                           {"mode", realtime ? "realtime" : "offline"},
                           {"mapping_scans", std::to_string(progress_now.mapping_scans)},
                           {"keyframes", std::to_string(progress_now.keyframes)},
                           {"lost_frames", std::to_string(progress_now.lost_frames)},
                           {"interrupted", interrupted ? "yes" : "no"}};
  for (const auto& l : progress_now.lidars)
    outcome.input_summary.emplace_back(l.sensor + "_scans", std::to_string(l.scans));
  outcome.stage_seconds = {{"pipeline", pipeline_seconds}, {"lidar_lidar", worker.seconds},
                          {"map", map_seconds}, {"base_lidar", base_seconds}};

  // What the capture or the network cost each sensor, and each sensor's clock against the capture time.
  const auto inputs = pipe->inputs();
  const pipeline::SensorInput* mapping_lag = nullptr;
  for (const auto& in : inputs) {
    outcome.input_summary.emplace_back(in.sensor + "_packets_lost", std::to_string(in.lost_packets));
    outcome.input_summary.emplace_back(in.sensor + "_packets_malformed", std::to_string(in.malformed));
    outcome.input_summary.emplace_back(in.sensor + "_packets_late_dropped", std::to_string(in.late_dropped));
    outcome.input_summary.emplace_back(in.sensor + "_packets_reordered", std::to_string(in.reordered));
    outcome.input_summary.emplace_back(in.sensor + "_packets_foreign", std::to_string(in.foreign_packets));
    if (in.clock_lag_ms) {
      std::ostringstream lag;
      lag << std::fixed << std::setprecision(1) << *in.clock_lag_ms;
      outcome.input_summary.emplace_back(in.sensor + "_clock_lag_ms", lag.str());
      if (in.sensor == rig.roles.mapping_lidar) mapping_lag = &in;
    }
    if (in.damaged()) {
      std::ostringstream w;
      w << in.sensor << ": " << in.lost_packets << " of " << (in.packets + in.lost_packets) << " packets lost, "
        << in.malformed << " malformed, " << in.late_dropped << " too late, " << in.reordered
        << " out of order";
      if (!in.last_error.empty()) w << " (last malformed: " << in.last_error << ")";
      if (!in.warning.empty()) w << "; damaged capture: " << in.warning;
      if (in.foreign_packets > 0) w << "; " << in.foreign;
      outcome.warnings.push_back(w.str());
      std::cerr << "warning: " << w.str() << "\n";
    }
  }
  if (inputs.empty()) {
    // Scans handed in without a driver (rings have their drivers' tallies in inputs()): each scan says how
    // many packets it lost, so that damage is still reported per sensor.
    std::vector<std::pair<std::string, std::uint64_t>> lost{{progress_now.mapping_sensor, progress_now.mapping_lost_packets}};
    for (const auto& l : progress_now.lidars) lost.emplace_back(l.sensor, l.lost_packets);
    for (const auto& [sensor, n] : lost) {
      outcome.input_summary.emplace_back(sensor + "_packets_lost", std::to_string(n));
      if (n == 0) continue;
      outcome.warnings.push_back(sensor + ": " + std::to_string(n) + " packets lost (as its scans from the ring say)");
      std::cerr << "warning: " << outcome.warnings.back() << "\n";
    }
  }
  for (const auto& s : rig.sensors)
    if (s.time_offset_ns != 0 || s.estimate_time_offset)
      outcome.input_summary.emplace_back(s.name + "_time_offset_ns", std::to_string(s.time_offset_ns));
  for (auto& r : outcome.lidars) {
    r.evidence.time_offset_applied_ms = double(rig.sensor(r.calibration_sensor).time_offset_ns) * 1e-6;
    for (const auto& in : inputs)
      if (in.sensor == r.calibration_sensor && in.clock_lag_ms && mapping_lag != nullptr) {
        const auto offset = pipeline::clockOffsetBetween(
            {*mapping_lag->clock_lag_ms, mapping_lag->clock_lag_sigma_ms, mapping_lag->clock_lag_sweeps},
            {*in.clock_lag_ms, in.clock_lag_sigma_ms, in.clock_lag_sweeps});
        calib::doubtClockOffset(r, offset.offset_ms, kClockOffsetLimitMs, offset.uncertainty_ms);
      }
    calib::doubtTrajectoryClockOffset(r, kClockOffsetLimitMs, rig.parameters.calibration_deadline_s);
  }
  const auto shortfalls = pipe->shortfalls();
  for (const auto& sf : shortfalls) outcome.input_summary.emplace_back(sf.sensor + "_missing", sf.message);
  const std::filesystem::path out(o.out);
  // A run without a result for every calibration lidar writes its failure into calibration.yaml, never
  // the initial guess under the normal header (exit 5 / 130 below).
  for (const auto& sf : shortfalls) outcome.failure += (outcome.failure.empty() ? "" : "; ") + sf.message;
  if (outcome.failure.empty() && outcome.lidars.empty() && !rig.roles.calibration_lidars.empty())
    outcome.failure = "no calibration lidar got a dataset: no packets from " + rig.roles.calibration_lidars.front() + "?";
  try {
    calib::writeCalibrationOutputs(out, outcome);
  } catch (const std::exception& e) {
    throw CommandFailed(kExitFailure, e.what());
  }
  if (!o.pipeline.stats_file.empty()) reportStats(o.pipeline, pipe->stats());
  std::cout << calib::summaryTable(outcome) << "outputs in " << out.string() << "\n" << std::flush;
  view.results(out, rig.roles.calibration_lidars);
  view.hold();

  if (!shortfalls.empty()) {
    std::string msg = shortfalls.front().message;
    for (std::size_t i = 1; i < shortfalls.size(); ++i) msg += "; " + shortfalls[i].message;
    throw CommandFailed(interrupted && outcome.lidars.empty() ? kExitInterrupted : kExitNotEnoughData,
                        msg + " (partial report in " + (out / "report.json").string() + ")");
  }
  if (outcome.lidars.empty() && !rig.roles.calibration_lidars.empty())
    throw CommandFailed(interrupted ? kExitInterrupted : kExitNotEnoughData,
                        "no calibration lidar got a dataset: no packets from " + rig.roles.calibration_lidars.front() +
                            "? (partial report in " + (out / "report.json").string() + ")");
  for (const auto& r : outcome.lidars)
    if (!r.ok) throw CommandFailed(kExitFailure, r.calibration_sensor + ": " + r.failure);
  if (outcome.base && !outcome.base->ok) throw CommandFailed(kExitFailure, "base-lidar: " + outcome.base->failure);
  for (const auto& r : outcome.lidars)
    if (r.verdict == calib::Verdict::kUnverified)
      throw CommandFailed(kExitUnverified, r.calibration_sensor + ": unverified: " + r.doubt);
}

}  // namespace

void addCalibrateCommand(CLI::App& app) {
  auto o = std::make_shared<CalibrateOptions>();
  CLI::App* cmd = app.add_subcommand("calibrate", "Map with the mapping lidar and calibrate the rig (the main job).");
  cmd->add_option("--config", o->config, "rig YAML file")->required();
  addPipelineOptions(*cmd, o->pipeline);
  addViewOptions(*cmd, o->view);
  cmd->add_option("--out", o->out, "output folder (default rigcal-out)");
  cmd->add_option("--deadline", o->deadline, "seconds for the lidar-lidar calibration (calibration_deadline_s)")
      ->check(CLI::NonNegativeNumber);
  cmd->add_flag("--static", o->static_vehicle,
                "the vehicle stands still: accumulate static_capture_s of every lidar and register the clouds "
                "directly (refused when the vehicle moves)");
  cmd->footer(kExitCodesHelp);
  cmd->callback([o, cmd] {
    if (o->pipeline.pcap.empty() && o->pipeline.bag.empty() && !o->pipeline.live && !o->pipeline.shm)
      throw CLI::RequiredError("--pcap or --bag or --live or --shm");
    (void)cmd;
    if (o->static_vehicle) runCalibrateStatic(o->config, o->pipeline, o->out, o->deadline);
    else run(*o);
  });
}

}  // namespace rigcal::app
