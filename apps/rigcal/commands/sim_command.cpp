// `rigcal sim --scenario NAME|FILE.yaml --out DIR [--seed N] [--format pcap|mcap|both]`: a synthetic rig
// recording with ground truth. Writes truth.yaml, poses.csv, rig.yaml (+ the sensors' calibration/metadata
// files) and, when every sensor's model has a packet encoder, recording.pcap; --format mcap (or both)
// writes the recording as MCAP bags instead (or too): recording.mcap (packets) and recording_points.mcap
// (PointCloud2), each with /tf_static and /odom (see sim/bag_recording.hpp); --dump-scans adds the
// simulated sweeps as PCD files per sensor.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <memory>

#include "../commands.hpp"
#include "../exit_codes.hpp"
#include "../output_folder.hpp"
#include "rigcal/core/pcd_io.hpp"
#include "rigcal/core/point_table.hpp"
#include "rigcal/sim/bag_recording.hpp"
#include "rigcal/sim/outputs.hpp"
#include "rigcal/sim/recording.hpp"
#include "rigcal/sim/simulation.hpp"

namespace rigcal::app {
namespace {

namespace fs = std::filesystem;

struct SimArgs {
  std::string scenario = "parking-lot";
  std::string out;
  std::optional<std::uint64_t> seed;
  bool dump_scans = false;
  bool list = false;
  int threads = 2;
  std::optional<double> perturb_translation_m, perturb_rotation_deg;
  std::optional<double> duration_s;  // simulate only the first seconds of the trajectory
  std::string format = "pcap";       // pcap, mcap or both
};

// Writes every simulated sweep as a PCD file under DIR/scans/<sensor>/.
class ScanDumper : public sim::SimulationSink {
 public:
  ScanDumper(const sim::Simulation& s, fs::path dir) : sim_(s), dir_(std::move(dir)) {}
  void onScan(sim::SimulatedScan&& scan) override {
    const fs::path dir = dir_ / sim_.scenario().sensors[scan.sensor].name;
    fs::create_directories(dir);
    char name[32];
    std::snprintf(name, sizeof name, "%06llu.pcd", static_cast<unsigned long long>(scan.scan.sequence));
    writePcd(dir / name, toTable(scan.scan));
    ++dumped_;
  }
  [[nodiscard]] std::uint64_t dumped() const { return dumped_; }

