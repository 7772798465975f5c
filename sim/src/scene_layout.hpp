#pragma once
// Internal to the scene generator: placement bookkeeping shared by the layouts.
#include <vector>

#include "rigcal/sim/scene_generator.hpp"
#include "rigcal/sim/scene_objects.hpp"

namespace rigcal::sim::detail {

/// Tracks what is taken: the path corridor and every placed object's footprint.
class Placer {
 public:
  Placer(const std::vector<Eigen::Vector2d>& path, double clearance) : path_(path), clearance_(clearance) {}
  /// True when r keeps `clearance` from the path and `margin` from every placed footprint.
  [[nodiscard]] bool free(const Rect2& r, double margin = 0.3) const;
  [[nodiscard]] bool clearOfPath(const Rect2& r) const;
  void occupy(const Rect2& r) { taken_.push_back(r); }
  [[nodiscard]] const std::vector<Eigen::Vector2d>& path() const { return path_; }

 private:
  std::vector<Eigen::Vector2d> path_;
  double clearance_;
  std::vector<Rect2> taken_;
};

void layoutParkingLot(const SceneSpec& spec, ObjectBuilder& build, Placer& place, Rng& rng);
void layoutStreet(const SceneSpec& spec, ObjectBuilder& build, Placer& place, Rng& rng);
void layoutContainerYard(const SceneSpec& spec, ObjectBuilder& build, SceneContent& content, Placer& place,
                         Rng& rng);
// scene_layout_bay.cpp: a parked vehicle's calibration bays (they add primitives straight to `content`).
void layoutCalibrationBay(const SceneSpec& spec, ObjectBuilder& build, Placer& place, Rng& rng, SceneContent& content);
void layoutBayOneWall(const SceneSpec& spec, ObjectBuilder& build, Placer& place, Rng& rng, SceneContent& content);

}  // namespace rigcal::sim::detail
