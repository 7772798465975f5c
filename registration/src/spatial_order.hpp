#pragma once
// Private: a visiting order in which consecutive points are close in space (Morton / Z-order of small
// cells). Nearest-neighbour queries issued in this order walk the same kd-tree leaves and target memory
// one after another, so they hit the cache instead of the map's 10 MB of points at random.
#include <cstdint>
#include <span>
#include <vector>

#include <Eigen/Core>

namespace rigcal::registration::detail {

/// A permutation of [0, points.size()): points sorted by the Z-order of their `cell`-sized cubes (ties
/// keep their input order, so the result is deterministic). Non-finite points go last.
std::vector<std::uint32_t> spatialOrder(std::span<const Eigen::Vector4d> points, double cell);

}  // namespace rigcal::registration::detail
