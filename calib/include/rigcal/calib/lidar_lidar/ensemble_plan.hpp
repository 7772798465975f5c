#pragma once
// What the lidar-lidar ensemble runs and in which order. Upstream's registrators with its parameters:
// NDT (res 1.0, step 0.1, outlier ratio 0.55), GICP (max corr 0.5), ICP coarse / fine / ultra-fine
// (max_corr_dist_coarse / _fine / _ultra_fine), each solver_iterations; then batched ICP over all frames
// at the same three distances. The order puts the largest expected improvements first so that a
// deadline cuts only the refinements that matter least:
//   1. the most informative frame's full ensemble from the initial guess (the big correction);
//   2. batched ICP over every frame from the best so far (uses all the data at once);
//   3. the other frames' ensembles, each from the candidates so far (guards against a wrong basin);
//   4. re-deskew with the best extrinsic, then batched ICP from {initial, best} (the last millimetres).
#include <string>
#include <vector>

#include "rigcal/config/parameters.hpp"
#include "rigcal/core/pose.hpp"
#include "rigcal/registration/deadline.hpp"
#include "rigcal/registration/point_cloud.hpp"
#include "rigcal/registration/registration_result.hpp"
#include "rigcal/registration/target.hpp"

namespace rigcal::calib {

enum class Registrator { kNdt, kGicp, kIcpCoarse, kIcpFine, kIcpUltraFine };

const char* toString(Registrator r);

/// The per-frame registrators, in upstream's order.
std::vector<Registrator> perFrameRegistrators();

/// The batched-ICP correspondence distances, coarse to fine (0.5 → 0.1 → 0.05 m by default).
std::vector<double> batchedDistances(const config::Parameters& params);

/// Runs one registrator of dataset frame (source → target) from `guess`. ICP coarse is point-to-point
/// (robust far from the solution); fine and ultra-fine are point-to-plane, whose error on a 5 cm voxel
/// map is not biased by the map's point spacing as point-to-point is. Never throws for bad data.
registration::RegistrationResult runRegistrator(Registrator r, const registration::Target& target,
                                                const registration::PointCloud& source, const Pose& guess,
                                                const config::Parameters& params, int num_threads,
                                                const registration::Deadline& deadline);

/// One batched point-to-plane ICP pass over all frames at `max_distance`.
registration::RegistrationResult runBatched(const std::vector<registration::SourceTarget>& frames, const Pose& guess,
                                            double max_distance, const config::Parameters& params, int num_threads,
                                            const registration::Deadline& deadline);

}  // namespace rigcal::calib
