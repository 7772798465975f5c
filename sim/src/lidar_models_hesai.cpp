#include <vector>

#include "rigcal/sim/lidar_model.hpp"

// Hesai PandarXT32. Elevation and azimuth offsets are the vendor's angle-correction file
// (PandarXT32.csv); channel timing from the XT32 user manual: 50 µs blocks, channel i fires
// 0.368 + 1.512·i µs into its block.
namespace rigcal::sim::detail {
namespace {

struct HesaiChannel {
  double elevation_deg, azimuth_deg;
};

constexpr HesaiChannel kXt32[] = {
    {14.972363, 0.082385}, {13.952372, 0.076529}, {12.938632, 0.07824}, {11.931141, 0.076267},
    {10.926151, 0.064337}, {9.92241, 0.059942}, {8.917419, 0.049319}, {7.917429, 0.044992},
    {6.919938, 0.034446}, {5.919947, 0.027658}, {4.922456, 0.020896}, {3.924965, 0.014147},
    {2.929974, 0.008668}, {1.936233, -0.000548}, {0.944992, -0.007248}, {-0.0475, -0.015201},
    {-1.039991, -0.025654}, {-2.036232, -0.031126}, {-3.028723, -0.037837}, {-4.024964, -0.045822},
    {-5.019955, -0.061312}, {-6.016196, -0.06557}, {-7.013687, -0.068599}, {-8.013678, -0.076658},
    {-9.011169, -0.088476}, {-10.011159, -0.09158}, {-11.00615, -0.098438}, {-12.003641, -0.092837},
    {-12.996131, -0.102247}, {-13.997372, -0.104231}, {-15.004862, -0.118783}, {-16.023602, -0.129679},
};

}  // namespace

LidarModel makePandarXt32() {
  LidarModel m;
  m.name = "PandarXT32";
  m.vendor = LidarVendor::kHesai;
  m.rotation_hz = 10.0;
  m.period_num_ns = 50'000;  // 2000 blocks per rotation: 0.18° resolution at 10 Hz
  m.distance_unit_m = 0.004;
  m.min_range_m = 0.05;
  m.max_range_m = 120.0;
  // Hesai's decoders place a channel at block azimuth + its table offset, not by firing time.
  m.azimuth_follows_firing_time = false;
  for (std::size_t i = 0; i < std::size(kXt32); ++i)
    m.beams.push_back({kXt32[i].elevation_deg, kXt32[i].azimuth_deg, TimeNs(368 + 1'512 * i)});
  return m;
}

}  // namespace rigcal::sim::detail
