#pragma once
// Runs any of the four registrations by name, so tests can loop over them.
#include <string>
#include <vector>

#include "rigcal/registration/batched_icp.hpp"
#include "rigcal/registration/gicp.hpp"
#include "rigcal/registration/icp.hpp"
#include "rigcal/registration/ndt.hpp"

namespace rigcal::registration::test {

enum class Method { kPointToPoint, kPointToPlane, kGicp, kNdt };

inline std::string name(Method m) {
  switch (m) {
    case Method::kPointToPoint:
      return "PointToPoint";
    case Method::kPointToPlane:
      return "PointToPlane";
    case Method::kGicp:
      return "Gicp";
    case Method::kNdt:
      return "Ndt";
  }
  return "?";
}

inline const std::vector<Method>& allMethods() {
  static const std::vector<Method> all{Method::kPointToPoint, Method::kPointToPlane, Method::kGicp, Method::kNdt};
  return all;
}

struct RunOptions {
  int threads = 1;
  double max_distance = 1.0;
  double ndt_resolution = 1.0;
  int max_iterations = 64;
  std::size_t min_correspondences = 10;
  bool coarse_to_fine = true;
};

/// The source must carry covariances for GICP; the target everything the method needs.
inline RegistrationResult run(Method m, const Target& target, const PointCloud& source, const Pose& guess,
                              const RunOptions& o = {}, const Deadline& deadline = {}) {
  auto common = [&](SolverParams& p) {
    p.num_threads = o.threads;
    p.max_iterations = o.max_iterations;
    p.min_correspondences = o.min_correspondences;
    p.coarse_to_fine = o.coarse_to_fine;
  };
  switch (m) {
    case Method::kPointToPoint:
    case Method::kPointToPlane: {
      IcpParams p;
      common(p);
      p.method = m == Method::kPointToPoint ? IcpMethod::kPointToPoint : IcpMethod::kPointToPlane;
      p.max_correspondence_distance = o.max_distance;
      return alignIcp(target, source, guess, p, deadline);
    }
    case Method::kGicp: {
      GicpParams p;
      common(p);
      p.max_correspondence_distance = o.max_distance;
      return alignGicp(target, source, guess, p, deadline);
    }
    case Method::kNdt: {
      NdtParams p;
      common(p);
      p.resolution = o.ndt_resolution;
      p.max_correspondence_distance = o.max_distance;
      return alignNdt(target, source, guess, p, deadline);
    }
  }
  return {};
}

/// Everything any method needs.
inline TargetOptions fullTarget(double ndt_resolution = 1.0, int threads = 1) {
  TargetOptions o;
  o.normals_and_covariances = true;
  o.ndt_resolutions = {ndt_resolution};
  o.num_threads = threads;
  return o;
}

}  // namespace rigcal::registration::test
