#include "rigcal/registration/ndt.hpp"

#include <atomic>
#include <cmath>
#include <cstdio>

#include <Eigen/Cholesky>

#include "rigcal/registration/parallel.hpp"
#include "kernels.hpp"
#include "solver.hpp"

namespace rigcal::registration {

namespace {

// A cell whose Gaussian has fallen below exp(−30) at the point (about 8σ away) adds nothing measurable.
constexpr double kNegligible = 30.0;

class NdtObjective final : public detail::Objective {
 public:
  NdtObjective(const NdtGrid& grid, const PointCloud& source, const NdtParams& params)
      : grid_(grid), source_(source), params_(params) {
    // PCL's constants (Magnusson 2009, eq. 6.8): a Gaussian plus a uniform outlier floor, fitted by
    // a single Gaussian-shaped score so the derivatives stay simple.
    const double c1 = 10.0 * (1.0 - params.outlier_ratio);
    const double c2 = params.outlier_ratio / std::pow(params.resolution, 3);
    const double d3 = -std::log(c2);
    d1_ = -std::log(c1 + c2) - d3;
    d2_ = -2.0 * std::log((-std::log(c1 * std::exp(-0.5) + c2) - d3) / d1_);
    chunks_ = chunkCount(source.size(), kDefaultChunk);
  }

  std::optional<detail::LinearSystem> linearize(const Pose& T, const Deadline& deadline) override {
    std::optional<Sums> sums;
    if (cached_ && cached_at_ == T.matrix()) {
      sums = std::move(cached_);
    } else {
      sums = run(T, deadline);
    }
    cached_.reset();
    if (!sums) return std::nullopt;
    if (Eigen::LLT<detail::Matrix6d>(sums->H_newton).info() == Eigen::Success) sums->sys.H = sums->H_newton;
    return sums->sys;
  }
  // NDT has no fixed matches, so the cost at a trial pose is a full pass anyway: linearise there too and
  // keep it, since an accepted trial pose is exactly where the next linearize() runs.
  std::optional<double> cost(const Pose& T, const Deadline& deadline, bool /*then_linearize*/) override {
    cached_ = run(T, deadline);
    if (!cached_) return std::nullopt;
    cached_at_ = T.matrix();
    return cached_->sys.cost;
  }
  [[nodiscard]] bool reportsNeighborMetrics() const override { return false; }
  [[nodiscard]] double maxStep() const override { return params_.step_size; }

 private:
  // What a chunk adds up. H_newton is the score's Hessian (without the transform's second derivatives),
  // exact and quadratically convergent near the optimum but indefinite far from it; H_gauss keeps only
  // the w·Σ⁻¹ part (always PSD, the reweighted Gauss–Newton / IRLS matrix). linearize() uses the first
  // when it is positive definite and falls back to the second.
  struct Sums {
    detail::LinearSystem sys;  // sys.H is H_gauss
    detail::Matrix6d H_newton = detail::Matrix6d::Zero();
    Sums& operator+=(const Sums& o) {
      sys += o.sys;
      H_newton += o.H_newton;
      return *this;
    }
  };

