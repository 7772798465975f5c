#pragma once
// Settings every registration shares (each method's params struct derives from this).
#include <cstddef>

namespace rigcal::registration {

/// Solver settings shared by ICP, GICP, NDT and batched ICP.
struct SolverParams {
  int max_iterations = 64;
  double transformation_epsilon = 1e-4;  // m: stop when an update translates less than this ...
  double rotation_epsilon = 1e-4;        // rad: ... and rotates less than this
  int num_threads = 1;                   // results are identical for any value
  std::size_t min_correspondences = 10;
  bool check_degeneracy = true;
  // conditioning below this → Status::kDegenerate. Measured: real scans 0.15–0.3, a bare 30 m corridor
  // 0.003 (its ends constrain it a little), a plane ~0.
  double degeneracy_threshold = 0.01;
  double initial_lambda = 1e-6;        // Levenberg–Marquardt damping (relative to the Hessian's diagonal)
  // ICP and GICP on 8k+ source points: iterate on a uniform subsample of at least 4096 of them first,
  // then on all points from there (a half to a third of the time). Same convergence test; the result is
  // another local minimum of the matching cost within about the convergence tolerance. NDT ignores it.
  bool coarse_to_fine = true;
};

}  // namespace rigcal::registration
