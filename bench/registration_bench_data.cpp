#include "registration_bench_data.hpp"

#include <cstdio>
#include <random>

#include "rigcal/core/pcd_io.hpp"
#include "rigcal/registration/covariance.hpp"
#include "rigcal/registration/voxel_grid.hpp"

namespace rigcal::bench {

using namespace rigcal::registration;

PclCloud::Ptr toPcl(const PointCloud& c) {
  auto out = std::make_shared<PclCloud>();
  out->reserve(c.size());
  for (const auto& p : c.points) out->push_back(pcl::PointXYZ(float(p.x()), float(p.y()), float(p.z())));
  return out;
}

namespace {
std::unique_ptr<Data> g_data;

PointCloud cropped(const PointCloud& c, double range) {
  PointCloud out;
  for (const auto& p : c.points) {
    if (p.head<3>().norm() < range) out.points.push_back(p);
  }
  return out;
}
}  // namespace

void loadRegistrationData(const std::filesystem::path& path, const std::filesystem::path& other) {
  auto d = std::make_unique<Data>();
  d->raw = fromTable(readPcd(path));
  d->truth = fromXyzRpy({0.3, -0.2, 0.05, deg2rad(1.0), deg2rad(-0.5), deg2rad(3.0)});
  std::mt19937 rng(7);
  std::normal_distribution<double> noise(0.0, 0.01);
  PointCloud moved = transformed(d->raw, d->truth.inverse());
  for (auto& p : moved.points) p.head<3>() += Eigen::Vector3d(noise(rng), noise(rng), noise(rng));
  d->source = voxelDownsample(cropped(moved, 22.0), 0.25);
  d->source_cov = d->source;
  estimateCovariances(d->source_cov);
  d->pcl_source = toPcl(d->source);

  TargetOptions options;
  options.normals_and_covariances = true;
  options.ndt_resolutions = {1.0};
  options.num_threads = 2;
  const PointCloud scan = voxelDownsample(cropped(d->raw, 22.0), 0.25);
  d->scan = {"s2s", std::make_unique<Target>(scan, options), toPcl(scan)};
  // Densify along scan lines: midpoints of consecutive returns closer than 0.3 m lie on the surfaces.
  PointCloud dense = d->raw;
  for (std::size_t i = 1; i < d->raw.size(); ++i) {
    const Eigen::Vector4d a = d->raw.points[i - 1], b = d->raw.points[i];
    if ((a - b).norm() < 0.3) dense.points.push_back(0.5 * (a + b));
  }
  PointCloud map = voxelDownsample(dense, 0.05);
  for (const auto& p : fromTable(readPcd(other)).points) map.points.push_back(p + Eigen::Vector4d(600.0, 0, 0, 0));
  d->map = {"s2m", std::make_unique<Target>(map, options), toPcl(map)};
  std::printf("data: raw %zu, source %zu, scan target %zu, map target %zu points\n", d->raw.size(),
              d->source.size(), scan.size(), map.size());
  g_data = std::move(d);
}

const Data& data() { return *g_data; }

}  // namespace rigcal::bench
