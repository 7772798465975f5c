// Simulator throughput. Run pinned, e.g.
//   taskset -c 0   build/bench/sim_bench --benchmark_filter='Cast|Physics.*threads:1'
//   taskset -c 0,1 build/bench/sim_bench
// Reported: rays/s of the ray caster on the parking-lot scene (single rays, and whole firings with
// 1 and 2 threads), and the wall time of the parking-lot recording's physics.
// Encoders: packets/s and firings/s of each vendor encoder on 0.5 s of recorded firings, next to the
// physics (casting) of the same firings on one thread, the baseline they must stay far below; and
// 2 s of the parking-lot recording (physics + encoders + pcap) next to its physics alone.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <filesystem>
#include <map>
#include <memory>
#include <string>
#include <unistd.h>

#include "rigcal/sim/packet_encoder.hpp"
#include "rigcal/sim/recording.hpp"
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

// --- encoders ------------------------------------------------------------------------------------

double p99(const std::vector<double>& v) {
  std::vector<double> s = v;
  std::sort(s.begin(), s.end());
  return s[std::min(s.size() - 1, std::size_t(0.99 * double(s.size() - 1) + 0.5))];
}

// One lidar of `model` driving through the parking lot.
Scenario oneLidar(const std::string& model) {
  return parseScenario("scenario: bench\nseed: 3\nrig:\n  mapping_lidar: l\n  sensors:\n"
                       "    - {name: l, model: " + model + ", address: 10.0.0.2, port: 2368, extrinsic: {z: 1.9}}\n"
                       "scene: {layout: parking-lot}\ntrajectory:\n  start: {x: -20, y: -6, speed_kmh: 8}\n"
                       "  segments: [{type: cruise, duration: 1}]\n", "bench");
}

struct BatchRecorder : SimulationSink {
  std::vector<FiringBatch> batches;
  void onFirings(std::size_t, const FiringBatch& b) override { batches.push_back(b); }
};

struct Recorded {
  std::unique_ptr<Simulation> sim;
  std::vector<FiringBatch> batches;
  std::size_t firings = 0;
};

const Recorded& recorded(const std::string& model) {
  static std::map<std::string, Recorded> cache;
  Recorded& r = cache[model];
  if (!r.sim) {
    r.sim = std::make_unique<Simulation>(oneLidar(model));
    BatchRecorder rec;
    SimulationOptions o;
    o.build_scans = false;
    o.max_duration_ns = kNsPerSec / 2;
    r.sim->run(rec, o);
    r.batches = std::move(rec.batches);
    for (const auto& b : r.batches) r.firings += b.size();
  }
  return r;
}

const char* const kModels[] = {"VLP-16", "VLP-32C", "VLS-128", "OS1-64", "OS1-128", "PandarXT32"};

void BM_Encode(benchmark::State& state) {
  const std::string model = kModels[state.range(0)];
  state.SetLabel(model);
  const Recorded& r = recorded(model);
  std::vector<EncodedPacket> out;
  std::size_t packets = 0;
  for (auto _ : state) {
    auto enc = makePacketEncoder(r.sim->model(0), {"l", 2368, false, 1});
    packets = 0;
    for (const auto& b : r.batches) {
      enc->add(b, out);
      packets += out.size();
      out.clear();
    }
    enc->finish(out);
    packets += out.size();
    out.clear();
  }
  state.counters["packets/s"] = benchmark::Counter(double(packets) * double(state.iterations()), benchmark::Counter::kIsRate);
  state.counters["firings/s"] = benchmark::Counter(double(r.firings) * double(state.iterations()), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_Encode)->DenseRange(0, 5)->Unit(benchmark::kMillisecond)->UseRealTime()->Repetitions(15)
    ->ReportAggregatesOnly(true)->ComputeStatistics("p99", p99);

// Baseline: casting the same 0.5 s of firings on one thread.
void BM_CastSameFirings(benchmark::State& state) {
  const std::string model = kModels[state.range(0)];
  state.SetLabel(model);
  const Recorded& r = recorded(model);
  SimulationOptions o;
  o.threads = 1;
  o.build_scans = false;
  o.max_duration_ns = kNsPerSec / 2;
  SimulationStats last;
  for (auto _ : state) {
    NullSink sink;
    last = r.sim->run(sink, o);
  }
  state.counters["rays/s"] = benchmark::Counter(double(last.rays) * double(state.iterations()), benchmark::Counter::kIsRate);
  state.counters["firings/s"] = benchmark::Counter(double(last.firings) * double(state.iterations()), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_CastSameFirings)->DenseRange(0, 5)->Unit(benchmark::kMillisecond)->UseRealTime()->Repetitions(5)
    ->ReportAggregatesOnly(true)->ComputeStatistics("p99", p99);

// 2 s of the parking-lot recording, physics + encoders + pcap (compare with BM_Physics2s).
void BM_Recording2s(benchmark::State& state) {
  const Simulation& sim = parkingLot();
  SimulationOptions opt;
  opt.threads = int(state.range(0));
  opt.build_scans = false;
  opt.max_duration_ns = 2 * kNsPerSec;
  const std::filesystem::path pcap =
      std::filesystem::temp_directory_path() / ("sim_bench_" + std::to_string(::getpid()) + ".pcap");
  RecordingResult last;
  for (auto _ : state) last = writeRecording(sim, makeEncoders(sim), pcap, opt);
  std::filesystem::remove(pcap);
  state.counters["rays/s"] = benchmark::Counter(double(last.stats.rays) * double(state.iterations()), benchmark::Counter::kIsRate);
  state.counters["datagrams/s"] = benchmark::Counter(double(last.datagrams) * double(state.iterations()), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_Recording2s)->ArgName("threads")->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime()
    ->Repetitions(3)->ReportAggregatesOnly(true)->ComputeStatistics("p99", p99);

}  // namespace

BENCHMARK_MAIN();
