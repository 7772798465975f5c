#include "rigcal/sim/material.hpp"

#include <array>

namespace rigcal::sim {

const MaterialProperties& properties(Material m) {
  // Rough near-infrared (905 nm) albedos: dark asphalt ~0.1, concrete ~0.3, white paint ~0.7,
  // vegetation is bright in the NIR. Glass mostly transmits, foliage is porous.
  static constexpr std::array<MaterialProperties, std::size_t(Material::kCount)> kTable{{
      {"asphalt", 0.10f, 0.00f, false},
      {"concrete", 0.30f, 0.00f, false},
      {"curb_stone", 0.35f, 0.00f, false},
      {"road_paint", 0.70f, 0.00f, false},
      {"grass", 0.45f, 0.02f, false},
      {"brick", 0.25f, 0.00f, false},
      {"plaster", 0.55f, 0.00f, false},
      {"glass", 0.08f, 0.60f, false},
      {"metal", 0.40f, 0.05f, false},
      {"car_paint", 0.35f, 0.03f, false},
      {"tyre", 0.05f, 0.02f, false},
      {"bark", 0.25f, 0.00f, false},
      {"foliage", 0.50f, 0.35f, false},
      {"retro_reflector", 0.95f, 0.00f, true},
  }};
  return kTable[std::size_t(m)];
}

}  // namespace rigcal::sim
