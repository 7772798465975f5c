#include "rigcal/registration/voxel_ordered_cloud.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <tuple>

#include "voxel_hash.hpp"

namespace rigcal::registration {

namespace {

void checkLeaf(double leaf, const char* who) {
  if (!(std::isfinite(leaf) && leaf > 0.0))
    throw std::invalid_argument(std::string(who) + ": leaf must be finite and > 0, got " + std::to_string(leaf));
}

/// The merge's order of voxels (any total order would do: voxelDownsample's first-hit order is restored from
/// the points' places in their clouds).
bool before(const detail::VoxelCoord& a, const detail::VoxelCoord& b) {
  return std::tie(a.x, a.y, a.z) < std::tie(b.x, b.y, b.z);
}

}  // namespace

VoxelOrderedCloud::VoxelOrderedCloud(const PointCloud& cloud, double leaf) : cloud_size_(cloud.size()), leaf_(leaf) {
  const std::vector<Eigen::Vector4d>& points = cloud.points;
  checkLeaf(leaf, "VoxelOrderedCloud");
  if (points.size() >= std::numeric_limits<std::uint32_t>::max())
    throw std::invalid_argument("VoxelOrderedCloud: more than 2^32 - 1 points");
  const double inv_leaf = 1.0 / leaf;  // as voxelDownsample: the same floor of the same product
  struct Keyed {
    detail::VoxelCoord c;
    std::uint32_t i;
  };
  std::vector<Keyed> keyed;
  keyed.reserve(points.size());
  for (std::size_t i = 0; i < points.size(); ++i) {
    detail::VoxelCoord c;
    if (detail::voxelCoord(points[i], inv_leaf, &c)) keyed.push_back({c, std::uint32_t(i)});
  }
  std::sort(keyed.begin(), keyed.end(), [](const Keyed& a, const Keyed& b) {
    return before(a.c, b.c) || (a.c == b.c && a.i < b.i);
  });
  points_.reserve(keyed.size());
  place_.reserve(keyed.size());
  for (const Keyed& k : keyed) {
    points_.push_back(points[k.i].head<3>());
    place_.push_back(k.i);
  }
}

PointCloud voxelDownsampleConcatenation(std::span<const VoxelOrderedCloud* const> clouds, double leaf) {
  checkLeaf(leaf, "voxelDownsampleConcatenation");
  for (const VoxelOrderedCloud* c : clouds) {
    if (c->leaf() != leaf) {
      throw std::invalid_argument("voxelDownsampleConcatenation: a cloud ordered at leaf " + std::to_string(c->leaf()) +
                                  ", merged at " + std::to_string(leaf));
    }
  }
  const double inv_leaf = 1.0 / leaf;
  // One cursor per cloud along its voxel order; a min-heap on (voxel, cloud) visits every voxel's points
  // cloud after cloud and, within one, in the cloud's order: the concatenation's order, as voxelDownsample
  // sums them.
  struct Cursor {
    std::size_t cloud = 0, next = 0;
    detail::VoxelCoord voxel;
  };
  std::vector<Cursor> heap;
  const auto load = [&](Cursor& c) {
    const Eigen::Vector3d& q = clouds[c.cloud]->byVoxel()[c.next];
    detail::voxelCoord(Eigen::Vector4d(q.x(), q.y(), q.z(), 1.0), inv_leaf, &c.voxel);  // kept: it has one
  };
  std::size_t largest = 0;
  for (std::size_t k = 0; k < clouds.size(); ++k) {
    largest = std::max(largest, clouds[k]->cloudSize());
    if (clouds[k]->byVoxel().empty()) continue;
    heap.push_back({k, 0, {}});
    load(heap.back());
  }
  const auto later = [](const Cursor& a, const Cursor& b) {
    return before(b.voxel, a.voxel) || (a.voxel == b.voxel && a.cloud > b.cloud);
  };
  std::make_heap(heap.begin(), heap.end(), later);

  // Each voxel's centroid as voxelDownsample computes it: sums relative to the voxel's first point, w counts.
  std::vector<Eigen::Vector4d> centroid;
  struct Place {
    std::uint32_t cloud, index;
  };
  std::vector<Place> first_at;  // where each voxel's first point is in the concatenation
  Eigen::Vector4d first = Eigen::Vector4d::Zero(), sum = Eigen::Vector4d::Zero();
  const auto close = [&] {
    centroid.push_back(first + sum / sum.w());
    centroid.back().w() = 1.0;
  };
  detail::VoxelCoord current;
  while (!heap.empty()) {
    std::pop_heap(heap.begin(), heap.end(), later);
    Cursor& c = heap.back();
    const VoxelOrderedCloud& cloud = *clouds[c.cloud];
    const Eigen::Vector3d& q = cloud.byVoxel()[c.next];
    const Eigen::Vector4d p(q.x(), q.y(), q.z(), 1.0);
    if (first_at.empty() || !(c.voxel == current)) {
      if (!first_at.empty()) close();
      current = c.voxel;
      first = p;
      sum.setZero();
      first_at.push_back({std::uint32_t(c.cloud), cloud.placeInCloud()[c.next]});
    }
    sum.head<3>() += (p - first).head<3>();
    sum.w() += 1.0;
    if (++c.next < cloud.byVoxel().size()) {
      load(c);
      std::push_heap(heap.begin(), heap.end(), later);
    } else {
      heap.pop_back();
    }
  }
  if (!first_at.empty()) close();
  // In the order voxelDownsample finds the voxels, by their first point's place in the concatenation: cloud
  // by cloud, and within one by the place in that cloud (one cloud-sized table, reused, stays in cache).
  std::vector<std::size_t> from(clouds.size() + 1, 0);  // voxels first hit in each cloud, bucketed
  for (const Place& f : first_at) ++from[f.cloud + 1];
  for (std::size_t k = 0; k < clouds.size(); ++k) from[k + 1] += from[k];
  std::vector<std::uint32_t> bucketed(first_at.size());
  {
    std::vector<std::size_t> fill(from.begin(), from.end() - 1);
    for (std::size_t v = 0; v < first_at.size(); ++v) bucketed[fill[first_at[v].cloud]++] = std::uint32_t(v);
  }
  constexpr std::uint32_t kNone = std::numeric_limits<std::uint32_t>::max();
  std::vector<std::uint32_t> voxel_at(largest, kNone);
  PointCloud out;
  out.points.reserve(centroid.size());
  for (std::size_t k = 0; k < clouds.size(); ++k) {
    for (std::size_t b = from[k]; b < from[k + 1]; ++b) voxel_at[first_at[bucketed[b]].index] = bucketed[b];
    for (std::size_t i = 0; i < clouds[k]->cloudSize(); ++i) {
      const std::uint32_t v = voxel_at[i];
      if (v == kNone) continue;
      voxel_at[i] = kNone;
      out.points.push_back(centroid[v]);
    }
  }
  return out;
}

}  // namespace rigcal::registration
