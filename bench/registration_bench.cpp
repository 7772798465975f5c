// rigcal registration against PCL 1.13 on the same real data, one run. Scan-to-scan: the VLS-128
// reference scan within 22 m, 0.25 m voxels (~18k points), against itself moved by a known transform
// with 1 cm noise. Scan-to-map: the same source against a ~255k-point map: the full scan densified along
// its scan lines at 5 cm voxels (192k), merged with the XT32 reference scan (63k) 600 m away (map content
// the source does not see, as in a real map). Every benchmark is one alignment per repetition; median and p99 over
// repetitions, error against the known transform as counters, and a side-by-side table at the end.
// Run pinned: taskset -c 0 (1 thread) and taskset -c 0,1 (2 threads). Skips when the data is missing.
#include <benchmark/benchmark.h>
#include <pcl/filters/voxel_grid.h>
#include <pcl/kdtree/kdtree_flann.h>
#include <pcl/point_types.h>
#include <pcl/registration/gicp.h>
#include <pcl/registration/icp.h>
#include <pcl/registration/ndt.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "registration_bench_data.hpp"
#include "registration_profile.hpp"
#include "rigcal/registration/covariance.hpp"
#include "rigcal/registration/gicp.hpp"
#include "rigcal/registration/icp.hpp"
#include "rigcal/registration/ndt.hpp"
#include "rigcal/registration/voxel_grid.hpp"
#include "rigcal/registration/voxel_ordered_cloud.hpp"

