#pragma once
// Private: the sums a neighbourhood's covariance is made of, Σd and Σd·dᵀ over a point's neighbours, d
// their offsets from the point, added in neighbour order. The AVX2 path keeps each sum in one lane of a
// register and does, lane by lane, the scalar loop's products and sums (no fused multiply-add): same bits.
#include <cstddef>

#include <Eigen/Core>

#include "rigcal/registration/nearest_neighbors.hpp"

namespace rigcal::registration::detail {

struct OffsetSums {
  double s[4];   // Σ dx, dy, dz (lane 3 unused)
  double x[4];   // Σ dx·dx, dx·dy, dx·dz (lane 3 unused)
  double yz[4];  // Σ dy·dy, dy·dz, dz·dz (lane 3 unused)
};

using OffsetSumsKernel = void (*)(const Eigen::Vector4d* points, const Neighbor* nb, std::size_t found,
                                  const Eigen::Vector4d& origin, OffsetSums* out);

/// The plain loop, the reference.
void offsetSumsScalar(const Eigen::Vector4d* points, const Neighbor* nb, std::size_t found,
                      const Eigen::Vector4d& origin, OffsetSums* out);
/// AVX2 where the CPU has it, else the plain loop.
OffsetSumsKernel fastestOffsetSums();

}  // namespace rigcal::registration::detail
