// `rigcal sim --scenario NAME|FILE.yaml --out DIR [--seed N]`: a synthetic rig recording with ground
// truth. Writes truth.yaml, poses.csv, rig.yaml (+ the sensors' calibration/metadata files) and, when
// every sensor's model has a packet encoder, recording.pcap; --dump-scans adds the simulated sweeps as
// PCD files per sensor.
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <memory>

#include "../commands.hpp"
#include "../exit_codes.hpp"
#include "rigcal/core/pcd_io.hpp"
#include "rigcal/core/point_table.hpp"
#include "rigcal/sim/outputs.hpp"
#include "rigcal/sim/packet_encoder.hpp"
#include "rigcal/sim/recording_writer.hpp"
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
};

// Encodes every sensor's firings into the capture and/or dumps sweeps, as the run produces them.
class OutputSink : public sim::SimulationSink {
 public:
  OutputSink(const sim::Simulation& s, std::vector<std::unique_ptr<sim::PacketEncoder>> encoders,
             std::unique_ptr<sim::RecordingWriter> recording, std::optional<fs::path> scans_dir)
      : sim_(s), encoders_(std::move(encoders)), recording_(std::move(recording)), scans_dir_(std::move(scans_dir)) {}

  void onFirings(std::size_t sensor, const sim::FiringBatch& batch) override {
    if (!recording_) return;
    encoders_[sensor]->add(batch, packets_);
    recording_->add(sensor, packets_);
  }
  void onChunkEnd(TimeNs true_time) override {
    // Packets still to come carry a firing from a later chunk, so they are sent after true_time.
    if (recording_) recording_->flushUntil(true_time);
  }
  void onScan(sim::SimulatedScan&& scan) override {
    if (!scans_dir_) return;
    const fs::path dir = *scans_dir_ / sim_.scenario().sensors[scan.sensor].name;
    fs::create_directories(dir);
    char name[32];
    std::snprintf(name, sizeof name, "%06llu.pcd", static_cast<unsigned long long>(scan.scan.sequence));
    writePcd(dir / name, toTable(scan.scan));
    ++dumped_;
  }
  void finish() {
    if (!recording_) return;
    for (std::size_t i = 0; i < encoders_.size(); ++i) {
      encoders_[i]->finish(packets_);
      recording_->add(i, packets_);
    }
    recording_->finish();
  }
  [[nodiscard]] std::uint64_t dumped() const { return dumped_; }

 private:
  const sim::Simulation& sim_;
  std::vector<std::unique_ptr<sim::PacketEncoder>> encoders_;
  std::unique_ptr<sim::RecordingWriter> recording_;
  std::optional<fs::path> scans_dir_;
  std::vector<sim::EncodedPacket> packets_;
  std::uint64_t dumped_ = 0;
};

sim::RecordingSensor endpointsOf(const sim::SensorSpec& s, const sim::LidarModel& m) {
  sim::RecordingSensor r;
  r.source.address = sim::ipv4FromText(s.address);
  r.source.port = s.port;
  r.source.mac = sim::macForAddress(r.source.address);
  r.clock_offset_ns = s.clock_offset_ns;
  if (m.vendor == sim::LidarVendor::kOuster) {
    // Ouster sends unicast to the configured host: here the .100 host of the sensor's /24.
    r.destination.address = (r.source.address & 0xffffff00u) | 100u;
    r.destination.mac = sim::macForAddress(r.destination.address);
  } else {
    // Velodyne and Hesai broadcast by default.
    r.destination.address = 0xffffffffu;
    r.destination.mac = {0xff, 0xff, 0xff, 0xff, 0xff, 0xff};
  }
  r.destination.port = s.port;
  return r;
}