 private:
  const sim::Simulation& sim_;
  fs::path dir_;
  std::uint64_t dumped_ = 0;
};

void run(const SimArgs& a) {
  if (a.list) {
    const auto names = sim::builtinScenarioNames();
    std::size_t width = 0;
    for (const auto& n : names) width = std::max(width, n.size());
    for (const auto& n : names)
      std::cout << std::left << std::setw(int(width + 2)) << n << sim::loadScenario(n).description << '\n';
    return;
  }
  if (a.out.empty()) throw CommandFailed(kExitUsage, "sim: --out DIR is required");
  sim::Scenario scenario;
  try {
    scenario = sim::loadScenario(a.scenario);
  } catch (const sim::ScenarioError& e) {
    // A file that is not there is an input problem; a file that is wrong is a config problem.
    const bool is_path = a.scenario.find('/') != std::string::npos || fs::path(a.scenario).has_extension();
    throw CommandFailed(is_path && !fs::exists(a.scenario) ? kExitInput : kExitConfig, e.what());
  }
  if (a.seed) scenario.seed = *a.seed;
  if (a.perturb_translation_m) scenario.perturbation.translation_m = *a.perturb_translation_m;
  if (a.perturb_rotation_deg) scenario.perturbation.rotation_deg = *a.perturb_rotation_deg;
  const fs::path out(a.out);
  prepareOutputFolder(out);

  const auto t0 = std::chrono::steady_clock::now();
  std::unique_ptr<sim::Simulation> simulation;
  try {
    simulation = std::make_unique<sim::Simulation>(scenario);
  } catch (const std::invalid_argument& e) {
    throw CommandFailed(kExitConfig, "scenario '" + scenario.name + "': " + e.what());
  }
  const sim::Simulation& s = *simulation;
  const double setup_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::cout << "scenario '" << scenario.name << "', seed " << scenario.seed << ": " << s.sensorCount() << " lidars, "
            << std::fixed << std::setprecision(1) << toSeconds(s.trajectory().duration()) << " s, "
            << s.trajectory().length() << " m of driving; scene of " << s.scene().primitiveCount()
            << " primitives (" << std::setprecision(2) << setup_s << " s to build)\n";

  sim::writeTruthYaml(s, out / "truth.yaml");
  sim::writePosesCsv(s, out / "poses.csv");
  sim::writeRigFiles(s, out);
  std::cout << "wrote " << (out / "truth.yaml").string() << ", poses.csv, rig.yaml and the sensors' calibration files\n";

  auto encoders = sim::makeEncoders(s);
  std::vector<std::string> missing;
  for (std::size_t i = 0; i < s.sensorCount(); ++i)
    if (!encoders[i] && std::find(missing.begin(), missing.end(), scenario.sensors[i].model) == missing.end())
      missing.push_back(scenario.sensors[i].model);
  const bool want_pcap = a.format != "mcap", want_mcap = a.format != "pcap";
  const fs::path pcap = out / "recording.pcap";
  const fs::path packets_bag = out / "recording.mcap", points_bag = out / "recording_points.mcap";
  // Never leave a file that does not match this run.
  for (const auto& f : {pcap, packets_bag, points_bag}) {
    std::error_code ignored;  // absent is fine; a symlink is removed, never followed
    fs::remove(f, ignored);
  }
  if (!missing.empty()) {
    std::string models;
    for (const auto& m : missing) models += (models.empty() ? "" : ", ") + m;
    std::cout << (want_mcap ? "recording.pcap and recording.mcap" : "recording.pcap")
              << " NOT written: there is no packet encoder yet for " << models << "\n";
  }
  std::unique_ptr<ScanDumper> dumper;
  if (a.dump_scans) dumper = std::make_unique<ScanDumper>(s, out / "scans");
  std::unique_ptr<sim::BagRecording> bags;
  if (want_mcap)
    bags = std::make_unique<sim::BagRecording>(s, missing.empty() ? packets_bag : fs::path(), points_bag,
                                               bag::McapWriterOptions{}, dumper.get());
  sim::SimulationSink* sink = bags ? static_cast<sim::SimulationSink*>(bags.get()) : dumper.get();
  if (!missing.empty() && !sink) {
    std::cout << "physics not run: nothing to write (use --dump-scans for the simulated sweeps as PCD)\n";
    return;
  }
  sim::SimulationOptions options;
  options.threads = a.threads;
  options.build_scans = sink != nullptr && (dumper || want_mcap);
  if (a.duration_s) options.max_duration_ns = fromSeconds(*a.duration_s);
  if (a.duration_s) std::cout << "simulating the first " << *a.duration_s << " s only (--duration)\n";
  sim::SimulationStats st;
  if (missing.empty()) {
    const sim::RecordingResult r =
        sim::writeRecording(s, std::move(encoders), want_pcap ? pcap : fs::path(), options, sink, bags.get());
    st = r.stats;
    if (want_pcap)
      std::cout << "wrote " << pcap.string() << ": " << r.datagrams << " datagrams in " << r.frames << " frames\n";
  } else {
    st = s.run(*sink, options);
  }
  if (bags) {
    bags->close();
    if (missing.empty())
      std::cout << "wrote " << packets_bag.string() << ": " << bags->packetMessages()
                << " packet messages on /<sensor>/packets, /tf_static, /odom\n";
    std::cout << "wrote " << points_bag.string() << ": " << bags->cloudMessages()
              << " PointCloud2 on /<sensor>/points, /tf_static, /odom\n";
  }
  std::cout << std::setprecision(2) << "simulated " << st.firings << " firings, " << st.rays << " rays, "
            << st.returns << " returns, " << st.scans << " sweeps in " << st.total_seconds << " s ("
            << std::setprecision(1) << double(st.rays) / std::max(st.cast_seconds, 1e-9) / 1e6
            << " M rays/s casting on " << a.threads << " threads)\n";
  if (dumper) std::cout << "wrote " << dumper->dumped() << " sweeps under " << (out / "scans").string() << "\n";
}

}  // namespace

void addSimCommand(CLI::App& app) {
  auto* cmd = app.add_subcommand("sim", "Simulate a rig recording with ground truth (truth.yaml, poses.csv, rig.yaml)");
  auto a = std::make_shared<SimArgs>();
  cmd->add_option("--scenario", a->scenario, "Preset name (`rigcal sim --list` lists them) or a scenario YAML file")
      ->capture_default_str();
  cmd->add_option("--out", a->out, "Output folder (created if missing)");
  cmd->add_option("--seed", a->seed, "Seed (default: the scenario's)");
  cmd->add_option("--threads", a->threads, "Ray-casting threads (output does not depend on it)")
      ->check(CLI::Range(1, 64))
      ->capture_default_str();
  cmd->add_option("--perturb-translation", a->perturb_translation_m,
                  "rig.yaml: initial extrinsics off the truth by this many metres (default: the scenario's, 0.3)")
      ->check(CLI::Range(0.0, 10.0));
  cmd->add_option("--perturb-rotation", a->perturb_rotation_deg,
                  "rig.yaml: initial extrinsics off the truth by this many degrees (default: the scenario's, 5)")
      ->check(CLI::Range(0.0, 90.0));
  cmd->add_flag("--dump-scans", a->dump_scans, "Also write every simulated sweep as PCD under DIR/scans/<sensor>/");
  cmd->add_option("--duration", a->duration_s, "Simulate only the first S seconds of the scenario (default: all of it)")
      ->check(CLI::PositiveNumber);
  cmd->add_option("--format", a->format,
                  "pcap: recording.pcap; mcap: recording.mcap (packet messages) and recording_points.mcap "
                  "(PointCloud2), each with /tf_static and /odom; both: all three")
      ->check(CLI::IsMember({"pcap", "mcap", "both"}))
      ->capture_default_str();
  cmd->add_flag("--list", a->list, "List the preset scenarios and exit");
  cmd->footer(kExitCodesHelp);
  cmd->callback([a] { run(*a); });
}

}  // namespace rigcal::app
