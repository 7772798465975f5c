#include "rigcal/sim/ground.hpp"

#include <algorithm>
#include <cmath>

namespace rigcal::sim {

Ground::Ground(const GroundSpec& spec, std::uint64_t seed) : spec_(spec) {
  Rng rng(seed);
  heights_.resize(std::size_t(kLattice) * kLattice);
  for (double& h : heights_) h = rng.uniform(-spec.bump_amplitude, spec.bump_amplitude);
  inv_spacing_ = 1.0 / spec.bump_spacing;
  double hi = 0, diff = 0;
  for (int j = 0; j < kLattice; ++j)
    for (int i = 0; i < kLattice; ++i) {
      hi = std::max(hi, std::abs(lattice(i, j)));
      diff = std::max({diff, std::abs(lattice(i + 1, j) - lattice(i, j)),
                       std::abs(lattice(i, j + 1) - lattice(i, j))});
    }
  max_bump_ = hi;
  // The quadratic B-spline over lattice cell (i, j) is a biquadratic polynomial in the cell's local
  // coordinates: precompute its 9 coefficients. Lattice point k sits at (k + 0.5)·spacing, so the
  // cell blends points i − 1, i, i + 1 with the basis ((1−a)²/2, 1/2 + a − a², a²/2).
  static constexpr double kBasis[3][3] = {{0.5, -1.0, 0.5}, {0.5, 1.0, -1.0}, {0.0, 0.0, 0.5}};
  poly_.assign(std::size_t(kLattice) * kLattice * 9, 0.0);
  for (int j = 0; j < kLattice; ++j)
    for (int i = 0; i < kLattice; ++i) {
      double* c = &poly_[std::size_t((j * kLattice + i) * 9)];
      for (int r = 0; r < 3; ++r)
        for (int q = 0; q < 3; ++q) {
          const double l = lattice(i - 1 + q, j - 1 + r);
          for (int k = 0; k < 3; ++k)
            for (int m = 0; m < 3; ++m) c[3 * k + m] += kBasis[q][k] * kBasis[r][m] * l;
        }
    }
  // ∂B/∂x is a convex combination of neighbour differences / spacing, likewise ∂B/∂y; along a unit
  // horizontal direction the derivative is bounded by √2 times that.
  max_gradient_ = std::sqrt(2.0) * diff * inv_spacing_;
}

double Ground::bumps(double x, double y, double* gx, double* gy) const {
  if (max_bump_ == 0) {
    if (gx) *gx = *gy = 0;
    return 0;
  }
  const double u = x * inv_spacing_, v = y * inv_spacing_;
  // floor without a libm call (no SSE4.1 in the baseline ISA); |u|, |v| are far inside int range.
  int i = int(u), j = int(v);
  i -= u < double(i);
  j -= v < double(j);
  const double a = u - i, b = v - j;
  const double* c = &poly_[std::size_t(((j & (kLattice - 1)) * kLattice + (i & (kLattice - 1))) * 9)];
  // c[3k + m] multiplies a^k·b^m.
  const double r0 = c[0] + b * (c[1] + b * c[2]), r1 = c[3] + b * (c[4] + b * c[5]), r2 = c[6] + b * (c[7] + b * c[8]);
  if (gx) {
    const double s0 = c[1] + 2 * b * c[2], s1 = c[4] + 2 * b * c[5], s2 = c[7] + 2 * b * c[8];
    *gx = (r1 + 2 * a * r2) * inv_spacing_;
    *gy = (s0 + a * (s1 + a * s2)) * inv_spacing_;
  }
  return r0 + a * (r1 + a * r2);
}

double Ground::height(double x, double y) const {
  return spec_.base_height + spec_.slope.x() * x + spec_.slope.y() * y + bumps(x, y, nullptr, nullptr);
}

double Ground::height(double x, double y, double& gx, double& gy) const {
  const double h = bumps(x, y, &gx, &gy);
  gx += spec_.slope.x();
  gy += spec_.slope.y();
  return spec_.base_height + spec_.slope.x() * x + spec_.slope.y() * y + h;
}

Eigen::Vector3d Ground::normal(double x, double y) const {
  double gx = 0, gy = 0;
  (void)height(x, y, gx, gy);
  return Eigen::Vector3d(-gx, -gy, 1.0).normalized();
}

double Ground::clearance(const Ray& ray, double t, double* df, double* gx, double* gy) const {
  const Eigen::Vector3d p = ray.origin + t * ray.dir;
  double hx = 0, hy = 0;
  const double h = height(p.x(), p.y(), hx, hy);
  if (df) *df = ray.dir.z() - hx * ray.dir.x() - hy * ray.dir.y();
  if (gx) {
    *gx = hx;
    *gy = hy;
  }
  return p.z() - h;
}

bool Ground::intersect(const Ray& ray, double t_min, Hit& hit) const {
  // The ray's height above the sloped plane is linear in t: p0 + p1·t. A crossing of the bumpy
  // ground can only happen where that height is within ±max_bump_.
  const Eigen::Vector3d& o = ray.origin;
  const Eigen::Vector3d& d = ray.dir;
  const double p0 = o.z() - (spec_.base_height + spec_.slope.x() * o.x() + spec_.slope.y() * o.y());
  const double p1 = d.z() - spec_.slope.x() * d.x() - spec_.slope.y() * d.y();
  if (p1 >= 0) return false;  // level or rising against the plane: stays clear of the ground
  const double band_in = (p0 - max_bump_) / -p1, band_out = (p0 + max_bump_) / -p1;
  double lo = std::max(t_min, band_in), hi = std::min(hit.t, band_out);
  if (lo > hi) return false;  // equal on a bump-free ground: the plane crossing itself
  // Above the band the clearance is ≥ 0 and below it ≤ 0; only cut ends need checking.
  if (lo > band_in && clearance(ray, lo, nullptr) <= 0) return false;  // t_min inside the ground
  const double horizontal = std::sqrt(d.x() * d.x() + d.y() * d.y());
  if (-p1 <= max_gradient_ * horizontal * 1.01) {
    // Grazing ray: the clearance may not be monotonic. March in steps short against the bump scale
    // until it changes sign, and bracket the first crossing.
    const double step = 0.25 * spec_.bump_spacing / std::max(horizontal, 1e-3);
    double t = lo;
    bool crossed = false;
    while (t < hi) {
      const double tn = std::min(t + step, hi);
      if (clearance(ray, tn, nullptr) <= 0) {
        lo = t;
        hi = tn;
        crossed = true;
        break;
      }
      t = tn;
    }
    if (!crossed) return false;
  } else if (hi < band_out && clearance(ray, hi, nullptr) > 0) {
    return false;  // the crossing lies beyond hit.t
  }
  // Safeguarded Newton inside the bracket [lo, hi] (clearance > 0 at lo, ≤ 0 at hi), starting at
  // the sloped plane's crossing.
  double t = std::clamp(p0 / -p1, lo, hi);
  double gx = 0, gy = 0;
  bool have_gradient = false;
  for (int iter = 0; iter < 50; ++iter) {
    double df = 0;
    const double f = clearance(ray, t, &df, &gx, &gy);
    have_gradient = std::abs(f) < 1e-9;
    if (have_gradient) break;
    if (f > 0)
      lo = t;
    else
      hi = t;
    double tn = (df < 0) ? t - f / df : 0.5 * (lo + hi);
    if (!(tn > lo && tn < hi)) tn = 0.5 * (lo + hi);
    t = tn;
    if (hi - lo < 1e-9) break;
  }
  if (t >= hit.t || t < t_min) return false;
  const Eigen::Vector3d p = o + t * d;
  hit.t = t;
  hit.normal = have_gradient ? Eigen::Vector3d(-gx, -gy, 1.0).normalized() : normal(p.x(), p.y());
  hit.material = Material::kAsphalt;
  return true;
}

}  // namespace rigcal::sim