  std::optional<Sums> run(const Pose& T, const Deadline& deadline) const {
    const Eigen::Matrix4d M = T.matrix();
    std::atomic<bool> stopped{false};
    Sums total = parallelReduce(chunks_, params_.num_threads, Sums{}, [&](std::size_t t) {
      Sums part;
      if (stopped.load(std::memory_order_relaxed) || deadline.expired()) {
        stopped.store(true, std::memory_order_relaxed);
        return part;
      }
      const NdtCell* cells[27];
      std::size_t n = 0;
      NdtGrid::Voxel last;
      bool have_last = false;  // consecutive scan points often share a voxel: reuse its lookups
      const std::size_t end = std::min(source_.size(), (t + 1) * kDefaultChunk);
      for (std::size_t i = t * kDefaultChunk; i < end; ++i) {
        const Eigen::Vector4d x = M * source_.points[i];
        NdtGrid::Voxel v;
        if (!grid_.voxelOf(x, &v)) continue;
        if (!have_last || !(v == last)) {
          n = grid_.neighbors(v, params_.neighborhood, cells);
          last = v;
          have_last = true;
        }
        if (n == 0) continue;
        ++part.sys.inliers;
        Eigen::Vector3d u = Eigen::Vector3d::Zero();
        Eigen::Matrix3d W = Eigen::Matrix3d::Zero();
        Eigen::Matrix3d V = Eigen::Matrix3d::Zero();  // the −d2·(Σ⁻¹d)(Σ⁻¹d)ᵀ part
        for (std::size_t c = 0; c < n; ++c) {
          const Eigen::Vector4d d = x - cells[c]->mean;
          const Eigen::Vector4d Cd = cells[c]->inverse_covariance * d;
          const double exponent = 0.5 * d2_ * d.dot(Cd);
          if (exponent > kNegligible) continue;  // contributes < 1e-13 of a matched point: skip the exp
          const double e = std::exp(-exponent);
          part.sys.cost += d1_ * e;  // d1 < 0: lower is better
          // Gradient of d1·e w.r.t. x: w·Σ⁻¹d with w = −d1·d2·e ≥ 0.
          const double w = -d1_ * d2_ * e;
          const Eigen::Vector3d g = Cd.head<3>();
          u += w * g;
          W += w * cells[c]->inverse_covariance.topLeftCorner<3, 3>();
          V.noalias() -= (w * d2_) * g * g.transpose();
        }
        const Eigen::Vector3d q = x.head<3>();
        detail::addWeightedHessian(W, q, part.sys.H);
        detail::addWeightedHessian(W + V, q, part.H_newton);
        detail::addGradient(q, u, part.sys.b);
      }
      detail::mirrorUpper(part.sys.H);
      detail::mirrorUpper(part.H_newton);
      return part;
    });
    if (stopped.load()) return std::nullopt;
    return total;
  }

  std::optional<Sums> cached_;
  Eigen::Matrix4d cached_at_ = Eigen::Matrix4d::Zero();
  const NdtGrid& grid_;
  const PointCloud& source_;
  const NdtParams& params_;
  double d1_ = 0.0, d2_ = 0.0;
  std::size_t chunks_ = 0;
};

}  // namespace

RegistrationResult alignNdt(const Target& target, const PointCloud& source, const Pose& guess,
                            const NdtParams& params, const Deadline& deadline) {
  constexpr const char* kName = "NDT";
  const SourceTarget pair{&source, &target};
  std::string bad = detail::validateInputs({&pair, 1}, guess, params, params.max_correspondence_distance);
  char buf[160];
  if (bad.empty() && !(params.outlier_ratio > 0.0 && params.outlier_ratio < 1.0)) {
    std::snprintf(buf, sizeof buf, "outlier_ratio must be in (0, 1), got %g", params.outlier_ratio);
    bad = buf;
  }
  if (bad.empty() && !(params.step_size > 0.0)) bad = "step_size must be > 0";
  const NdtGrid* grid = bad.empty() ? target.ndtGrid(params.resolution) : nullptr;
  if (bad.empty() && grid == nullptr) {
    std::snprintf(buf, sizeof buf, "target has no NDT grid of resolution %g m (add it to ndt_resolutions)",
                  params.resolution);
    bad = buf;
  }
  if (bad.empty() && grid->empty()) bad = "target's NDT grid has no voxel with enough points";
  if (!bad.empty()) return detail::invalid(guess, std::string(kName) + ": " + bad, params.max_correspondence_distance);
  NdtObjective objective(*grid, source, params);
  const std::span<const SourceTarget> pairs(&pair, 1);
  const detail::SolveOutcome outcome = detail::solve(objective, guess, params, deadline);
  return detail::finish(outcome, objective, pairs, params.max_correspondence_distance, params, deadline, kName);
}

}  // namespace rigcal::registration
