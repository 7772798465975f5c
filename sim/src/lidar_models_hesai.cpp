#include <cstdint>
#include <vector>

#include "rigcal/sim/lidar_model.hpp"

// Hesai PandarXT32 and Pandar64. Elevation and azimuth offsets are the vendors' angle-correction files
// (PandarXT32.csv, Pandar64.csv); XT32 timing from its user manual: 50 µs blocks, channel i fires
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

// Pandar64.csv (the unit recorded in ../shared/data/hesai/pandar64_dual.pcap).
constexpr HesaiChannel kPandar64[] = {
    {14.9, -1.042}, {11.05, -1.042}, {8.077, -1.042}, {5.075, -1.042},
    {3.058, -1.042}, {2.046, -1.042}, {1.878, 1.042}, {1.706, 3.125},
    {1.54, 5.208}, {1.369, -5.208}, {1.202, -3.125}, {1.031, -1.042},
    {0.864, 1.042}, {0.693, 3.125}, {0.526, 5.208}, {0.355, -5.208},
    {0.187, -3.125}, {0.018, -1.042}, {-0.151, 1.042}, {-0.319, 3.125},
    {-0.49, 5.208}, {-0.657, -5.208}, {-0.827, -3.125}, {-0.995, -1.042},
    {-1.166, 1.042}, {-1.333, 3.125}, {-1.504, 5.208}, {-1.67, -5.208},
    {-1.842, -3.125}, {-2.01, -1.042}, {-2.18, 1.042}, {-2.347, 3.125},
    {-2.518, 5.208}, {-2.682, -5.208}, {-2.855, -3.125}, {-3.022, -1.042},
    {-3.192, 1.042}, {-3.357, 3.125}, {-3.53, 5.208}, {-3.694, -5.208},
    {-3.866, -3.125}, {-4.032, -1.042}, {-4.203, 1.042}, {-4.367, 3.125},
    {-4.54, 5.208}, {-4.702, -5.208}, {-4.874, -3.125}, {-5.039, -1.042},
    {-5.211, 1.042}, {-5.373, 3.125}, {-5.547, 5.208}, {-5.708, -5.208},
    {-5.88, -3.125}, {-6.043, -1.042}, {-7.045, -1.042}, {-8.041, -1.042},
    {-9.042, -1.042}, {-10.027, -1.042}, {-11.014, -1.042}, {-11.988, -1.042},
    {-12.956, -1.042}, {-13.912, -1.042}, {-18.871, -1.042}, {-24.879, -1.042},
};

// Pandar64 user manual, firing-time table: channel c fires this long (ns) before the time of its
// block (the same table as drivers/src/hesai/hesai_packet.cpp; here shifted so the earliest laser
// fires at 0, at the start of its 55.56 µs round).
constexpr std::int32_t kPandar64FiringNs[64] = {
    -23180, -21876, -20572, -19268, -17964, -16660, -11444, -46796, -7532,  -36956, -50732, -54668, -40892,
    -44828, -31052, -34988, -48764, -52700, -38924, -42860, -29084, -33020, -46796, -25148, -36956, -50732,
    -27116, -40892, -44828, -31052, -34988, -48764, -25148, -38924, -42860, -29084, -33020, -52700, -6228,
    -54668, -15356, -27116, -10140, -23180, -4924,  -21876, -14052, -17964, -8836,  -19268, -3620,  -20572,
    -12748, -16660, -7532,  -11444, -6228,  -15356, -10140, -4924,  -3620,  -14052, -8836,  -12748};

}  // namespace

LidarModel makePandar64() {
  LidarModel m;
  m.name = "Pandar64";
  m.vendor = LidarVendor::kHesai;
  m.rotation_hz = 10.0;
  m.period_num_ns = kPandar64RoundNs;  // 55.56 µs rounds: 0.2° resolution at 10 Hz
  m.distance_unit_m = 0.004;
  m.min_range_m = 0.3;
  m.max_range_m = 200.0;
  m.azimuth_follows_firing_time = false;
  for (std::size_t i = 0; i < std::size(kPandar64); ++i)
    m.beams.push_back(
        {kPandar64[i].elevation_deg, kPandar64[i].azimuth_deg, TimeNs(kPandar64FiringNs[i] + kPandar64EarliestNs)});
  return m;
}

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
