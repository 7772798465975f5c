#pragma once
// When each Hesai laser fires within a packet: the per-model firing-time rules and tables of the user
// manuals, which give every point its own time.
#include <cstdint>

#include "rigcal/drivers/hesai/hesai_packet.hpp"

namespace rigcal::drivers::hesai {

/// Firing time (ns) of `channel` (0-based) in `block` (0-based) relative to the packet's absolute
/// time t0 (tail date + µs timestamp), from the Hesai user manuals (Appendix "Absolute Time and
/// Laser Firing Time"):
///  XT16/XT32: block start = t0 + 5.632 µs − 50 µs × (firings after this block's firing);
///             channel offset = 0.368 µs + 1.512 µs × channel (XT32), 3.024 µs × channel (XT16).
///  QT128:     block start = t0 + 9 µs (dual: both blocks; single: block 2, block 1 is one firing
///             round, 111.11 µs, earlier); channel offset from the firing sequence table (loop 1 or
///             2: single → block 1 uses loop 1, block 2 loop 2; dual → loop 1 when mode_flag bit 0).
///  XT32M:     as XT32 with 6 blocks; channels c and c + 16 fire together, 0.368 + 2.888 µs × (c mod 16).
///  Pandar40P: block start = t0 − 28.58 µs − 55.56 µs × (firings after); Pandar64: t0 − 42.58 µs −
///             55.56 µs × (firings after); channel offsets from the manuals' firing-time tables.
///  QT64:      block start = t0 + 25.71 µs + 166.67 µs × (firing index in the packet); channel
///             offsets from the QT64 firing-time table.
/// Channels that do not fire in the chosen loop get the block start (their distance is 0 anyway).
std::int64_t firingOffsetNs(Model model, int returns, int block, int channel, std::uint8_t mode_flag);

/// The QT128 firing-sequence offset (ns) of `channel` in loop 1 or 2; 0 = does not fire there.
std::int32_t qt128LoopOffsetNs(int loop, int channel);

}  // namespace rigcal::drivers::hesai
