#pragma once
// A scan's finite positions as Eigen vectors: what the cloud-pair registration and the shared-floor
// refinement fit planes and search poses on. Private to calib/.
#include <vector>

#include <Eigen/Core>

#include "rigcal/core/scan.hpp"

namespace rigcal::calib::detail {

inline std::vector<Eigen::Vector3d> finitePoints(const Scan& s) {
  std::vector<Eigen::Vector3d> out;
  out.reserve(s.size());
  for (std::size_t i = 0; i < s.size(); ++i) {
    const Eigen::Vector3d p(s.x[i], s.y[i], s.z[i]);
    if (p.allFinite()) out.push_back(p);
  }
  return out;
}

}  // namespace rigcal::calib::detail
