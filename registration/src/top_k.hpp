#pragma once
// Private: the k nearest of one query, kept sorted while candidates are offered one at a time.
#include <cstddef>
#include <cstdint>

#include "rigcal/registration/nearest_neighbors.hpp"

namespace rigcal::registration::detail {

/// The k best of the candidates offered, closest first; of equally distant ones the first offered wins
/// (so the answer is the first k of the offers stably sorted by distance: independent of how a caller
/// skips candidates that could not have entered).
struct TopK {
  Neighbor* out;
  std::size_t k;
  std::size_t count = 0;
  float worst;  // distance a candidate must beat: the caller's bound until k are found

  void offer(std::uint32_t i, float d) {
    if (!(d < worst)) return;
    std::size_t pos = count < k ? count++ : k - 1;
    while (pos > 0 && out[pos - 1].sq_distance > d) {
      out[pos] = out[pos - 1];
      --pos;
    }
    out[pos] = {i, d};
    if (count == k) worst = out[k - 1].sq_distance;
  }
};

}  // namespace rigcal::registration::detail
