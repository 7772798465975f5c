#pragma once
// Procedural, seeded scenes. A layout ("parking-lot", "street") places buildings, parked cars, trees,
// poles, signs, bollards, walls, curbs, islands and road paint around the vehicle's path, never within
// `clearance_m` of it, so the same scenario and seed always give the same world.
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "rigcal/sim/scene.hpp"

namespace rigcal::sim {

struct SceneSpec {
  std::string layout = "parking-lot";
  Eigen::Vector2d center{0, 0};
  Eigen::Vector2d size{120, 90};   // extent of the lot (parking-lot); the street follows the path
  double slope_percent = 1.0;      // ground slope, in a seeded direction
  double bump_amplitude_m = 0.04;
  double bump_spacing_m = 5.0;
  double clearance_m = 2.6;        // nothing stands nearer the path's centre line than this
  double grid_cell_m = 2.0;        // ray-caster grid cell (a speed knob, not a physical one)
  std::optional<std::uint64_t> seed;  // default: derived from the scenario seed
};

/// Layout names generateScene accepts.
std::vector<std::string> sceneLayouts();

/// The ground of the scene (needed first: the trajectory rests on it).
Ground makeGround(const SceneSpec& spec, std::uint64_t seed);

/// Builds the scene's content; throws std::invalid_argument for an unknown layout.
SceneContent generateScene(const SceneSpec& spec, std::uint64_t seed, Ground ground,
                           const std::vector<Eigen::Vector2d>& path);

}  // namespace rigcal::sim
