// The lidar-lidar ensemble on simulator data (parking-lot, a 10 s stretch, 4 frames, guess 0.3 m / 5° off):
// time per registrator on one frame (our NDT / GICP / ICP coarse, fine, ultra-fine against PCL 1.13's NDT,
// GICP and ICP with upstream's settings, the baseline upstream runs), the augmented-target build (the first
// frame's box crop, a later frame's near crop, and the crop alone), the all-frames score, batched ICP, and
// a whole calibrateLidarLidar run under the default 10 s deadline (without one, the exhaustive pass runs
// every registrator from every candidate: ~870 registrations).
// Run pinned: taskset -c 0,1 calibration_bench --benchmark_repetitions=10 (median and p99 are reported).
#include <benchmark/benchmark.h>
#include <sys/resource.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <memory>
#include <vector>

#include <pcl/point_cloud.h>
#include <pcl/point_types.h>
#include <pcl/registration/gicp.h>
#include <pcl/registration/icp.h>
#include <pcl/registration/ndt.h>

#include "../tests/calib/lidar_lidar_sim_dataset.hpp"
#include "rigcal/calib/lidar_lidar/augmented_target.hpp"
#include "rigcal/calib/lidar_lidar/calibration_score.hpp"
#include "rigcal/calib/lidar_lidar/calibration_source.hpp"
#include "rigcal/calib/lidar_lidar/ensemble_plan.hpp"
#include "rigcal/calib/lidar_lidar/lidar_lidar_calibration.hpp"

