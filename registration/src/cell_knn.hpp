#pragma once
// Private: the k nearest neighbours of every point of a cloud among its own points (the all-k-NN that
// covariance estimation needs), on a hashed grid of cells sized so that a point's k nearest usually lie
// in its own and the 26 surrounding cells. All points of one cell share those candidates, gathered once
// into a small contiguous float array, so a query is a tight distance loop instead of a tree walk.
// Exact: a point's answer is kept only when its k-th distance is provably smaller than the distance to
// anything outside the 3x3x3 block; the rest (sparse outskirts, over-crowded blocks) are searched
// further or listed for a kd-tree query.
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include <Eigen/Core>

#include "rigcal/registration/deadline.hpp"
#include "rigcal/registration/nearest_neighbors.hpp"

namespace rigcal::registration::detail {

struct CellKnn {
  std::size_t k = 0;
  std::vector<Neighbor> neighbors;      // k per point, closest first (the point itself among them)
  std::vector<std::uint32_t> count;     // how many of the k slots are filled (proven points: k)
  std::vector<std::uint32_t> unproven;  // points whose answer the grid could not prove, ascending
};

/// All-k-NN of `points` (finite). Like KdTree::knn(points[i], k) for every i, up to the order of equally
/// distant points. Deterministic and independent of num_threads. Returns false (and leaves `out`
/// unspecified) when a grid does not suit the cloud (too few points, or an extent no cell size covers);
/// then use the tree for everything. `tree_at_hand`: the caller already has a tree, so what the 3x3x3
/// block cannot prove is listed as unproven at once instead of searched further on the grid.
/// `stop` (with a tree at hand): once it expires the remaining cells are skipped, their points left with
/// no neighbours and unproven; the caller, seeing it expired, discards the result.
bool cellKnn(std::span<const Eigen::Vector4d> points, std::size_t k, int num_threads, bool tree_at_hand,
             CellKnn* out, const Deadline& stop = {});

}  // namespace rigcal::registration::detail
