#pragma once
// One simulated recording: the scenario's world (ground, trajectory, scene) and its run, which steps
// through time in chunks, schedules every sensor's firing sequences, casts them in parallel and hands
// them, in time order per sensor, to a sink (packet encoders, sweep builders, tests).
#include <cstdint>
#include <memory>
#include <vector>

#include "rigcal/sim/firing_scheduler.hpp"
#include "rigcal/sim/lidar_simulator.hpp"
#include "rigcal/sim/scenario.hpp"
#include "rigcal/sim/scene.hpp"
#include "rigcal/sim/simulated_scan.hpp"
#include "rigcal/sim/trajectory.hpp"

namespace rigcal::sim {

struct SimulationOptions {
  int threads = 2;
  TimeNs chunk_ns = 50 * kNsPerMs;
  bool build_scans = true;        // deliver SimulatedScans to the sink
  bool keep_truth_poses = false;  // fill SimulatedScan::T_world_sensor
  TimeNs max_duration_ns = -1;    // simulate only this much (−1: the whole trajectory)
};

/// Receives the simulation's output. Calls come from the thread that called run(), in time order per
/// sensor (sensors interleave chunk by chunk).
class SimulationSink {
 public:
  virtual ~SimulationSink() = default;
  virtual void onFirings(std::size_t /*sensor*/, const FiringBatch& /*batch*/) {}
  virtual void onScan(SimulatedScan&& /*scan*/) {}
  /// Every sensor's firings before `true_time` have been delivered.
  virtual void onChunkEnd(TimeNs /*true_time*/) {}
};

struct SimulationStats {
  std::uint64_t firings = 0, rays = 0, returns = 0, scans = 0;
  double cast_seconds = 0;  // wall time spent casting
  double total_seconds = 0;
};

class Simulation {
 public:
  /// Builds the world for scenario.seed. Throws std::invalid_argument on an inconsistent scenario.
  explicit Simulation(Scenario scenario);

  [[nodiscard]] const Scenario& scenario() const { return scenario_; }
  [[nodiscard]] const Scene& scene() const { return *scene_; }
  [[nodiscard]] const Trajectory& trajectory() const { return *trajectory_; }
  [[nodiscard]] std::size_t sensorCount() const { return scenario_.sensors.size(); }
  [[nodiscard]] const LidarModel& model(std::size_t sensor) const { return *models_.at(sensor); }
  [[nodiscard]] const FiringScheduler& scheduler(std::size_t sensor) const { return schedulers_.at(sensor); }
  /// True time of the trajectory's start and end.
  [[nodiscard]] TimeNs startTime() const { return scenario_.start_time_ns; }
  [[nodiscard]] TimeNs endTime() const { return scenario_.start_time_ns + trajectory_->duration(); }
  [[nodiscard]] Pose T_world_base(TimeNs true_time) const;
  [[nodiscard]] Pose T_world_sensor(std::size_t sensor, TimeNs true_time) const;
  [[nodiscard]] std::uint64_t sceneSeed() const { return scene_seed_; }

  SimulationStats run(SimulationSink& sink, const SimulationOptions& options = {}) const;

 private:
  Scenario scenario_;
  std::uint64_t scene_seed_ = 0;
  std::unique_ptr<Trajectory> trajectory_;
  std::unique_ptr<Scene> scene_;
  std::vector<const LidarModel*> models_;
  std::vector<FiringScheduler> schedulers_;
  std::vector<LidarSimulator> lidars_;
};

}  // namespace rigcal::sim
