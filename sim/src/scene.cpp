#include "rigcal/sim/scene.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "fast_floor.hpp"

namespace rigcal::sim {
namespace {

void grow(Rect2& acc, const Rect2& r) {
  acc.x0 = std::min(acc.x0, r.x0);
  acc.y0 = std::min(acc.y0, r.y0);
  acc.x1 = std::max(acc.x1, r.x1);
  acc.y1 = std::max(acc.y1, r.y1);
}

using detail::fastFloor;

bool insidePatch(const GroundPatch& p, double x, double y) {
  const double px = x - p.cx, py = y - p.cy;
  return std::abs(p.cos_yaw * px + p.sin_yaw * py) <= p.hx && std::abs(-p.sin_yaw * px + p.cos_yaw * py) <= p.hy;
}

std::vector<std::uint32_t> flatten(const std::vector<std::vector<std::uint32_t>>& cells,
                                   std::vector<std::uint32_t>& start) {
  start.assign(cells.size() + 1, 0);
  std::vector<std::uint32_t> refs;
  for (std::size_t c = 0; c < cells.size(); ++c) {
    start[c] = std::uint32_t(refs.size());
    refs.insert(refs.end(), cells[c].begin(), cells[c].end());
  }
  start[cells.size()] = std::uint32_t(refs.size());
  return refs;
}

}  // namespace

Scene::Scene(SceneContent content, double cell_size) : content_(std::move(content)) {
  if (!(cell_size > 0)) throw std::invalid_argument("scene grid cell size must be positive");
  if (primitiveCount() >= (1u << 30)) throw std::invalid_argument("too many scene primitives");
  cell_ = cell_size;
  inv_cell_ = 1.0 / cell_size;
  Rect2 b{0, 0, 0, 0};
  bool any = false;
  const auto take = [&](const Rect2& r) {
    if (!any) b = r;
    grow(b, r);
    any = true;
  };
  for (const auto& x : content_.boxes) take(footprint(x));
  for (const auto& x : content_.cylinders) take(footprint(x));
  for (const auto& x : content_.ellipsoids) take(footprint(x));
  for (const auto& x : content_.patches) take(footprint(x));
  x0_ = std::floor(b.x0) - cell_;
  y0_ = std::floor(b.y0) - cell_;
  nx_ = std::max(1, int(std::ceil((b.x1 + cell_ - x0_) * inv_cell_)));
  ny_ = std::max(1, int(std::ceil((b.y1 + cell_ - y0_) * inv_cell_)));

  const std::size_t n = std::size_t(nx_) * std::size_t(ny_);
  std::vector<std::vector<std::uint32_t>> cells(n), patch_cells(n);
  std::vector<float> tops(n, -1e30f), unused(n);
  for (std::uint32_t i = 0; i < content_.boxes.size(); ++i)
    index(footprint(content_.boxes[i]), kBox | i, content_.boxes[i].z1, cells, tops);
  for (std::uint32_t i = 0; i < content_.cylinders.size(); ++i)
    index(footprint(content_.cylinders[i]), kCylinder | i, content_.cylinders[i].z1, cells, tops);
  for (std::uint32_t i = 0; i < content_.ellipsoids.size(); ++i) {
    const auto& e = content_.ellipsoids[i];
    index(footprint(e), kEllipsoid | i, e.cz + e.rz, cells, tops);
  }
  for (std::uint32_t i = 0; i < content_.patches.size(); ++i)
    index(footprint(content_.patches[i]), i, 0, patch_cells, unused);
  refs_ = flatten(cells, start_);
  patch_refs_ = flatten(patch_cells, patch_start_);
  cell_top_ = std::move(tops);
  ref_z_.reserve(refs_.size());
  for (const std::uint32_t ref : refs_) {
    const std::uint32_t idx = ref & ~kTypeMask;
    double lo = 0, hi = 0;
    switch (ref & kTypeMask) {
      case kBox: lo = content_.boxes[idx].z0, hi = content_.boxes[idx].z1; break;
      case kCylinder: lo = content_.cylinders[idx].z0, hi = content_.cylinders[idx].z1; break;
      default: lo = content_.ellipsoids[idx].cz - content_.ellipsoids[idx].rz, hi = content_.ellipsoids[idx].cz + content_.ellipsoids[idx].rz;
    }
    ref_z_.emplace_back(std::nextafter(float(lo), -1e30f), std::nextafter(float(hi), 1e30f));
  }
  top_ = -1e30;
  for (float t : cell_top_) top_ = std::max(top_, double(t));
}

bool Scene::cellRange(const Rect2& r, int& i0, int& j0, int& i1, int& j1) const {
  i0 = std::max(0, int(std::floor((r.x0 - x0_) * inv_cell_)));
  j0 = std::max(0, int(std::floor((r.y0 - y0_) * inv_cell_)));
  i1 = std::min(nx_ - 1, int(std::floor((r.x1 - x0_) * inv_cell_)));
  j1 = std::min(ny_ - 1, int(std::floor((r.y1 - y0_) * inv_cell_)));
  return i0 <= i1 && j0 <= j1;
}

void Scene::index(const Rect2& r, std::uint32_t ref, double top, std::vector<std::vector<std::uint32_t>>& cells,
                  std::vector<float>& tops) const {
  int i0, j0, i1, j1;
  if (!cellRange(r, i0, j0, i1, j1)) return;
  for (int j = j0; j <= j1; ++j)
    for (int i = i0; i <= i1; ++i) {
      const std::size_t c = std::size_t(j) * std::size_t(nx_) + std::size_t(i);
      cells[c].push_back(ref);
      // Rounded up so a float top never cuts off a primitive's true top.
      tops[c] = std::max(tops[c], std::nextafter(float(top), 1e30f));
    }
}

Material Scene::groundMaterial(double x, double y) const {
  const int i = fastFloor((x - x0_) * inv_cell_), j = fastFloor((y - y0_) * inv_cell_);
  if (i < 0 || j < 0 || i >= nx_ || j >= ny_) return Material::kAsphalt;
  const std::size_t c = std::size_t(j) * std::size_t(nx_) + std::size_t(i);
  // The last listed patch wins: markings are added after the surfaces they are painted on.
  Material m = Material::kAsphalt;
  for (std::uint32_t k = patch_start_[c]; k < patch_start_[c + 1]; ++k) {
    const GroundPatch& p = content_.patches[patch_refs_[k]];
    if (insidePatch(p, x, y)) m = p.material;
  }
  return m;
}

double Scene::surfaceDistance(const Eigen::Vector3d& p, double radius) const {
  double gx = 0, gy = 0;
  const double h = content_.ground.height(p.x(), p.y(), gx, gy);
  double best = std::abs(p.z() - h) / std::sqrt(1 + gx * gx + gy * gy);
  int i0, j0, i1, j1;
  if (!cellRange({p.x() - radius, p.y() - radius, p.x() + radius, p.y() + radius}, i0, j0, i1, j1)) return best;
  for (int j = j0; j <= j1; ++j)
    for (int i = i0; i <= i1; ++i) {
      const std::size_t c = std::size_t(j) * std::size_t(nx_) + std::size_t(i);
      for (std::uint32_t k = start_[c]; k < start_[c + 1]; ++k) {
        const std::uint32_t ref = refs_[k], idx = ref & ~kTypeMask;
        double d = 0;
        switch (ref & kTypeMask) {
          case kBox: d = sim::surfaceDistance(content_.boxes[idx], p); break;
          case kCylinder: d = sim::surfaceDistance(content_.cylinders[idx], p); break;
          default: d = sim::surfaceDistance(content_.ellipsoids[idx], p); break;
        }
        best = std::min(best, d);
      }
    }
  return best;
}

double Scene::meanRefsPerOccupiedCell() const {
  std::size_t occupied = 0;
  for (std::size_t c = 0; c + 1 < start_.size(); ++c) occupied += start_[c + 1] != start_[c];
  return occupied ? double(refs_.size()) / double(occupied) : 0.0;
}

}  // namespace rigcal::sim