namespace {

using namespace rigcal;
using namespace rigcal::registration;
using namespace rigcal::bench;

void setErrors(benchmark::State& state, const Pose& estimate) {
  const Pose e = data().truth.inverse() * estimate;
  state.counters["t_err_mm"] = e.translation().norm() * 1e3;
  state.counters["r_err_deg"] = rad2deg(rotationAngle(e));
}

// ---- ours ------------------------------------------------------------------------------------------------
void oursGicp(benchmark::State& state, const Scenario* s, bool with_source_covariances) {
  const auto params = [&] {
    auto p = commonParams<GicpParams>(static_cast<int>(state.range(0)));
    p.max_correspondence_distance = 1.0;
    return p;
  }();
  RegistrationResult r;
  for (auto _ : state) {
    if (with_source_covariances) {
      PointCloud src = data().source;
      CovarianceOptions co;
      co.num_threads = params.num_threads;
      estimateCovariances(src, co);
      r = alignGicp(*s->target, src, Pose::Identity(), params);
    } else {
      r = alignGicp(*s->target, data().source_cov, Pose::Identity(), params);
    }
  }
  setErrors(state, r.T_target_source);
  state.counters["iterations"] = r.iterations;
}

void oursNdt(benchmark::State& state, const Scenario* s) {
  auto params = commonParams<NdtParams>(static_cast<int>(state.range(0)));
  RegistrationResult r;
  for (auto _ : state) r = alignNdt(*s->target, data().source, Pose::Identity(), params);
  setErrors(state, r.T_target_source);
  state.counters["iterations"] = r.iterations;
}

void oursIcp(benchmark::State& state, const Scenario* s, IcpMethod method) {
  auto params = commonParams<IcpParams>(static_cast<int>(state.range(0)));
  params.method = method;
  params.max_correspondence_distance = 1.0;
  RegistrationResult r;
  for (auto _ : state) r = alignIcp(*s->target, data().source, Pose::Identity(), params);
  setErrors(state, r.T_target_source);
  state.counters["iterations"] = r.iterations;
}

// ---- PCL (single-threaded in 1.13); same limits: 1 m correspondences, 64 iterations, 1e-4 m / rad -----------
template <class Reg>
void runPcl(benchmark::State& state, Reg& reg, const Scenario* s) {
  reg.setInputTarget(s->pcl_target);
  reg.setInputSource(data().pcl_source);
  PclCloud out;
  reg.align(out);  // warm-up: builds and caches the target side (tree, covariances, grid), like our Target
  for (auto _ : state) {
    reg.setInputSource(data().pcl_source);  // source-side work (GICP covariances) is redone per align
    reg.align(out);
  }
  setErrors(state, Pose(reg.getFinalTransformation().template cast<double>()));
  state.counters["converged"] = reg.hasConverged();
}

// `neighbors`: PCL's default is 20 covariance neighbours, ours (CovarianceOptions) 10.
void pclGicp(benchmark::State& state, const Scenario* s, int neighbors) {
  pcl::GeneralizedIterativeClosestPoint<pcl::PointXYZ, pcl::PointXYZ> reg;
  reg.setCorrespondenceRandomness(neighbors);
  reg.setMaxCorrespondenceDistance(1.0);
  reg.setMaximumIterations(64);
  reg.setTransformationEpsilon(1e-4);
  reg.setRotationEpsilon(1e-4);
  runPcl(state, reg, s);
}

void pclNdt(benchmark::State& state, const Scenario* s) {
  pcl::NormalDistributionsTransform<pcl::PointXYZ, pcl::PointXYZ> reg;
  reg.setResolution(1.0);
  reg.setStepSize(0.1);
  reg.setOulierRatio(0.55);
  reg.setMaximumIterations(64);
  reg.setTransformationEpsilon(1e-8);                  // squared translation of the last step (m²)
  reg.setTransformationRotationEpsilon(1.0 - 5e-9);   // cos of its rotation: 1e-4 rad
  runPcl(state, reg, s);
}

void pclIcp(benchmark::State& state, const Scenario* s) {
  pcl::IterativeClosestPoint<pcl::PointXYZ, pcl::PointXYZ> reg;
  reg.setMaxCorrespondenceDistance(1.0);
  reg.setMaximumIterations(64);
  reg.setTransformationEpsilon(1e-8);
  reg.setTransformationRotationEpsilon(1.0 - 5e-9);
  runPcl(state, reg, s);
}

// ---- building blocks -------------------------------------------------------------------------------------
void oursNearest(benchmark::State& state, const Scenario* s) {
  const KdTree& tree = s->target->tree();
  const Eigen::Matrix4d M = data().truth.matrix();
  std::size_t found = 0;
  for (auto _ : state) {
    for (const auto& p : data().source.points) {
      Neighbor nb;
      found += tree.nearest(M * p, 1.0, &nb);
    }
  }
  state.counters["found"] = static_cast<double>(found) / static_cast<double>(state.iterations());
}

void pclNearest(benchmark::State& state, const Scenario* s) {
  pcl::KdTreeFLANN<pcl::PointXYZ> tree;
  tree.setInputCloud(s->pcl_target);
  const Eigen::Matrix4d M = data().truth.matrix();
  std::vector<int> idx(1);
  std::vector<float> d2(1);
  std::size_t found = 0;
  for (auto _ : state) {
    for (const auto& p : data().source.points) {
      const Eigen::Vector4d q = M * p;
      const int n = tree.nearestKSearch(pcl::PointXYZ(float(q.x()), float(q.y()), float(q.z())), 1, idx, d2);
      found += n > 0 && d2[0] < 1.0F;  // the same question: the nearest point within 1 m
    }
  }
  state.counters["found"] = static_cast<double>(found) / static_cast<double>(state.iterations());
}

void oursTreeBuild(benchmark::State& state, const Scenario* s) {
  for (auto _ : state) benchmark::DoNotOptimize(KdTree(s->target->cloud().points));
}
void pclTreeBuild(benchmark::State& state, const Scenario* s) {
  for (auto _ : state) {
    pcl::KdTreeFLANN<pcl::PointXYZ> tree;
    tree.setInputCloud(s->pcl_target);
    benchmark::DoNotOptimize(tree);
  }
}

// At 0.1 m the full scan (412 x 452 x 61 m: 1.1e10 voxels) overflows PCL's int index: PCL warns and returns
// the input unfiltered (points_out = input), so only the 0.25 m row (7e8 voxels, within PCL's range) is a
// like-for-like timing; the 0.1 m row shows the failure.
void oursVoxel(benchmark::State& state, double leaf) {
  std::size_t n = 0;
  for (auto _ : state) n = voxelDownsample(data().raw, leaf).size();
  state.counters["points_out"] = static_cast<double>(n);
}
void pclVoxel(benchmark::State& state, double leaf) {
  const PclCloud::Ptr raw = toPcl(data().raw);
  PclCloud out;
  const auto f = static_cast<float>(leaf);
  for (auto _ : state) {
    pcl::VoxelGrid<pcl::PointXYZ> grid;
    grid.setInputCloud(raw);
    grid.setLeafSize(f, f, f);
    grid.filter(out);
  }
  state.counters["points_out"] = static_cast<double>(out.size());
}

// The mapper's local map at each keyframe: 15 keyframes (the VLS-128 scan voxelised at 0.1 m, placed 1 m
// apart as a drive places them) voxelised together at 0.1 m in the map frame. Ours: each keyframe ordered by
// voxel once when it is added, the orders merged at each rebuild; the baseline (what the mapper did before,
// the same points bit for bit): voxelDownsample's hashed pass over the concatenated keyframes.
constexpr int kLocalMapKeyframes = 15;
constexpr double kLocalMapLeaf = 0.1;
std::vector<PointCloud> placedKeyframes() {
  const PointCloud scan = voxelDownsample(data().raw, kLocalMapLeaf);
  std::vector<PointCloud> keyframes;
  for (int k = 0; k < kLocalMapKeyframes; ++k) {
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.rotate(Eigen::AngleAxisd(0.01 * k, Eigen::Vector3d::UnitZ()));
    T.pretranslate(Eigen::Vector3d(1.0 * k, 0.02 * k, 0.0));
    keyframes.push_back(transformed(scan, T));
  }
  return keyframes;
}
void localMapMerge(benchmark::State& state) {
  std::vector<VoxelOrderedCloud> ordered;
  for (const PointCloud& k : placedKeyframes()) ordered.emplace_back(k, kLocalMapLeaf);
  std::vector<const VoxelOrderedCloud*> clouds;
  for (const auto& k : ordered) clouds.push_back(&k);
  std::size_t n = 0;
  for (auto _ : state) n = voxelDownsampleConcatenation(clouds, kLocalMapLeaf).size();
  state.counters["points_out"] = static_cast<double>(n);
}
void localMapVoxelPass(benchmark::State& state) {
  PointCloud all;
  for (const PointCloud& k : placedKeyframes()) all.points.insert(all.points.end(), k.points.begin(), k.points.end());
  std::size_t n = 0;
  for (auto _ : state) n = voxelDownsample(all, kLocalMapLeaf).size();
  state.counters["points_out"] = static_cast<double>(n);
}
// What ordering one keyframe costs when it is added (once per keyframe, against ~15 rebuilds it is in).
void localMapOrderKeyframe(benchmark::State& state) {
  const PointCloud k = placedKeyframes().back();
  for (auto _ : state) benchmark::DoNotOptimize(VoxelOrderedCloud(k, kLocalMapLeaf).byVoxel().size());
}

void oursTarget(benchmark::State& state, const Scenario* s) {
  TargetOptions options;
  options.normals_and_covariances = true;
  options.ndt_resolutions = {1.0};
  options.num_threads = static_cast<int>(state.range(0));
  // From positions only, as a calibration builds its targets (the prepared target's cloud carries
  // normals, which would leave only the neighbour graph to build).
  PointCloud positions;
  positions.points = s->target->cloud().points;
  for (auto _ : state) benchmark::DoNotOptimize(Target(positions, options));
}

double percentile99(const std::vector<double>& v) {
  std::vector<double> s = v;
  std::sort(s.begin(), s.end());
  return s.empty() ? 0.0 : s[std::min(s.size() - 1, static_cast<std::size_t>(std::ceil(0.99 * s.size())) - 1)];
}

// Collects median / p99 and the error counters to print the comparison table at the end.
struct Row {
  double median = NAN, median_cpu = NAN, p99 = NAN, t_err = NAN, r_err = NAN;
};
std::map<std::string, Row> g_rows;

class TableReporter : public benchmark::ConsoleReporter {
 public:
  void ReportRuns(const std::vector<Run>& runs) override {
    for (const Run& r : runs) {
      if (r.run_type != Run::RT_Aggregate) continue;
      Row& row = g_rows[r.run_name.str()];
      if (r.aggregate_name == "median") {
        row.median = r.GetAdjustedRealTime();
        row.median_cpu = r.GetAdjustedCPUTime();
        if (r.counters.count("t_err_mm")) row.t_err = r.counters.at("t_err_mm");
        if (r.counters.count("r_err_deg")) row.r_err = r.counters.at("r_err_deg");
      } else if (r.aggregate_name == "p99") {
        row.p99 = r.GetAdjustedRealTime();
      }
    }
    ConsoleReporter::ReportRuns(runs);
  }
};

void printTable() {
  auto get = [](const std::string& name) {
    for (const auto& [key, row] : g_rows) {
      if (key.rfind(name, 0) == 0) return row;
    }
    return Row{};
  };
  // Wall-clock medians and p99s; in brackets the main thread's CPU time (what a loaded machine cannot
  // inflate for 1 thread). PCL/ours compares wall-clock medians with one thread each.
  std::printf("\n%-4s %-9s | %-26s | %-26s | %-26s | %-8s | %-17s | %-17s\n", "", "method",
              "ours 1T med (cpu) / p99 ms", "ours 2T med (cpu) / p99 ms", "PCL med (cpu) / p99 ms", "PCL/ours",
              "ours err mm / deg", "PCL err mm / deg");
  for (const char* scenario : {"s2s", "s2m"}) {
    for (const auto& [method, pcl] : std::vector<std::pair<std::string, std::string>>{
             {"GICP+cov", "GICP"}, {"GICP", ""}, {"NDT", "NDT"}, {"ICP", "ICP"}, {"ICP-plane", ""}}) {
      const std::string base = std::string(scenario) + "/" + method + "/ours/";
      const Row one = get(base + "threads:1"), two = get(base + "threads:2");
      const Row theirs = pcl.empty() ? Row{} : get(std::string(scenario) + "/" + pcl + "/pcl");
      std::printf("%-4s %-9s | %7.1f (%7.1f) / %7.1f | %7.1f (%7.1f) / %7.1f | %7.0f (%7.0f) / %7.0f | %7.1fx | %6.3f / %.5f | "
                  "%6.3f / %.5f\n",
                  scenario, method.c_str(), one.median, one.median_cpu, one.p99, two.median, two.median_cpu, two.p99,
                  theirs.median, theirs.median_cpu, theirs.p99, theirs.median / one.median, one.t_err, one.r_err,
                  theirs.t_err, theirs.r_err);
    }
  }
  // CPU-time ratios too: on a machine loaded by other work, wall time of a 1-thread run is mostly waiting.
  std::printf("\nPCL/ours on main-thread CPU time (1 thread each):");
  for (const char* scenario : {"s2s", "s2m"}) {
    for (const auto& [method, pcl] : std::vector<std::pair<std::string, std::string>>{
             {"GICP+cov", "GICP"}, {"NDT", "NDT"}, {"ICP", "ICP"}}) {
      const Row one = get(std::string(scenario) + "/" + method + "/ours/threads:1");
      const Row theirs = get(std::string(scenario) + "/" + pcl + "/pcl");
      std::printf(" %s %s %.1fx;", scenario, method.c_str(), theirs.median_cpu / one.median_cpu);
    }
  }
  // PCL with our number of covariance neighbours: the same work per point, not only the same task.
  std::printf("\nPCL GICP with k = 10 covariance neighbours as ours (default 20):");
  for (const char* scenario : {"s2s", "s2m"}) {
    const Row one = get(std::string(scenario) + "/GICP+cov/ours/threads:1");
    const Row theirs = get(std::string(scenario) + "/GICP-k10/pcl");
    std::printf(" %s %.0f ms, %.1fx, error %.3f mm / %.5f deg;", scenario, theirs.median, theirs.median / one.median,
                theirs.t_err, theirs.r_err);
  }
  // Building blocks: whether our own structures beat PCL's (the issue allows them only where they do).
  std::printf("\n\n%-22s | %-24s | %-24s | %-8s\n", "building block", "ours med (cpu) / p99 ms",
              "PCL med (cpu) / p99 ms", "PCL/ours");
  for (const char* block : {"s2s/nearest", "s2s/tree-build", "s2m/nearest", "s2m/tree-build", "voxel-0.25m",
                            "voxel-0.1m"}) {
    const Row ours = get(std::string(block) + "/ours"), theirs = get(std::string(block) + "/pcl");
    std::printf("%-22s | %6.2f (%6.2f) / %6.2f | %6.2f (%6.2f) / %6.2f | %7.1fx\n", block, ours.median,
                ours.median_cpu, ours.p99, theirs.median, theirs.median_cpu, theirs.p99, theirs.median / ours.median);
  }
  const Row merge = get("local-map/merge"), pass = get("local-map/voxel-pass"), order = get("local-map/order-keyframe");
  std::printf("\nlocal map (%d keyframes at %.1f m): merge of the keyframes' voxel orders %.2f / %.2f ms (median / "
              "p99), hashed voxel pass over the concatenation %.2f / %.2f ms: %.1fx; ordering a keyframe once %.2f / "
              "%.2f ms\n",
              kLocalMapKeyframes, kLocalMapLeaf, merge.median, merge.p99, pass.median, pass.p99,
              pass.median / merge.median, order.median, order.p99);
}

}  // namespace

