#pragma once
// The registration loops run on rigcal::parallelFor / parallelReduce (core/parallel.hpp), in tasks of
// kDefaultChunk points.
#include <cstddef>

#include "rigcal/core/parallel.hpp"

namespace rigcal::registration {

/// Points per task in the registration loops: small enough to poll a deadline often, large enough that
/// handing out a task costs nothing measurable.
inline constexpr std::size_t kDefaultChunk = 512;

using rigcal::chunkCount;
using rigcal::parallelFor;
using rigcal::parallelReduce;

}  // namespace rigcal::registration
