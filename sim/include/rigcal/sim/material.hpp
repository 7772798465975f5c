#pragma once
// Surface materials. A material sets the return's intensity (its diffuse reflectivity) and how often
// a return is lost (glass and foliage lose many); retro-reflectors return strongly at any angle.
#include <cstdint>

namespace rigcal::sim {

enum class Material : std::uint8_t {
  kAsphalt,
  kConcrete,
  kCurbStone,
  kRoadPaint,
  kGrass,
  kBrick,
  kPlaster,
  kGlass,
  kMetal,
  kCarPaint,
  kTyre,
  kBark,
  kFoliage,
  kRetroReflector,
  kCount
};

struct MaterialProperties {
  const char* name;
  float reflectivity;  // diffuse albedo at the laser wavelength, 0..1
  float dropout;       // extra probability that a return is lost
  bool retro;          // retro-reflective: intensity independent of incidence angle
};

const MaterialProperties& properties(Material m);

}  // namespace rigcal::sim
