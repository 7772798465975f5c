#pragma once
// The static world the lidars see: the ground, its painted/planted patches, and upright primitives,
// indexed by a uniform 2D grid over the ground plane (cells list the primitives whose footprint
// overlaps them, plus the highest top in the cell so rays passing above are skipped cheaply).
#include <cstdint>
#include <utility>
#include <vector>

#include "rigcal/sim/ground.hpp"
#include "rigcal/sim/primitives.hpp"

namespace rigcal::sim {

/// A flat region of the ground with its own material (road paint, grass); boxes' z is ignored.
using GroundPatch = Box;

struct SceneContent {
  Ground ground;
  std::vector<Box> boxes;
  std::vector<Cylinder> cylinders;
  std::vector<Ellipsoid> ellipsoids;
  std::vector<GroundPatch> patches;
};

class Scene {
 public:
  explicit Scene(SceneContent content, double cell_size = 2.0);

  /// Nearest surface along the ray in [t_min, t_max]. Returns false (hit untouched) when none.
  bool cast(const Ray& ray, double t_min, double t_max, Hit& hit) const;
  /// Distance from p to the nearest surface within `radius` horizontally (the ground always counts).
  [[nodiscard]] double surfaceDistance(const Eigen::Vector3d& p, double radius = 1.0) const;

  [[nodiscard]] const SceneContent& content() const { return content_; }
  [[nodiscard]] const Ground& ground() const { return content_.ground; }
  [[nodiscard]] Rect2 gridBounds() const { return {x0_, y0_, x0_ + nx_ * cell_, y0_ + ny_ * cell_}; }
  [[nodiscard]] double cellSize() const { return cell_; }
  [[nodiscard]] std::size_t primitiveCount() const {
    return content_.boxes.size() + content_.cylinders.size() + content_.ellipsoids.size();
  }
  /// Mean number of primitive references per non-empty cell (an index quality figure).
  [[nodiscard]] double meanRefsPerOccupiedCell() const;

 private:
  enum : std::uint32_t { kBox = 0u << 30, kCylinder = 1u << 30, kEllipsoid = 2u << 30 };
  static constexpr std::uint32_t kTypeMask = 3u << 30;

  void index(const Rect2& r, std::uint32_t ref, double top, std::vector<std::vector<std::uint32_t>>& cells,
             std::vector<float>& tops) const;
  [[nodiscard]] bool cellRange(const Rect2& r, int& i0, int& j0, int& i1, int& j1) const;
  [[nodiscard]] Material groundMaterial(double x, double y) const;
  /// Tests the primitives of the cells the ray crosses in [t_in, t_out]; true if any was hit.
  bool walkCells(const Ray& ray, double t_in, double t_out, double t_min, Hit& best, std::uint32_t* tested,
                 std::uint32_t ray_id) const;

  SceneContent content_;
  double cell_ = 2.0, inv_cell_ = 0.5;
  double x0_ = 0, y0_ = 0;
  int nx_ = 0, ny_ = 0;
  double top_ = 0;  // highest point of any primitive
  // Compressed cell lists: refs_[start_[c] .. start_[c + 1]) for cell c; patch lists likewise.
  std::vector<std::uint32_t> start_, refs_, patch_start_, patch_refs_;
  std::vector<float> cell_top_;
  std::vector<std::pair<float, float>> ref_z_;  // per entry of refs_: its primitive's z range (rounded out)
};

}  // namespace rigcal::sim
