#include "rigcal/sim/simulation.hpp"

#include <algorithm>
#include <chrono>

#include "rigcal/core/parallel.hpp"
#include "rigcal/sim/random.hpp"

namespace rigcal::sim {
namespace {

constexpr std::uint64_t kSceneTag = 0x7363656e65ULL;  // "scene"
constexpr std::uint64_t kNoiseTag = 0x6e6f697365ULL;  // "noise"
constexpr std::size_t kFiringsPerTask = 96;

double secondsSince(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

}  // namespace

Simulation::Simulation(Scenario scenario) : scenario_(std::move(scenario)) {
  scene_seed_ = scenario_.scene.seed.value_or(hashKeys(scenario_.seed, kSceneTag));
  // Ground first (the vehicle rests on it), then the drive, then the scene around the drive.
  Ground ground = makeGround(scenario_.scene, scene_seed_);
  trajectory_ = std::make_unique<Trajectory>(scenario_.trajectory, ground);
  scene_ = std::make_unique<Scene>(generateScene(scenario_.scene, scene_seed_, ground, trajectory_->path(0.5)),
                                   scenario_.scene.grid_cell_m);
  for (std::size_t i = 0; i < scenario_.sensors.size(); ++i) {
    const SensorSpec& s = scenario_.sensors[i];
    models_.push_back(&lidarModel(s.model));
    schedulers_.emplace_back(*models_.back(), s.scan_phase_deg, s.clock_offset_ns, startTime());
    lidars_.emplace_back(*models_.back(), *scene_, *trajectory_, startTime(), s.T_base_sensor, scenario_.noise,
                         hashKeys(scenario_.seed, kNoiseTag, i));
  }
}

Pose Simulation::T_world_base(TimeNs true_time) const { return trajectory_->pose(true_time - startTime()); }

Pose Simulation::T_world_sensor(std::size_t sensor, TimeNs true_time) const {
  return T_world_base(true_time) * scenario_.sensors.at(sensor).T_base_sensor;
}

SimulationStats Simulation::run(SimulationSink& sink, const SimulationOptions& options) const {
  const auto t_start = std::chrono::steady_clock::now();
  SimulationStats stats;
  const std::size_t n = sensorCount();
  std::vector<SweepBuilder> sweeps;
  if (options.build_scans) {
    for (std::size_t i = 0; i < n; ++i) {
      SweepBuilder::PoseAt truth;
      if (options.keep_truth_poses) truth = [this, i](TimeNs t) { return T_world_sensor(i, t); };
      sweeps.emplace_back(i, scenario_.sensors[i].name, *models_[i], truth, [&sink, &stats](SimulatedScan&& s) {
        ++stats.scans;
        sink.onScan(std::move(s));
      });
    }
  }
  const TimeNs end = options.max_duration_ns >= 0 ? std::min(endTime(), startTime() + options.max_duration_ns) : endTime();
  std::vector<FiringBatch> batches(n);
  struct Task {
    std::size_t sensor, begin, end;
  };
  std::vector<Task> tasks;
  std::vector<CastStats> task_stats;
  for (TimeNs t = startTime(); t < end; t += options.chunk_ns) {
    const TimeNs chunk_end = std::min(t + options.chunk_ns, end);
    tasks.clear();
    for (std::size_t i = 0; i < n; ++i) {
      FiringBatch& b = batches[i];
      b.clear();
      b.beams = models_[i]->beamCount();
      schedulers_[i].schedule(t, chunk_end, b.firings);
      // A sensor in an outage sends nothing at all.
      const auto& outages = scenario_.sensors[i].outages;
      if (!outages.empty()) {
        std::erase_if(b.firings, [&](const SimFiring& f) {
          const double rel = toSeconds(f.true_time_ns - startTime());
          return std::any_of(outages.begin(), outages.end(), [&](const Outage& o) { return rel >= o.from_s && rel < o.to_s; });
        });
      }
      b.returns.resize(b.size() * b.beams);
      b.points.resize(b.size() * b.beams);
      for (std::size_t f = 0; f < b.size(); f += kFiringsPerTask) tasks.push_back({i, f, std::min(b.size(), f + kFiringsPerTask)});
    }
    task_stats.assign(tasks.size(), CastStats{});
    const auto t_cast = std::chrono::steady_clock::now();
    parallelFor(tasks.size(), options.threads, [&](std::size_t k) {
      const Task& task = tasks[k];
      lidars_[task.sensor].cast(batches[task.sensor], task.begin, task.end, task_stats[k]);
    });
    stats.cast_seconds += secondsSince(t_cast);
    for (const CastStats& s : task_stats) {
      stats.rays += s.rays;
      stats.returns += s.returns;
    }
    for (std::size_t i = 0; i < n; ++i) {
      stats.firings += batches[i].size();
      sink.onFirings(i, batches[i]);
      if (options.build_scans) sweeps[i].add(batches[i]);
    }
    sink.onChunkEnd(chunk_end);
  }
  for (auto& s : sweeps) s.flush();
  stats.total_seconds = secondsSince(t_start);
  return stats;
}

}  // namespace rigcal::sim
