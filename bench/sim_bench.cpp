// Simulator throughput. Run pinned, e.g.
//   taskset -c 0   build/bench/sim_bench --benchmark_filter='Cast|Physics.*threads:1'
//   taskset -c 0,1 build/bench/sim_bench
// Reported: rays/s of the ray caster on the parking-lot scene (single rays, and whole firings with
// 1 and 2 threads), and the wall time of the parking-lot recording's physics.
#include <benchmark/benchmark.h>

#include <memory>

#include "rigcal/sim/simulation.hpp"

namespace {

using namespace rigcal;
using namespace rigcal::sim;

const Simulation& parkingLot() {
  static const auto sim = std::make_unique<Simulation>(loadScenario("parking-lot"));
  return *sim;
}

// The rays of every beam of the OS1-64 over one sweep, from the vehicle's pose 10 s into the drive.
std::vector<Ray> sweepRays(const Simulation& sim) {
  const std::size_t top = sim.scenario().sensorIndex(sim.scenario().mapping_lidar);
  const LidarModel& m = sim.model(top);
  const Pose T = sim.T_world_sensor(top, sim.startTime() + 10 * kNsPerSec);
  std::vector<Ray> rays;
  for (int c = 0; c < 1024; ++c)
    for (std::size_t b = 0; b < m.beamCount(); ++b) {
      const double az = 360.0 * c / 1024.0;
      rays.push_back({T * m.beamOrigin(az), T.linear() * m.direction(b, az)});
    }
  return rays;
}

void BM_CastSingleRays(benchmark::State& state) {
  const Simulation& sim = parkingLot();
  const std::vector<Ray> rays = sweepRays(sim);
  std::size_t hits = 0;
  for (auto _ : state) {
    for (const Ray& r : rays) {
      Hit h;
      hits += sim.scene().cast(r, 0.0, 120.0, h);
    }
  }
  benchmark::DoNotOptimize(hits);
  state.counters["rays/s"] = benchmark::Counter(double(state.iterations() * rays.size()), benchmark::Counter::kIsRate);
  state.counters["hit_ratio"] = double(hits) / double(state.iterations() * rays.size());
}
BENCHMARK(BM_CastSingleRays)->Unit(benchmark::kMillisecond)->UseRealTime();

struct NullSink : SimulationSink {};

// All sensors of parking-lot for 2 s of the drive (firings, poses, noise, no sweeps).
void BM_Physics2s(benchmark::State& state) {
  const Simulation& sim = parkingLot();
  SimulationOptions opt;
  opt.threads = int(state.range(0));
  opt.build_scans = false;
  opt.max_duration_ns = 2 * kNsPerSec;
  SimulationStats last;
  for (auto _ : state) {
    NullSink sink;
    last = sim.run(sink, opt);
  }
  state.counters["rays/s"] = benchmark::Counter(double(last.rays) * double(state.iterations()), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_Physics2s)->ArgName("threads")->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();

// The whole parking-lot recording's physics, with sweeps built (what `rigcal sim` does before encoding).
void BM_PhysicsParkingLotFull(benchmark::State& state) {
  const Simulation& sim = parkingLot();
  SimulationOptions opt;
  opt.threads = int(state.range(0));
  SimulationStats last;
  for (auto _ : state) {
    NullSink sink;
    last = sim.run(sink, opt);
  }
  state.counters["rays"] = double(last.rays);
  state.counters["rays/s"] = benchmark::Counter(double(last.rays) * double(state.iterations()), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_PhysicsParkingLotFull)->ArgName("threads")->Arg(1)->Arg(2)->Iterations(1)->Unit(benchmark::kSecond)->UseRealTime();

void BM_SceneGeneration(benchmark::State& state) {
  for (auto _ : state) {
    Simulation sim(loadScenario("parking-lot"));
    benchmark::DoNotOptimize(sim.scene().primitiveCount());
  }
}
BENCHMARK(BM_SceneGeneration)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