void run(const SimArgs& a) {
  if (a.list) {
    for (const auto& n : sim::builtinScenarioNames()) {
      const sim::Scenario sc = sim::loadScenario(n);
      std::cout << std::left << std::setw(14) << n << sc.description << '\n';
    }
    return;
  }
  if (a.out.empty()) throw CommandFailed(kExitUsage, "sim: --out DIR is required");
  sim::Scenario scenario;
  try {
    scenario = sim::loadScenario(a.scenario);
  } catch (const sim::ScenarioError& e) {
    throw CommandFailed(kExitConfig, e.what());
  }
  if (a.seed) scenario.seed = *a.seed;
  const fs::path out(a.out);
  std::error_code ec;
  fs::create_directories(out, ec);
  if (ec) throw CommandFailed(kExitInput, out.string() + ": cannot create the output folder: " + ec.message());

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

  std::vector<std::unique_ptr<sim::PacketEncoder>> encoders;
  std::vector<std::string> missing;
  std::vector<sim::RecordingSensor> endpoints;
  for (std::size_t i = 0; i < s.sensorCount(); ++i) {
    const auto& spec = scenario.sensors[i];
    encoders.push_back(sim::makePacketEncoder(s.model(i), {spec.name, spec.port, false, scenario.seed}));
    if (!encoders.back() && std::find(missing.begin(), missing.end(), spec.model) == missing.end())
      missing.push_back(spec.model);
    endpoints.push_back(endpointsOf(spec, s.model(i)));
  }
  std::unique_ptr<sim::RecordingWriter> recording;
  const fs::path pcap = out / "recording.pcap";
  if (missing.empty()) {
    recording = std::make_unique<sim::RecordingWriter>(pcap, endpoints, sim::hashKeys(scenario.seed, 0x6e6963ULL));
  } else {
    std::string models;
    for (const auto& m : missing) models += (models.empty() ? "" : ", ") + m;
    if (fs::exists(pcap)) fs::remove(pcap);  // never leave a capture that does not match this run
    std::cout << "recording.pcap NOT written: there is no packet encoder yet for " << models
              << " (the vendor wire-format encoders are phase 2 of the simulator)\n";
  }
  std::optional<fs::path> scans_dir;
  if (a.dump_scans) scans_dir = out / "scans";
  if (!recording && !scans_dir) {
    std::cout << "physics not run: nothing to write (use --dump-scans for the simulated sweeps as PCD)\n";
    return;
  }
  OutputSink sink(s, std::move(encoders), std::move(recording), scans_dir);
  sim::SimulationOptions options;
  options.threads = a.threads;
  options.build_scans = bool(scans_dir);
  const sim::SimulationStats st = s.run(sink, options);
  sink.finish();
  std::cout << std::setprecision(2) << "simulated " << st.firings << " firings, " << st.rays << " rays, "
            << st.returns << " returns, " << st.scans << " sweeps in " << st.total_seconds << " s ("
            << std::setprecision(1) << double(st.rays) / std::max(st.cast_seconds, 1e-9) / 1e6
            << " M rays/s casting on " << a.threads << " threads)\n";
  if (scans_dir) std::cout << "wrote " << sink.dumped() << " sweeps under " << scans_dir->string() << "\n";
  if (missing.empty()) std::cout << "wrote " << pcap.string() << "\n";
}

}  // namespace

void addSimCommand(CLI::App& app) {
  auto* cmd = app.add_subcommand("sim", "Simulate a rig recording with ground truth (truth.yaml, poses.csv, rig.yaml)");
  auto a = std::make_shared<SimArgs>();
  cmd->add_option("--scenario", a->scenario, "Preset name (parking-lot, street, lost, pose) or a scenario YAML file")
      ->capture_default_str();
  cmd->add_option("--out", a->out, "Output folder (created if missing)");
  cmd->add_option("--seed", a->seed, "Seed (default: the scenario's)");
  cmd->add_option("--threads", a->threads, "Ray-casting threads (output does not depend on it)")
      ->check(CLI::Range(1, 64))
      ->capture_default_str();
  cmd->add_flag("--dump-scans", a->dump_scans, "Also write every simulated sweep as PCD under DIR/scans/<sensor>/");
  cmd->add_flag("--list", a->list, "List the preset scenarios and exit");
  cmd->footer(kExitCodesHelp);
  cmd->callback([a] { run(*a); });
}

}  // namespace rigcal::app
