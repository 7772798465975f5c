// `rigcal map --config rig.yaml (--pcap F | --bag B [--topic S=T]...) [--rate R] | --live | --shm) [--out DIR] [--stats FILE.json]
// [--pin] [--cores 0,1]`: runs the online pipeline (mapping, keyframes, pairing, frame selection) without
// calibrating; prints the stage stats at exit and writes the trajectory, map.pcd and a selection summary.
#include <unistd.h>

#include <atomic>
#include <condition_variable>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <mutex>
#include <thread>

#include "../bag_extrinsics.hpp"
#include "../commands.hpp"
#include "../exit_codes.hpp"
#include "../rig_loading.hpp"
#include "../output_folder.hpp"
#include "../pipeline_options.hpp"
#include "../stop_signals.hpp"
#include "../view_option.hpp"
#include "rigcal/config/rig_config.hpp"
#include "rigcal/core/pcd_io.hpp"
#include "rigcal/core/point_table.hpp"
#include "rigcal/shm/ring_error.hpp"

namespace rigcal::app {
namespace {

namespace fs = std::filesystem;

struct MapArgs {
  std::string config, out;
  PipelineCliOptions pipeline;
  ViewCliOptions view;
};

void writeTrajectory(const fs::path& file, const pipeline::MappingResult& m) {
  AtomicFile atomic(file);
  std::ostream& out = atomic.stream();
  out << "# sequence,stamp_ns,kind,lost,path_length_m,x,y,z,qw,qx,qy,qz,lost_reason  (T_map_" << m.mapping_sensor
      << "; map = the first frame)\n";
  out << std::setprecision(9);
  for (const auto& f : m.trajectory) {
    const Eigen::Quaterniond q(f.T_map_lidar.linear());
    const Eigen::Vector3d t = f.T_map_lidar.translation();
    out << f.sequence << ',' << f.stamp_ns << ',' << pipeline::toString(f.kind) << ',' << (f.lost ? 1 : 0) << ','
        << f.path_length << ',' << t.x() << ',' << t.y() << ',' << t.z() << ',' << q.w() << ',' << q.x() << ','
        << q.y() << ',' << q.z() << ',' << f.lost_reason << '\n';
  }
  commitOutput(atomic);
}

void writeSelection(const fs::path& file, const std::vector<std::shared_ptr<const pipeline::CalibrationDataset>>& ds,
                    const std::vector<pipeline::Shortfall>& shortfalls) {
  AtomicFile atomic(file);
  std::ostream& out = atomic.stream();
  for (const auto& d : ds) {
    out << d->calibration_sensor << ": " << d->frames.size() << " frames selected ("
        << (d->budget_full ? "budget full" : "end of input") << "), " << d->candidates.size() << " candidates, "
        << d->mapping_clouds.size() << " mapping clouds\n";
    for (const auto& f : d->frames)
      out << "  selected scan " << f.pairing.scan_sequence << " at keyframe frame " << f.pairing.keyframe_frame
          << ", information " << f.information << ", dt " << f.pairing.stats.time_s << " s, "
          << f.deskewed->size() << " points\n";
    for (const auto& r : d->rejected)
      out << "  rejected scan " << d->candidates[r.id].scan_sequence << ": " << r.reason << '\n';
  }
  for (const auto& s : shortfalls) out << s.sensor << ": " << s.message << '\n';
  commitOutput(atomic);
}

void run(const MapArgs& a) {
  config::RigConfig rig = loadRig(a.config);
  pipeline::PipelineOptions options = toPipelineOptions(a.pipeline);
  applyExtrinsicsFromBag(rig, options);
  if (!a.out.empty()) prepareOutputFolder(a.out);
  CommandView view(a.view, "map", rig);
  view.attach(options);

  std::mutex m;
  std::vector<std::shared_ptr<const pipeline::CalibrationDataset>> datasets;
  StopSignals signals;
  std::unique_ptr<pipeline::Pipeline> p;
  try {
    p = std::make_unique<pipeline::Pipeline>(rig, options, [&](std::shared_ptr<const pipeline::CalibrationDataset> d) {
      std::lock_guard lock(m);
      datasets.push_back(std::move(d));
    });
  } catch (const shm::RingError& e) {
    throw CommandFailed(kExitInput, e.what());
  } catch (const std::exception& e) {
    throw CommandFailed(kExitInput, e.what());
  }

  const auto view_follows = view.follow(*p);
  // A one-line progress display on a terminal.
  std::atomic<bool> done{false};
  std::thread progress;
  if (isatty(STDERR_FILENO)) {
    progress = std::thread([&] {
      while (!done.load()) {
        std::cerr << '\r' << p->progress().line() << "   " << std::flush;
        std::this_thread::sleep_for(std::chrono::milliseconds(500));
      }
      std::cerr << '\r' << p->progress().line() << '\n';
    });
  }
  p->run(StopSignals::flag());
  done.store(true);
  if (progress.joinable()) progress.join();
  view.finish();

  const pipeline::MappingResult mapping = p->mapping();
  const auto shortfalls = p->shortfalls();
  const auto progress_now = p->progress();
  reportStats(a.pipeline, p->stats());
  std::cout << progress_now.line() << '\n';
  for (const auto& s : shortfalls) std::cout << "not enough frames: " << s.message << '\n';
  if (!a.out.empty()) {
    writeTrajectory(fs::path(a.out) / "trajectory.csv", mapping);
    try {
      writePcd(fs::path(a.out) / "map.pcd", toTable(*mapping.map_cloud));
    } catch (const std::exception& e) {
      throw CommandFailed(kExitFailure, e.what());
    }
    std::lock_guard lock(m);
    writeSelection(fs::path(a.out) / "selection.txt", datasets, shortfalls);
    std::cout << "wrote trajectory.csv (" << mapping.trajectory.size() << " frames), map.pcd ("
              << mapping.map_cloud->size() << " points), selection.txt to " << a.out << '\n';
  }
  view.hold();
  if (mapping.trajectory.empty()) throw CommandFailed(kExitNotEnoughData, "no mapping-lidar scan was registered");
  if (StopSignals::requested() && pipeline::isRecording(options.input))
    throw CommandFailed(kExitInterrupted, "map interrupted (outputs hold what was mapped)");
}

}  // namespace

void addMapCommand(CLI::App& app) {
  auto a = std::make_shared<MapArgs>();
  auto* cmd = app.add_subcommand("map", "Run the online pipeline (mapping, keyframes, pairing, selection) and write the map");
  cmd->add_option("--config", a->config, "Rig YAML file")->required();
  addPipelineOptions(*cmd, a->pipeline);
  addViewOptions(*cmd, a->view);
  cmd->add_option("--out", a->out, "Write trajectory.csv, map.pcd and selection.txt here");
  cmd->footer(std::string("Stops at the end of the capture, or on Ctrl-C. ") + kExitCodesHelp);
  cmd->callback([a] { run(*a); });
}

}  // namespace rigcal::app