namespace {

using namespace rigcal;
using PclCloud = pcl::PointCloud<pcl::PointXYZ>;

struct Fixture {
  test::SimDatasets data;
  std::vector<registration::PointCloud> sources;
  std::vector<std::shared_ptr<const registration::Target>> targets;
  PclCloud::Ptr pcl_source, pcl_target;
  Pose truth;
};

const Fixture& fixture() {
  static const std::unique_ptr<Fixture> f = [] {
    auto fx = std::make_unique<Fixture>();
    fx->data = test::buildSimDatasets({});
    const auto& d = fx->data.datasets.front();
    fx->truth = fx->data.truth_T_mapping_calib.at(d.calibration_sensor);
    for (std::size_t i = 0; i < d.frames.size(); ++i) {
      calib::SourceOptions so;
      so.num_threads = 2;
      fx->sources.push_back(calib::buildSource(*d.frames[i].deskewed, fx->data.params, so));
      calib::AugmentedTargetOptions to;
      to.num_threads = 2;
      fx->targets.push_back(calib::buildAugmentedTarget(d, i, fx->sources.back(), fx->data.params, to).target);
    }
    const auto toPcl = [](const registration::PointCloud& c) {
      PclCloud::Ptr out(new PclCloud);
      for (const auto& p : c.points) out->push_back(pcl::PointXYZ(float(p.x()), float(p.y()), float(p.z())));
      return out;
    };
    fx->pcl_source = toPcl(fx->sources.front());
    fx->pcl_target = toPcl(fx->targets.front()->cloud());
    return fx;
  }();
  return *f;
}

void setErrors(benchmark::State& state, const Pose& T) {
  const auto& f = fixture();
  state.counters["err_mm"] = 1000.0 * (T.translation() - f.truth.translation()).norm();
  state.counters["err_deg"] = rad2deg(rotationAngleBetween(T, f.truth));
}

void ours(benchmark::State& state, calib::Registrator r, int threads) {
  const auto& f = fixture();
  const auto& d = f.data.datasets.front();
  registration::RegistrationResult res;
  for (auto _ : state) {
    res = calib::runRegistrator(r, *f.targets.front(), f.sources.front(), d.T_mapping_calib_guess, f.data.params,
                                threads, registration::Deadline::never());
    benchmark::DoNotOptimize(res);
  }
  state.counters["iterations"] = res.iterations;
  setErrors(state, res.T_target_source);
}

template <class Reg>
void runPcl(benchmark::State& state, Reg& reg) {
  const auto& f = fixture();
  reg.setMaximumIterations(f.data.params.solver_iterations);
  PclCloud out;
  for (auto _ : state) {
    reg.setInputTarget(f.pcl_target);  // upstream sets the target per frame: its build is part of the cost
    reg.setInputSource(f.pcl_source);
    reg.align(out, f.data.datasets.front().T_mapping_calib_guess.matrix().cast<float>());
  }
  setErrors(state, Pose(reg.getFinalTransformation().template cast<double>()));
}

void pclNdt(benchmark::State& state) {
  pcl::NormalDistributionsTransform<pcl::PointXYZ, pcl::PointXYZ> reg;
  reg.setResolution(1.0);
  reg.setStepSize(0.1);
  reg.setOulierRatio(0.55);
  reg.setTransformationEpsilon(0.1);  // upstream's
  runPcl(state, reg);
}

void pclGicp(benchmark::State& state) {
  pcl::GeneralizedIterativeClosestPoint<pcl::PointXYZ, pcl::PointXYZ> reg;
  reg.setMaxCorrespondenceDistance(0.5);
  runPcl(state, reg);
}

void pclIcp(benchmark::State& state, double max_corr) {
  pcl::IterativeClosestPoint<pcl::PointXYZ, pcl::PointXYZ> reg;
  reg.setMaxCorrespondenceDistance(max_corr);
  runPcl(state, reg);
}

// A frame's target build: the first frame's crops the box under the initial guess; a later frame's (`near`)
// keeps only the mapping points near the source under the guess and an estimate (here the truth, which the
// first frame's ensemble comes within millimetres of).
void buildTargets(benchmark::State& state, bool near) {
  const auto& f = fixture();
  const auto& d = f.data.datasets.front();
  calib::AugmentedTargetOptions to;
  to.num_threads = int(state.range(0));
  if (near) to.near_poses = {d.T_mapping_calib_guess, f.truth};
  to.near_radius = calib::nearTargetRadius(f.data.params);
  std::size_t points = 0;
  for (auto _ : state) {
    const auto t = calib::buildAugmentedTarget(d, 0, f.sources.front(), f.data.params, to);
    points = t.target->size();
  }
  state.counters["target_points"] = double(points);
}
void targetBuild(benchmark::State& state) { buildTargets(state, false); }
void targetBuildNear(benchmark::State& state) { buildTargets(state, true); }

// The crop and voxels alone (no Target), box or near.
void targetCrop(benchmark::State& state) {
  const auto& f = fixture();
  const auto& d = f.data.datasets.front();
  calib::AugmentedTargetOptions to;
  if (state.range(0) != 0) to.near_poses = {d.T_mapping_calib_guess, f.truth};
  to.near_radius = calib::nearTargetRadius(f.data.params);
  std::size_t points = 0;
  for (auto _ : state) points = calib::augmentedCloud(d, 1, f.sources[1], f.data.params, to).size();
  state.counters["target_points"] = double(points);
}

void scoreAll(benchmark::State& state) {
  const auto& f = fixture();
  std::vector<registration::SourceTarget> pairs;
  for (std::size_t i = 0; i < f.sources.size(); ++i) pairs.push_back({&f.sources[i], f.targets[i].get()});
  const std::size_t stride = calib::scoreStride(pairs, 60000);
  for (auto _ : state)
    benchmark::DoNotOptimize(calib::scoreAllFrames(pairs, f.truth, 0.1, stride, int(state.range(0))));
  state.counters["stride"] = double(stride);
}

void batched(benchmark::State& state) {
  const auto& f = fixture();
  std::vector<registration::SourceTarget> pairs;
  for (std::size_t i = 0; i < f.sources.size(); ++i) pairs.push_back({&f.sources[i], f.targets[i].get()});
  registration::RegistrationResult res;
  for (auto _ : state) {
    Pose T = f.data.datasets.front().T_mapping_calib_guess;
    for (const double dist : calib::batchedDistances(f.data.params)) {
      res = calib::runBatched(pairs, T, dist, f.data.params, int(state.range(0)), registration::Deadline::never());
      T = res.T_target_source;
    }
  }
  setErrors(state, res.T_target_source);
}

void wholeRun(benchmark::State& state) {
  const auto& f = fixture();
  calib::LidarLidarOptions o;
  o.num_threads = int(state.range(0));
  calib::LidarLidarResult r;
  for (auto _ : state)
    r = calib::calibrateLidarLidar(f.data.datasets.front(), f.data.params,
                                   registration::Deadline::after(std::chrono::duration_cast<std::chrono::nanoseconds>(
                                       std::chrono::duration<double>(f.data.params.calibration_deadline_s))),
                                   o);
  state.counters["runs"] = double(r.runs.size());
  state.counters["regs_per_s"] = double(r.runs.size()) / std::max(r.seconds, 1e-9);  // of calibration time
  state.counters["deadline_reached"] = r.deadline_reached;
  state.counters["score_mm2"] = r.final_score.value * 1e6;  // what the ensemble minimises
  setErrors(state, r.T_mapping_calib);
}

double processCpuSeconds() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return double(u.ru_utime.tv_sec + u.ru_stime.tv_sec) + 1e-6 * double(u.ru_utime.tv_usec + u.ru_stime.tv_usec);
}

