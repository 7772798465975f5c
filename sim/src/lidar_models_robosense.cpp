#include <cmath>
#include <cstdint>
#include <iterator>

#include "rigcal/sim/lidar_model.hpp"

// RoboSense RS-Helios-16P. Angles are the DIFOP calibration of the unit recorded in
// ../shared/data/robosense/helios16p.pcap, lasers renumbered from the lowest beam up (the order the
// decoder gives rings in). Timing and geometry as the decoders read the format (rs_driver, nebula, and
// drivers/src/robosense/robosense_decoder.cpp): one 55.56 µs block per firing sequence carries 32
// channel slots, each laser twice (slot c is laser c mod 16) at the slot's firing time, and a slot's
// azimuth is the block azimuth plus slot time / 111.12 µs of the block's azimuth step, i.e. half the
// rotation during its delay. The beams point where the decoders put them. The lens sits 34.98 mm
// from the rotation axis and ranges are measured from it.
namespace rigcal::sim::detail {
namespace {

struct RobosenseLaser {
  std::int32_t vertical, horizontal;  // 0.01°, as the DIFOP carries them
};

constexpr RobosenseLaser kHelios16p[16] = {
    {-801, 357}, {-663, -397}, {-523, 356}, {-396, -396}, {-267, 355}, {-133, -395}, {0, 355},   {133, -395},
    {267, 355},  {398, -396},  {546, 356},  {696, -397},  {890, 358},  {1092, -400}, {1303, 361}, {1494, -405},
};

// Firing time of each channel slot after the block's time (µs), as the decoders use it.
constexpr double kSlotUs[32] = {0.00,  3.15,  6.30,  9.45,  13.26, 17.08, 20.56, 23.71, 26.53, 27.77, 31.49,
                                32.73, 36.46, 38.94, 41.42, 43.91, 55.56, 58.70, 61.85, 65.00, 68.82, 72.64,
                                76.12, 79.27, 82.08, 83.32, 87.05, 88.29, 92.01, 94.50, 96.98, 99.46};

// Azimuth the decoders add for a firing `delay_ns` into the block: half the rotation in that time.
double slotShareDeg(double rotation_hz, TimeNs delay_ns) { return 180.0 * rotation_hz * double(delay_ns) * 1e-9; }

}  // namespace

LidarModel makeHelios16p() {
  LidarModel m;
  m.name = "RS-Helios-16P";
  m.vendor = LidarVendor::kRobosense;
  m.rotation_hz = 10.0;
  m.period_num_ns = 55'560;  // one block: 0.2° at 600 rpm
  m.distance_unit_m = 0.0025;
  m.min_range_m = 0.2;
  m.max_range_m = 150.0;
  m.beam_origin_radius_m = 0.03498;
  m.range_from_beam_origin = true;
  m.azimuth_follows_firing_time = false;  // the slot's share is in its azimuth offset
  for (std::size_t slot = 0; slot < std::size(kSlotUs); ++slot) {
    const RobosenseLaser& l = kHelios16p[slot % 16];
    const TimeNs delay = std::llround(kSlotUs[slot] * 1000.0);
    const double share = slotShareDeg(m.rotation_hz, delay);  // where the lens stands, as decoded
    m.beams.push_back({l.vertical * 0.01, l.horizontal * 0.01 + share, delay, share});
  }
  return m;
}

double helios16pHorizontalOffsetDeg(const LidarModel& model, std::size_t beam) {
  const LidarBeam& b = model.beams.at(beam);
  return b.azimuth_offset_deg - b.origin_azimuth_deg;
}

}  // namespace rigcal::sim::detail
