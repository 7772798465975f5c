// A data packet's place in the stream: its sensor time, the packets lost before it, the rotor rate, the
// azimuth step of each firing sequence and each block's time.
//
// Limited field of view (VLP-32C/VLP-16 "FOV" setting): the sensor skips the dead sector but keeps
// filling packets, so one packet can hold the end of one sweep and the start of the next, ~50 ms
// apart at 10 Hz. A block-to-block azimuth jump far beyond what the rotor can turn in one firing
// sequence is recognised as that; the blocks after it are timed by the rotor rate, and the gap is not
// counted as packet loss (also when it falls between two packets, once the dead sector was seen).
#include <algorithm>
#include <cmath>
#include <cstdlib>

#include "velodyne_decoder_impl.hpp"

namespace rigcal::drivers::velodyne::detail {

TimeNs VelodyneDecoder::skippedNs(int hundredths, float step) const {
  const double seconds = rate_hz_ > 0 ? hundredths / double(kAzimuthUnits) / rate_hz_ - sequence_us_ * 1e-6
                                      : (hundredths - double(step)) / step * sequence_us_ * 1e-6;
  return std::llround(std::clamp(seconds, 0.0, 1.0) * 1e9);  // a dead sector lasts under a turn
}

VelodyneDecoder::PacketTime VelodyneDecoder::timeBlocks(std::uint32_t micros, TimeNs receive_ns, bool dual,
                                                        int blocks, const Blocks& azimuth, BlockSteps& step,
                                                        BlockTimes& block_ns, DecodedPacket& out) {
  // Sensor time of the packet; packets lost since the previous one.
  const TimeNs sensor_ns = hours_.resolve(micros, receive_ns);
  const TimeNs base_ns = time_source_ == TimeSource::kSensorClock ? sensor_ns : receive_ns;
  const double period_ns = packetPeriodUs(model_, dual) * 1000.0;
  float known_step = step_;
  if (have_previous_) {
    TimeNs gap = sensor_ns - expected_next_ns_;
    const int boundary = (azimuth[0] - previous_last_azimuth_ + kAzimuthUnits) % kAzimuthUnits;
    if (boundary > 2 * max_step_ && dead_from_ >= 0 && step_ > 0) {
      // The dead sector of a limited field of view, falling between two packets.
      const int tolerance = static_cast<int>(3 * max_step_);
      const auto near = [&](int a, int b) {
        const int diff = std::abs(a - b);
        return std::min(diff, kAzimuthUnits - diff) <= tolerance;
      };
      if (near(previous_last_azimuth_, dead_from_) && near(azimuth[0], dead_to_))
        gap -= skippedNs(boundary, step_);
    }
    if (gap > period_ns / 2 && gap < 3600 * kNsPerSec)
      out.lost_before = static_cast<std::uint32_t>(std::llround(double(gap) / period_ns));
    if (out.lost_before == 0 && boundary <= 2 * max_step_) {
      // Consecutive packets: the step across the boundary is one firing sequence's.
      known_step = static_cast<float>(boundary);
      const TimeNs dt = sensor_ns - previous_sensor_ns_;
      const int advance = (azimuth[0] - previous_first_azimuth_ + kAzimuthUnits) % kAzimuthUnits;
      if (dt > 0 && advance > 0) {
        const double hz = double(advance) / kAzimuthUnits / toSeconds(dt);
        if (hz > 1.0 && hz < 2 * kMaxRpm / 60.0) rate_hz_ = rate_hz_ > 0 ? 0.95 * rate_hz_ + 0.05 * hz : hz;
      }
    }
  }

  // Azimuth step per firing sequence, and the time skipped by a limited field of view.
  TimeNs shift = 0;
  for (int b = 0; b < blocks;) {
    const int next = nextSequenceBlock(model_, dual, b);
    float s = known_step;
    TimeNs jump_ns = 0;
    if (next < blocks) {
      const int raw = (azimuth[next] - azimuth[b] + kAzimuthUnits) % kAzimuthUnits;
      if (raw <= 2 * max_step_) {
        s = static_cast<float>(raw);
        known_step = s;
      } else if (known_step > 0) {
        jump_ns = skippedNs(raw, known_step);
        dead_from_ = azimuth[b];
        dead_to_ = azimuth[next];
      }
    }
    for (int k = b; k < std::min(next, blocks); ++k) {
      step[k] = s;
      block_ns[k] = base_ns + shift;
    }
    shift += jump_ns;
    b = next;
  }
  // Sequences before the first measured step (a first packet that starts with a jump) take the
  // step measured later in the packet.
  for (int b = 0; b < blocks; ++b)
    if (step[b] == 0) step[b] = known_step;

  have_previous_ = true;
  expected_next_ns_ = sensor_ns + static_cast<TimeNs>(period_ns) + shift;
  previous_sensor_ns_ = sensor_ns;
  previous_first_azimuth_ = azimuth[0];
  previous_last_azimuth_ = azimuth[blocks - 1];
  if (known_step > 0) step_ = known_step;
  return {sensor_ns, base_ns};
}

}  // namespace rigcal::drivers::velodyne::detail
