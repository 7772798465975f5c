#pragma once
// What the RoboSense tests share: captures held in memory and decoded (tests/support), a point-set match.
#include "captured_packets.hpp"
#include "point_set_match.hpp"

namespace rigcal::drivers::robosense_test {

using Capture = rigcal::test::CapturedPackets;
using rigcal::test::countMatched;
using rigcal::test::decodeScans;
using rigcal::test::loadCapture;
using rigcal::test::xyzOf;
using rigcal::test::Xyz;

}  // namespace rigcal::drivers::robosense_test
