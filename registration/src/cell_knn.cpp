#include "cell_knn.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include "candidate_scan.hpp"
#include "rigcal/registration/parallel.hpp"
#include "top_k.hpp"
#include "voxel_hash.hpp"

namespace rigcal::registration::detail {

namespace {

// Points per occupied cell the grid aims for, as a fraction of k. Smaller cells: fewer candidates per
// point but more points the 3x3x3 block cannot vouch for (they look further, one at a time). Measured
// (callgrind) on the VLS-128 scan at 0.25 m voxels, k = 10: 0.25–0.5 all within 5 %, 0.7 +18 %, 1.0 +80 %;
// at 0.3, 83 % are proven by the block, all but 0.2 % by blocks up to 9 cells a side.
constexpr double kPointsPerCellPerK = 0.5;
constexpr std::size_t kCellsPerTask = 128;
constexpr std::int64_t kMaxRing = 8;  // blocks of up to 17 cells a side before brute force or the tree
constexpr std::size_t kBruteForceBudget = 4'000'000;  // point pairs: ~1/3 of a tree build's instructions
constexpr double kMaxCellsPerAxis = 1e12;  // keeps cell coordinates exact in int64 and double
// With a tree at hand, a block with more candidates than this per neighbour wanted is left to the tree:
// ~11 instructions per candidate against ~3.6k per 12-NN tree query (callgrind; 16 beat 32 on both the
// mapper's 0.1 m local map and the bench's merged 0.05 m map). Clouds of uneven density (a near field,
// two clouds merged) have such cells.
constexpr std::size_t kMaxCandidatesPerK = 16;

struct Grid {
  Eigen::Vector3d lo = Eigen::Vector3d::Zero();
  double h = 1.0;

