#include "rigcal/calib/lidar_lidar/ensemble_plan.hpp"

#include "rigcal/registration/batched_icp.hpp"
#include "rigcal/registration/gicp.hpp"
#include "rigcal/registration/icp.hpp"
#include "rigcal/registration/ndt.hpp"

namespace rigcal::calib {
namespace {

template <class P>
void common(P& p, const config::Parameters& params, int num_threads) {
  p.max_iterations = params.solver_iterations;
  p.num_threads = num_threads;
  // A calibration cloud may constrain some direction weakly (a VLP-16 sees a few planes); the ensemble's
  // score decides between results, so a weakly conditioned result is still a candidate.
  p.check_degeneracy = false;
  p.transformation_epsilon = 1e-5;
  p.rotation_epsilon = 1e-6;
}

}  // namespace

const char* toString(Registrator r) {
  switch (r) {
    case Registrator::kNdt: return "ndt";
    case Registrator::kGicp: return "gicp";
    case Registrator::kIcpCoarse: return "icp_coarse";
    case Registrator::kIcpFine: return "icp_fine";
    case Registrator::kIcpUltraFine: return "icp_ultra_fine";
  }
  return "?";
}

std::vector<Registrator> perFrameRegistrators() {
  return {Registrator::kNdt, Registrator::kGicp, Registrator::kIcpCoarse, Registrator::kIcpFine,
          Registrator::kIcpUltraFine};
}

std::vector<double> batchedDistances(const config::Parameters& params) {
  return {params.max_corr_dist_coarse, params.max_corr_dist_fine, params.max_corr_dist_ultra_fine};
}

registration::RegistrationResult runRegistrator(Registrator r, const registration::Target& target,
                                                const registration::PointCloud& source, const Pose& guess,
                                                const config::Parameters& params, int num_threads,
                                                const registration::Deadline& deadline) {
  switch (r) {
    case Registrator::kNdt: {
      registration::NdtParams p;
      common(p, params, num_threads);
      p.resolution = 1.0;
      p.step_size = 0.1;
      p.outlier_ratio = 0.55;
      p.transformation_epsilon = 1e-3;  // NDT's optimum is only as sharp as its 1 m voxels; ICP refines
      p.rotation_epsilon = 1e-4;
      p.max_correspondence_distance = params.max_corr_dist_coarse;
      return registration::alignNdt(target, source, guess, p, deadline);
    }
    case Registrator::kGicp: {
      registration::GicpParams p;
      common(p, params, num_threads);
      p.max_correspondence_distance = params.max_corr_dist_coarse;
      return registration::alignGicp(target, source, guess, p, deadline);
    }
    case Registrator::kIcpCoarse:
    case Registrator::kIcpFine:
    case Registrator::kIcpUltraFine: {
      registration::IcpParams p;
      common(p, params, num_threads);
      p.method = r == Registrator::kIcpCoarse ? registration::IcpMethod::kPointToPoint
                                              : registration::IcpMethod::kPointToPlane;
      p.max_correspondence_distance = r == Registrator::kIcpCoarse ? params.max_corr_dist_coarse
                                      : r == Registrator::kIcpFine ? params.max_corr_dist_fine
                                                                   : params.max_corr_dist_ultra_fine;
      return registration::alignIcp(target, source, guess, p, deadline);
    }
  }
  return {};
}

registration::RegistrationResult runBatched(const std::vector<registration::SourceTarget>& frames, const Pose& guess,
                                            double max_distance, const config::Parameters& params, int num_threads,
                                            const registration::Deadline& deadline) {
  registration::BatchedIcpParams p;
  common(p, params, num_threads);
  p.method = registration::IcpMethod::kPointToPlane;
  p.max_correspondence_distance = max_distance;
  return registration::alignBatchedIcp(frames, guess, p, deadline);
}

}  // namespace rigcal::calib
