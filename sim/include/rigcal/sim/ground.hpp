#pragma once
// The ground: a gently sloped plane plus smooth random bumps (a periodic quadratic B-spline over a
// lattice of seeded heights: C1, cheap, with known bounds on height and gradient that make the
// ray intersection fast and safe).
#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "rigcal/sim/primitives.hpp"
#include "rigcal/sim/random.hpp"

namespace rigcal::sim {

struct GroundSpec {
  double base_height = 0.0;
  Eigen::Vector2d slope{0.0, 0.0};  // dz/dx, dz/dy (e.g. 0.01 = 1 %)
  double bump_amplitude = 0.04;     // bump heights are uniform in [−a, a] (m)
  double bump_spacing = 5.0;        // lattice spacing of the bumps (m)
};

class Ground {
 public:
  /// A flat, level ground at height 0.
  Ground() : Ground(GroundSpec{0.0, {0.0, 0.0}, 0.0, 5.0}, 0) {}
  Ground(const GroundSpec& spec, std::uint64_t seed);

  [[nodiscard]] double height(double x, double y) const;
  /// Height and its gradient (dz/dx, dz/dy).
  [[nodiscard]] double height(double x, double y, double& gx, double& gy) const;
  [[nodiscard]] Eigen::Vector3d normal(double x, double y) const;
  /// Nearest intersection in [t_min, hit.t); updates hit (material asphalt; the scene sets patches).
  bool intersect(const Ray& ray, double t_min, Hit& hit) const;
  [[nodiscard]] const GroundSpec& spec() const { return spec_; }

 private:
  static constexpr int kLattice = 64;  // power of two: the bumps repeat every 64 spacings
  [[nodiscard]] double bumps(double x, double y, double* gx, double* gy) const;
  [[nodiscard]] double lattice(int i, int j) const {
    return heights_[std::size_t((j & (kLattice - 1)) * kLattice + (i & (kLattice - 1)))];
  }
  /// f(t) = ray height above the ground at t; its derivative in df, the ground gradient in gx, gy.
  [[nodiscard]] double clearance(const Ray& ray, double t, double* df, double* gx = nullptr,
                                 double* gy = nullptr) const;

  GroundSpec spec_;
  std::vector<double> heights_;
  std::vector<double> poly_;  // per lattice cell: 9 coefficients of its biquadratic patch
  double inv_spacing_ = 0.2;
  double max_bump_ = 0;       // bound on |bumps|
  double max_gradient_ = 0;   // bound on |∇bumps| along any unit horizontal direction
};

}  // namespace rigcal::sim