  [[nodiscard]] VoxelCoord cell(const Eigen::Vector4d& p) const {
    return {static_cast<std::int64_t>(std::floor((p.x() - lo.x()) / h)),
            static_cast<std::int64_t>(std::floor((p.y() - lo.y()) / h)),
            static_cast<std::int64_t>(std::floor((p.z() - lo.z()) / h))};
  }
  [[nodiscard]] Eigen::Vector3d centre(const VoxelCoord& c) const {
    return lo + h * Eigen::Vector3d(static_cast<double>(c.x) + 0.5, static_cast<double>(c.y) + 0.5,
                                    static_cast<double>(c.z) + 0.5);
  }
};

std::size_t occupiedCells(std::span<const Eigen::Vector4d> points, const Grid& grid) {
  VoxelIndexMap map(points.size() / 4);
  for (const auto& p : points) map.findOrInsert(grid.cell(p));
  return map.size();
}

// The 27 cells of a block: the middle one, its 6 faces, 12 edges, 8 corners.
constexpr std::array<std::array<std::int64_t, 3>, 27> kBlockOrder = [] {
  std::array<std::array<std::int64_t, 3>, 27> out{};
  std::size_t o = 0;
  for (int ring = 0; ring <= 3; ++ring) {
    for (std::int64_t dz = -1; dz <= 1; ++dz) {
      for (std::int64_t dy = -1; dy <= 1; ++dy) {
        for (std::int64_t dx = -1; dx <= 1; ++dx) {
          if ((dx != 0) + (dy != 0) + (dz != 0) == ring) out[o++] = {dx, dy, dz};
        }
      }
    }
  }
  return out;
}();

// A point the 3x3x3 block could not prove, during the shell search.
struct ShellQuery {
  std::uint32_t q;
  Eigen::Vector3d p;
  double inner;  // from the point to its own cell's faces
  TopK top;
  bool done = false;
};

// A proven query of the cell being searched: its k nearest are among the block's candidates, so any other
// query q of the cell has k candidates within |q − anchor| + (anchor's k-th distance). That bound is
// usually much tighter than the proof's: fewer candidates are offered, none that could be the answer is
// turned away. Only the proof's bound decides which answers count as proven. (The cell's latest proven
// query: the closest of several is not worth its cost, measured.)
struct Anchor {
  float x, y, z;  // as the query's own coordinates in the block
  float kth;      // its k-th squared distance, as the scan computed it; +inf: no anchor yet
};

// (|q − a| + √kth)², widened for the float rounding of the distances it bounds (relative error of a
// float squared distance: < 5 · 2⁻²⁴; underflow: the absolute term).
float anchorBound(const Anchor& a, float qx, float qy, float qz) {
  const double ex = double(qx) - double(a.x), ey = double(qy) - double(a.y), ez = double(qz) - double(a.z);
  const double reach = std::sqrt(ex * ex + ey * ey + ez * ez) + std::sqrt(double(a.kth));
  return static_cast<float>(reach * reach * (1.0 + 1e-5) + 1e-30);
}

}  // namespace

bool cellKnn(std::span<const Eigen::Vector4d> points, std::size_t k, int num_threads, bool tree_at_hand,
             CellKnn* out, const Deadline& stop) {
  const std::size_t n = points.size();
  if (k == 0 || n < 4 * k) return false;
  Eigen::Vector3d lo = points[0].head<3>(), hi = lo;
  for (const auto& p : points) {
    lo = lo.cwiseMin(p.head<3>());
    hi = hi.cwiseMax(p.head<3>());
  }
  const Eigen::Vector3d extent = hi - lo;
  const double largest = extent.maxCoeff();
  if (!(largest > 0.0) || !std::isfinite(largest)) return false;

  // Cell size: start from the volume per point, then rescale (as for a surface, count ∝ h²) until the
  // occupied cells hold about the wanted number of points each.
  Grid grid;
  grid.lo = lo;
  const Eigen::Vector3d floored = extent.cwiseMax(1e-3 * largest);
  grid.h = std::cbrt(floored.prod() / static_cast<double>(n));
  const double wanted = std::max(2.0, kPointsPerCellPerK * static_cast<double>(k));
  for (int pass = 0; pass < 4; ++pass) {
    if (!(largest / grid.h < kMaxCellsPerAxis)) return false;
    const double per_cell = static_cast<double>(n) / static_cast<double>(occupiedCells(points, grid));
    if (per_cell > 0.7 * wanted && per_cell < 1.4 * wanted) break;
    grid.h *= std::clamp(std::sqrt(wanted / per_cell), 0.25, 4.0);
  }
  if (!(grid.h > 0.0) || !(largest / grid.h < kMaxCellsPerAxis)) return false;

  // Cells in first-seen order; points sorted by cell (counting sort), positions copied in that order.
  VoxelIndexMap map(n / 2);
  std::vector<VoxelCoord> coords;
  std::vector<std::uint32_t> cell_of(n);
  for (std::size_t i = 0; i < n; ++i) {
    const VoxelCoord c = grid.cell(points[i]);
    const std::uint32_t id = map.findOrInsert(c);
    if (id == coords.size()) coords.push_back(c);
    cell_of[i] = id;
  }
  const std::size_t cells = coords.size();
  std::vector<std::uint32_t> begin(cells + 1, 0);
  for (const std::uint32_t c : cell_of) ++begin[c + 1];
  for (std::size_t c = 0; c < cells; ++c) begin[c + 1] += begin[c];
  std::vector<std::uint32_t> order(n);
  {
    std::vector<std::uint32_t> fill(begin.begin(), begin.end() - 1);
    for (std::size_t i = 0; i < n; ++i) order[fill[cell_of[i]]++] = static_cast<std::uint32_t>(i);
  }
  // Positions in that order, one array per axis: a cell's points are contiguous runs to copy.
  std::vector<double> sx(n), sy(n), sz(n);
  for (std::size_t s = 0; s < n; ++s) {
    sx[s] = points[order[s]].x();
    sy[s] = points[order[s]].y();
    sz[s] = points[order[s]].z();
  }

  out->k = k;
  out->neighbors.assign(n * k, Neighbor{});
  out->count.assign(n, 0);
  std::vector<std::uint8_t> proven(n, 0);
  const double block = 1.5 * grid.h;  // half-width of the 3x3x3 block around a cell's centre

  const CandidateScan scan = candidateScan(fastestCandidateScanPath());
  parallelFor(chunkCount(cells, kCellsPerTask), num_threads, [&](std::size_t task) {
    std::vector<float> xs, ys, zs;
    std::vector<std::uint32_t> ids;
    if (tree_at_hand && stop.expired()) return;  // skipped cells stay unproven with no neighbours
    const std::size_t first = task * kCellsPerTask;
    const std::size_t last = std::min(cells, first + kCellsPerTask);
    for (std::size_t c = first; c < last; ++c) {
      const VoxelCoord cc = coords[c];
      const Eigen::Vector3d centre = grid.centre(cc);
      // Candidates: every point of the 27 cells, relative to this cell's centre (small floats: exact enough).
      std::uint32_t runs[27][2];
      std::size_t num_runs = 0, m = 0;
      for (const auto& d : kBlockOrder) {  // nearest cells first: the top-k bound tightens early
        const std::uint32_t other = map.find({cc.x + d[0], cc.y + d[1], cc.z + d[2]});
        if (other == VoxelIndexMap::kNone) continue;
        runs[num_runs][0] = begin[other];
        runs[num_runs][1] = begin[other + 1];
        m += begin[other + 1] - begin[other];
        ++num_runs;
      }
      if (tree_at_hand && m > kMaxCandidatesPerK * k) continue;  // too crowded: unproven, for the tree
      const std::size_t padded = (m + kCandidateLanes - 1) / kCandidateLanes * kCandidateLanes;
      if (xs.size() < padded) {
        xs.resize(padded);
        ys.resize(padded);
        zs.resize(padded);
        ids.resize(padded);
      }
      std::size_t o = 0;
      for (std::size_t r = 0; r < num_runs; ++r) {
        const std::uint32_t b = runs[r][0], e = runs[r][1];
        for (std::uint32_t t = b; t < e; ++t) {
          xs[o + (t - b)] = static_cast<float>(sx[t] - centre.x());
          ys[o + (t - b)] = static_cast<float>(sy[t] - centre.y());
          zs[o + (t - b)] = static_cast<float>(sz[t] - centre.z());
          ids[o + (t - b)] = order[t];
        }
        o += e - b;
      }
      constexpr float kFar = std::numeric_limits<float>::infinity();
      std::fill(xs.begin() + m, xs.begin() + padded, kFar);
      std::fill(ys.begin() + m, ys.begin() + padded, kFar);
      std::fill(zs.begin() + m, zs.begin() + padded, kFar);
      const CandidateBlock candidates{xs.data(), ys.data(), zs.data(), ids.data(), padded};
      Anchor anchor{0.0F, 0.0F, 0.0F, std::numeric_limits<float>::infinity()};
      for (std::uint32_t s = begin[c]; s < begin[c + 1]; ++s) {
        const std::uint32_t q = order[s];
        const Eigen::Vector3d local = points[q].head<3>() - centre;
        const float qx = static_cast<float>(local.x()), qy = static_cast<float>(local.y()),
                    qz = static_cast<float>(local.z());
        // Anything outside the block is at least `margin` away: only candidates closer than that can be
        // proven members (with a relative slack for the float distances), so the rest are never offered.
        const double margin = block - local.cwiseAbs().maxCoeff();
        const float proof_bound = static_cast<float>(margin * margin * (1.0 - 1e-5));
        TopK top{out->neighbors.data() + q * k, k, 0, std::min(proof_bound, anchorBound(anchor, qx, qy, qz))};
        scan(candidates, qx, qy, qz, top);
        out->count[q] = static_cast<std::uint32_t>(top.count);
        proven[q] = top.count == k;
        if (proven[q]) anchor = {qx, qy, qz, top.worst};
      }
    }
  });
  std::vector<std::uint32_t> pending;
  for (std::size_t i = 0; i < n; ++i) {
    if (!proven[i]) pending.push_back(static_cast<std::uint32_t>(i));
  }
  if (tree_at_hand) {  // a tree query costs less than looking further cell by cell
    out->unproven = std::move(pending);
    return true;
  }
  // The few left (sparse places, or near a block face) look further, shell by shell: after the cells
  // within r of its own, a point's k best so far are the answer once the k-th is closer than the faces of
  // that (2r+1)³ block. The pending points of one cell share the look-ups of its shells; each still sees
  // the candidates in the same order as alone. What even r = kMaxRing cannot prove goes further below.
  {
    std::vector<std::uint32_t> by_cell = pending;  // ascending: stable by point within a cell
    std::stable_sort(by_cell.begin(), by_cell.end(),
                     [&](std::uint32_t a, std::uint32_t b) { return cell_of[a] < cell_of[b]; });
    std::vector<std::size_t> group_begin;
    for (std::size_t u = 0; u < by_cell.size(); ++u) {
      if (u == 0 || cell_of[by_cell[u]] != cell_of[by_cell[u - 1]]) group_begin.push_back(u);
    }
    const std::size_t groups = group_begin.size();
    group_begin.push_back(by_cell.size());
    constexpr std::size_t kGroupsPerTask = 64;
    parallelFor(chunkCount(groups, kGroupsPerTask), num_threads, [&](std::size_t task) {
      std::vector<ShellQuery> queries;
      for (std::size_t g = task * kGroupsPerTask; g < std::min(groups, (task + 1) * kGroupsPerTask); ++g) {
        const VoxelCoord cc = coords[cell_of[by_cell[group_begin[g]]]];
        queries.clear();
        for (std::size_t u = group_begin[g]; u < group_begin[g + 1]; ++u) {
          const std::uint32_t q = by_cell[u];
          queries.push_back({q, points[q].head<3>(),
                             grid.h * 0.5 - (points[q].head<3>() - grid.centre(cc)).cwiseAbs().maxCoeff(),
                             TopK{out->neighbors.data() + q * k, k, 0, std::numeric_limits<float>::infinity()}});
        }
        std::size_t open = queries.size();
        for (std::int64_t r = 0; r <= kMaxRing && open > 0; ++r) {
          for (std::int64_t dz = -r; dz <= r; ++dz) {
            for (std::int64_t dy = -r; dy <= r; ++dy) {
              const bool face = std::abs(dz) == r || std::abs(dy) == r;
              for (std::int64_t dx = -r; dx <= r; dx += face ? 1 : 2 * r) {  // inside rows: the two ends only
                const std::uint32_t other = map.find({cc.x + dx, cc.y + dy, cc.z + dz});
                if (other == VoxelIndexMap::kNone) continue;
                for (ShellQuery& sq : queries) {
                  if (sq.done) continue;
                  for (std::uint32_t t = begin[other]; t < begin[other + 1]; ++t) {
                    const double ex = sx[t] - sq.p.x(), ey = sy[t] - sq.p.y(), ez = sz[t] - sq.p.z();
                    const auto d = static_cast<float>(ex * ex + ey * ey + ez * ez);
                    if (d < sq.top.worst) sq.top.offer(order[t], d);
                  }
                }
              }
            }
          }
          const double margin_base = static_cast<double>(r) * grid.h;
          for (ShellQuery& sq : queries) {
            if (sq.done) continue;
            const double margin = margin_base + sq.inner;
            if (sq.top.count == k && static_cast<double>(sq.top.worst) < margin * margin * (1.0 - 1e-5)) {
              proven[sq.q] = 1;
              sq.done = true;
              --open;
            }
          }
        }
        for (const ShellQuery& sq : queries) out->count[sq.q] = static_cast<std::uint32_t>(sq.top.count);
      }
    });
    std::erase_if(pending, [&](std::uint32_t q) { return proven[q] != 0; });
  }
  // A handful left: comparing each with every point is cheaper than building a tree for them.
  if (pending.size() * n <= kBruteForceBudget) {
    parallelFor(pending.size(), num_threads, [&](std::size_t u) {
      const std::uint32_t q = pending[u];
      TopK top{out->neighbors.data() + q * k, k, 0, std::numeric_limits<float>::infinity()};
      const double qx = points[q].x(), qy = points[q].y(), qz = points[q].z();
      for (std::size_t t = 0; t < n; ++t) {
        const double ex = sx[t] - qx, ey = sy[t] - qy, ez = sz[t] - qz;
        const auto d = static_cast<float>(ex * ex + ey * ey + ez * ez);
        if (d < top.worst) top.offer(order[t], d);
      }
      out->count[q] = static_cast<std::uint32_t>(top.count);
    });
    pending.clear();
  }
  out->unproven = std::move(pending);
  return true;
}

}  // namespace rigcal::registration::detail