int main(int argc, char** argv) {
  const char* env = std::getenv("RIGCAL_DATA_DIR");
  const std::filesystem::path dir = env && *env ? env : RIGCAL_DEFAULT_DATA_DIR;
  const std::filesystem::path scan = dir / "velodyne/vls128_strongest.reference.pcd";
  const std::filesystem::path other = dir / "hesai/xt32_dual.reference.pcd";
  for (const auto& f : {scan, other}) {
    if (!std::filesystem::exists(f)) {
      std::printf("SKIPPED: shared data not found: %s (set RIGCAL_DATA_DIR)\n", f.c_str());
      return 0;
    }
  }
  if (argc >= 3 && std::string(argv[1]) == "--profile") {
    loadRegistrationData(scan, other);
    return registrationProfile(argv[2], argc >= 4 ? std::atoi(argv[3]) : 5);
  }
  benchmark::Initialize(&argc, argv);
  loadRegistrationData(scan, other);
  const auto stats = [](benchmark::internal::Benchmark* b, int reps) {
    b->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(1)->Repetitions(reps);
    b->ComputeStatistics("p99", percentile99)->ReportAggregatesOnly(true);
  };
  for (const Scenario* s : {&data().scan, &data().map}) {
    const std::string n = s->name + "/";
    const int pcl_reps = s == &data().scan ? 5 : 3;
    for (const int t : {1, 2}) {
      const std::string th = "/ours/threads:" + std::to_string(t);
      stats(benchmark::RegisterBenchmark((n + "GICP+cov" + th).c_str(), oursGicp, s, true)->Arg(t), 20);
      stats(benchmark::RegisterBenchmark((n + "GICP" + th).c_str(), oursGicp, s, false)->Arg(t), 20);
      stats(benchmark::RegisterBenchmark((n + "NDT" + th).c_str(), oursNdt, s)->Arg(t), 20);
      stats(benchmark::RegisterBenchmark((n + "ICP" + th).c_str(), oursIcp, s, IcpMethod::kPointToPoint)->Arg(t), 20);
      stats(benchmark::RegisterBenchmark((n + "ICP-plane" + th).c_str(), oursIcp, s, IcpMethod::kPointToPlane)->Arg(t),
            20);
      stats(benchmark::RegisterBenchmark((n + "target-build" + th).c_str(), oursTarget, s)->Arg(t), 5);
    }
    stats(benchmark::RegisterBenchmark((n + "GICP/pcl").c_str(), pclGicp, s, 20), pcl_reps);
    stats(benchmark::RegisterBenchmark((n + "GICP-k10/pcl").c_str(), pclGicp, s, 10), pcl_reps);
    stats(benchmark::RegisterBenchmark((n + "NDT/pcl").c_str(), pclNdt, s), pcl_reps);
    stats(benchmark::RegisterBenchmark((n + "ICP/pcl").c_str(), pclIcp, s), pcl_reps);
    stats(benchmark::RegisterBenchmark((n + "nearest/ours").c_str(), oursNearest, s), 10);
    stats(benchmark::RegisterBenchmark((n + "nearest/pcl").c_str(), pclNearest, s), 10);
    stats(benchmark::RegisterBenchmark((n + "tree-build/ours").c_str(), oursTreeBuild, s), 10);
    stats(benchmark::RegisterBenchmark((n + "tree-build/pcl").c_str(), pclTreeBuild, s), 10);
  }
  for (const double leaf : {0.25, 0.1}) {
    const std::string n = leaf == 0.25 ? "voxel-0.25m/" : "voxel-0.1m/";
    stats(benchmark::RegisterBenchmark((n + "ours").c_str(), oursVoxel, leaf), 10);
    stats(benchmark::RegisterBenchmark((n + "pcl").c_str(), pclVoxel, leaf), 10);
  }
  stats(benchmark::RegisterBenchmark("local-map/merge", localMapMerge), 10);
  stats(benchmark::RegisterBenchmark("local-map/order-keyframe", localMapOrderKeyframe), 10);
  stats(benchmark::RegisterBenchmark("local-map/voxel-pass", localMapVoxelPass), 10);
  TableReporter reporter;
  benchmark::RunSpecifiedBenchmarks(&reporter);
  printTable();
  benchmark::Shutdown();
  return 0;
}
