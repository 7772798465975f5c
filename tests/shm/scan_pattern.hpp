#pragma once
// Deterministic scan contents for the ring tests: every value is a function of (sequence, point index), so a
// reader can check each scan it gets, value by value, without talking to the writer.
#include <cstdint>
#include <string>

#include "rigcal/core/scan.hpp"

namespace rigcal::shm::test {

/// Point count of scan `sequence` when slots hold `max_points`: varies between 60% and 100% of it.
std::uint32_t patternPoints(std::uint64_t sequence, std::uint32_t max_points);

/// Fills `scan` (reusing its capacity) with the pattern of `sequence`, `points` points.
void fillPattern(Scan& scan, std::uint64_t sequence, std::uint32_t points);

/// Empty if `scan` is exactly the pattern of scan.sequence with patternPoints(sequence, max_points) points;
/// otherwise what differs (first mismatch).
std::string checkPattern(const Scan& scan, std::uint32_t max_points);

}  // namespace rigcal::shm::test
