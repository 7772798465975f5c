#include "rigcal/pipeline/target_window_picks.hpp"

#include <algorithm>
#include <numeric>

namespace rigcal::pipeline {

int targetKeyframeStride(int window_keyframes, std::size_t max_picks) {
  const int n = std::max(0, window_keyframes);
  const int on_stride_allowed = int(std::max<std::size_t>(max_picks, 2)) - 1;
  // A window of 2n + 1 keyframes holds at most 2n / stride + 1 keyframes on the stride.
  int stride = 1;
  while (2 * n / stride + 1 > on_stride_allowed) ++stride;
  return stride;
}

bool isTargetCloud(const MappingFrame& f, int own_keyframe, int stride) {
  if (!f.isKeyframe() || f.keyframe_index < 0) return false;
  return f.keyframe_index == own_keyframe || f.keyframe_index % std::max(1, stride) == 0;
}

std::vector<std::size_t> spreadWindowPicks(std::size_t count, std::size_t own, std::size_t max_picks) {
  std::vector<std::size_t> picked;
  if (max_picks == 0 || count <= max_picks) {
    picked.resize(count);
    std::iota(picked.begin(), picked.end(), std::size_t{0});
    return picked;
  }
  const std::size_t gaps = std::max<std::size_t>(max_picks - 1, 1);
  for (std::size_t k = 0; k < max_picks; ++k) picked.push_back(k * (count - 1) / gaps);
  if (own < count && std::find(picked.begin(), picked.end(), own) == picked.end()) {
    // Replace the nearest pick by the keyframe's own cloud.
    auto nearest = std::min_element(picked.begin(), picked.end(), [&](std::size_t a, std::size_t b) {
      const auto da = a > own ? a - own : own - a;
      const auto db = b > own ? b - own : own - b;
      return da < db;
    });
    *nearest = own;
  }
  std::sort(picked.begin(), picked.end());
  picked.erase(std::unique(picked.begin(), picked.end()), picked.end());
  return picked;
}

}  // namespace rigcal::pipeline
