#pragma once
// Waiting for a parked vehicle: `rigcal calibrate --static` accumulates only once the mapping lidar's
// sweeps have agreed for a while, so a recording (or a live session) may start with the vehicle still
// rolling into the bay. Each mapping sweep is registered (point-to-plane ICP on 0.2 m voxels, from the
// identity) to the first sweep of the current still stretch; one further than static_max_motion_m /
// static_max_motion_deg from it starts a new stretch. The vehicle has settled once a stretch lasts
// `settle_s`.
#include <memory>
#include <optional>
#include <string>

#include "rigcal/config/parameters.hpp"
#include "rigcal/core/pose.hpp"
#include "rigcal/core/scan.hpp"

namespace rigcal::calib {

/// A sweep registered to a reference sweep of the same lidar (the stillness checks' yardstick).
class SweepRegistrar {
 public:
  explicit SweepRegistrar(const Scan& reference);
  ~SweepRegistrar();
  SweepRegistrar(const SweepRegistrar&) = delete;
  SweepRegistrar& operator=(const SweepRegistrar&) = delete;
  /// T_reference_sweep, or nullopt when either sweep is too sparse to register or the ICP found no
  /// overlap (treat as moved: nothing says it stood still).
  std::optional<Pose> motion(const Scan& sweep, const Pose& start = Pose::Identity()) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

class StillnessWatch {
 public:
  explicit StillnessWatch(const config::Parameters& params, double settle_s = 0.5);
  ~StillnessWatch();
  StillnessWatch(const StillnessWatch&) = delete;
  StillnessWatch& operator=(const StillnessWatch&) = delete;

  /// Feeds the next mapping sweep (in stamp order); true once the vehicle has settled (and from then on:
  /// later sweeps are not looked at).
  bool add(const Scan& sweep);
  [[nodiscard]] bool settled() const { return settled_at_.has_value(); }
  [[nodiscard]] std::size_t sweeps() const { return sweeps_; }
  /// Stamp of the sweep at which the vehicle had been still for settle_s.
  [[nodiscard]] std::optional<TimeNs> settledAt() const { return settled_at_; }
  /// Seconds from the first sweep seen to settledAt() (or to the last sweep seen).
  [[nodiscard]] double waitedS() const;
  /// One line for an input that ended before the vehicle settled: how long it was watched, the longest
  /// still stretch, the limits.
  [[nodiscard]] std::string neverStillMessage() const;

 private:
  double settle_s_, limit_m_, limit_deg_;
  std::unique_ptr<SweepRegistrar> reference_;
  TimeNs reference_stamp_ = 0;
  std::optional<TimeNs> first_stamp_, last_stamp_, settled_at_;
  double longest_still_s_ = 0.0;
  std::size_t sweeps_ = 0;
};

}  // namespace rigcal::calib