// What the whole plan costs without a deadline and without the exhaustive pass (every frame's target, its
// ensemble, the batched chain, the re-deskew): CPU seconds of every thread (getrusage), so that a loaded
// machine does not blur it, and registrations per CPU second.
void fullPlan(benchmark::State& state) {
  const auto& f = fixture();
  calib::LidarLidarOptions o;
  o.num_threads = int(state.range(0));
  o.exhaustive = false;
  calib::LidarLidarResult r;
  double cpu = 0.0;
  for (auto _ : state) {
    const double c0 = processCpuSeconds();
    r = calib::calibrateLidarLidar(f.data.datasets.front(), f.data.params, registration::Deadline::never(), o);
    cpu = processCpuSeconds() - c0;
  }
  state.counters["runs"] = double(r.runs.size());
  state.counters["cpu_s"] = cpu;
  state.counters["regs_per_cpu_s"] = double(r.runs.size()) / std::max(cpu, 1e-9);
  state.counters["frames"] = double(r.frames_used.size());
  setErrors(state, r.T_mapping_calib);
}

double p99(const std::vector<double>& v) {
  std::vector<double> s = v;
  std::sort(s.begin(), s.end());
  return s.empty() ? 0.0 : s[std::min(s.size() - 1, std::size_t(std::ceil(0.99 * double(s.size()))) - 1)];
}

template <class B>
void add(B* b) {
  b->Unit(benchmark::kMillisecond)->UseRealTime()->ComputeStatistics("p99", p99);
}

}  // namespace

int main(int argc, char** argv) {
  using calib::Registrator;
  for (const int threads : {1, 2}) {
    for (const auto r : calib::perFrameRegistrators()) {
      const std::string name = std::string("ours/") + calib::toString(r) + "/threads:" + std::to_string(threads);
      add(benchmark::RegisterBenchmark(name.c_str(), [r, threads](benchmark::State& s) { ours(s, r, threads); }));
    }
  }
  add(benchmark::RegisterBenchmark("pcl/ndt", pclNdt));
  add(benchmark::RegisterBenchmark("pcl/gicp", pclGicp));
  add(benchmark::RegisterBenchmark("pcl/icp_coarse", [](benchmark::State& s) { pclIcp(s, 0.5); }));
  add(benchmark::RegisterBenchmark("pcl/icp_fine", [](benchmark::State& s) { pclIcp(s, 0.1); }));
  add(benchmark::RegisterBenchmark("ours/target_build", targetBuild)->Arg(1)->Arg(2));
  add(benchmark::RegisterBenchmark("ours/target_build_near", targetBuildNear)->Arg(1)->Arg(2));
  add(benchmark::RegisterBenchmark("ours/target_crop", targetCrop)->ArgName("near")->Arg(0)->Arg(1));
  add(benchmark::RegisterBenchmark("ours/score_all_frames", scoreAll)->Arg(1)->Arg(2));
  add(benchmark::RegisterBenchmark("ours/batched_icp_chain", batched)->Arg(1)->Arg(2));
  add(benchmark::RegisterBenchmark("ours/calibrate_whole_run", wholeRun)->Arg(1)->Arg(2)->Iterations(1));
  add(benchmark::RegisterBenchmark("ours/calibrate_full_plan", fullPlan)->Arg(2)->Iterations(1));
  benchmark::Initialize(&argc, argv);
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
