#pragma once
// Runs simulator scenarios (shortened in code) through the Pipeline in process, and the truth to check
// the result against.
#include <filesystem>
#include <memory>
#include <mutex>
#include <vector>

#include "rigcal/config/rig_config.hpp"
#include "rigcal/pipeline/pipeline.hpp"
#include "rigcal/sim/outputs.hpp"
#include "rigcal/sim/simulation.hpp"
#include "test_data.hpp"

namespace rigcal::pipeline::test {

/// rig.yaml for the simulation (initial extrinsics perturbed as the scenario says), with its parameters.
inline config::RigConfig rigFor(const sim::Simulation& sim, const std::filesystem::path& dir) {
  sim::writeRigFiles(sim, dir);
  return config::loadRigConfig(dir / "rig.yaml");
}

/// Everything a run produced.
struct RunResult {
  std::vector<std::shared_ptr<const CalibrationDataset>> datasets;
  /// Each dataset's use_count() as the callback received it: how many references the pipeline kept.
  std::vector<long> use_counts_at_hand_over;
  MappingResult mapping;
  PipelineProgress progress;
  PipelineStats stats;
  std::vector<Shortfall> shortfalls;
};

/// Feeds every simulated scan into a pipeline as the simulation produces it.
class Feeder : public sim::SimulationSink {
 public:
  explicit Feeder(Pipeline& p) : pipeline_(p) {}
  void onScan(sim::SimulatedScan&& s) override { pipeline_.push(std::move(s.scan)); }

 private:
  Pipeline& pipeline_;
};

/// Runs a pipeline over what `feed(pipeline)` pushes, finishes it and collects everything it produced.
template <class Feed>
RunResult runPipeline(const config::RigConfig& rig, const PipelineOptions& options, Feed&& feed) {
  RunResult r;
  std::mutex m;
  Pipeline pipeline(rig, options, [&](std::shared_ptr<const CalibrationDataset> d) {
    std::lock_guard lock(m);
    r.use_counts_at_hand_over.push_back(d.use_count());
    r.datasets.push_back(std::move(d));
  });
  feed(pipeline);
  pipeline.finish();
  r.mapping = pipeline.mapping(/*with_dense_cloud=*/true);
  r.progress = pipeline.progress();
  r.stats = pipeline.stats();
  r.shortfalls = pipeline.shortfalls();
  return r;
}

/// Simulates `duration_s` of the scenario straight into an offline pipeline.
inline RunResult runInProcess(const sim::Simulation& sim, const config::RigConfig& rig, double duration_s,
                              PipelineOptions options = {}) {
  return runPipeline(rig, options, [&](Pipeline& pipeline) {
    Feeder feeder(pipeline);
    sim::SimulationOptions so;
    so.max_duration_ns = fromSeconds(duration_s);
    sim.run(feeder, so);
  });
}

/// The true pose of sensor `index` at its own clock's `stamp`.
inline Pose truthAt(const sim::Simulation& sim, std::size_t index, TimeNs stamp) {
  return sim.T_world_sensor(index, stamp - sim.scenario().sensors[index].clock_offset_ns);
}

}  // namespace rigcal::pipeline::test
