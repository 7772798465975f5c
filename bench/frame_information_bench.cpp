// The pairing stage's frame information (pipeline::frameInformation: voxel thinning, a k-NN plane fit per
// point, the point-to-plane information of the planar ones), run on every accepted candidate frame of every
// calibration lidar, on real sweeps: a VLP-16 (dual returns) and a VLP-32C. Baselines in the same run:
// PCL 1.13's NormalEstimation over the same thinned points (the same k-NN plane fit, the library way) and
// the cheap PCA information that the `pca` ranking uses instead.
// Run pinned: taskset -c 1 frame_information_bench --benchmark_repetitions=10 (median and p99 are reported).
#include <benchmark/benchmark.h>

#include <pcl/features/normal_3d.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>
#include <pcl/search/kdtree.h>

#include <filesystem>
#include <string>
#include <vector>

#include "bench_support.hpp"
#include "rigcal/core/pcd_io.hpp"
#include "rigcal/pipeline/frame_information.hpp"
#include "rigcal/pipeline/frame_selector.hpp"
#include "rigcal/registration/point_cloud.hpp"
#include "rigcal/registration/voxel_grid.hpp"

namespace {

using namespace rigcal;

struct Sweep {
  std::string name;
  std::filesystem::path pcd;
};

const std::vector<Sweep>& sweeps() {
  static const std::vector<Sweep> s = {
      {"vlp16_dual", bench::dataDir() / "velodyne" / "vlp16_dual.reference.pcd"},
      {"vlp32c", bench::dataDir() / "velodyne" / "vlp32c_fov270to90.reference.pcd"},
  };
  return s;
}

void ours(benchmark::State& state, const Sweep& sweep) {
  if (bench::skipUnlessPresent(state, {sweep.pcd})) return;
  const Scan scan = toScan(readPcd(sweep.pcd));
  registration::PointToPlaneInformation info;
  for (auto _ : state) {
    info = pipeline::frameInformation(scan);
    benchmark::DoNotOptimize(info);
  }
  state.counters["points"] = double(scan.size());
}

void pclNormals(benchmark::State& state, const Sweep& sweep) {
  if (bench::skipUnlessPresent(state, {sweep.pcd})) return;
  const Scan scan = toScan(readPcd(sweep.pcd));
  const pipeline::FrameInformationOptions o;
  for (auto _ : state) {
    // The same work up to the normals: thinning, a k-NN search structure, k-NN plane fits.
    const registration::PointCloud thinned = registration::voxelDownsample(registration::fromScan(scan), o.leaf_size);
    pcl::PointCloud<pcl::PointXYZ>::Ptr cloud(new pcl::PointCloud<pcl::PointXYZ>);
    cloud->reserve(thinned.size());
    for (const auto& p : thinned.points) cloud->push_back(pcl::PointXYZ(float(p.x()), float(p.y()), float(p.z())));
    pcl::NormalEstimation<pcl::PointXYZ, pcl::Normal> ne;
    ne.setInputCloud(cloud);
    ne.setSearchMethod(pcl::search::KdTree<pcl::PointXYZ>::Ptr(new pcl::search::KdTree<pcl::PointXYZ>));
    ne.setKSearch(o.num_neighbors);
    pcl::PointCloud<pcl::Normal> normals;
    ne.compute(normals);
    benchmark::DoNotOptimize(normals);
  }
  state.counters["points"] = double(scan.size());
}

void pca(benchmark::State& state, const Sweep& sweep) {
  if (bench::skipUnlessPresent(state, {sweep.pcd})) return;
  const Scan scan = toScan(readPcd(sweep.pcd));
  double info = 0.0;
  for (auto _ : state) {
    info = pipeline::pcaInformation(scan);
    benchmark::DoNotOptimize(info);
  }
}

template <class B>
void add(B* b) {
  b->Unit(benchmark::kMillisecond)->ComputeStatistics("p99", [](const std::vector<double>& v) { return bench::p99(v); });
}

}  // namespace

int main(int argc, char** argv) {
  for (const Sweep& s : sweeps()) {
    add(benchmark::RegisterBenchmark(("ours/frame_information/" + s.name).c_str(), [&s](benchmark::State& st) { ours(st, s); }));
    add(benchmark::RegisterBenchmark(("pcl/normal_estimation/" + s.name).c_str(), [&s](benchmark::State& st) { pclNormals(st, s); }));
    add(benchmark::RegisterBenchmark(("ours/pca_information/" + s.name).c_str(), [&s](benchmark::State& st) { pca(st, s); }));
  }
  benchmark::Initialize(&argc, argv);
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
