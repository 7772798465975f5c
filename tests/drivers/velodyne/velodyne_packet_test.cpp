#include <gtest/gtest.h>

#include "rigcal/drivers/velodyne/velodyne_decoder.hpp"
#include "rigcal/drivers/velodyne/velodyne_packet.hpp"

namespace rigcal::drivers::velodyne {
namespace {

TEST(VelodynePacket, ModelNamesParseLeniently) {
  EXPECT_EQ(parseModel("VLP-16"), Model::kVlp16);
  EXPECT_EQ(parseModel("vlp16"), Model::kVlp16);
  EXPECT_EQ(parseModel("VLP-32C"), Model::kVlp32c);
  EXPECT_EQ(parseModel("hdl_32e"), Model::kHdl32e);
  EXPECT_EQ(parseModel("VLS-128"), Model::kVls128);
  EXPECT_FALSE(parseModel("HDL-64E"));
  EXPECT_FALSE(parseModel(""));
  EXPECT_EQ(velodyneModels(), (std::vector<std::string>{"VLP-16", "VLP-32C", "HDL-32E", "VLS-128"}));
}

TEST(VelodynePacket, DistanceUnits) {
  EXPECT_FLOAT_EQ(modelInfo(Model::kVlp16).distance_unit_m, 0.002f);
  EXPECT_FLOAT_EQ(modelInfo(Model::kHdl32e).distance_unit_m, 0.002f);
  EXPECT_FLOAT_EQ(modelInfo(Model::kVlp32c).distance_unit_m, 0.004f);
  EXPECT_FLOAT_EQ(modelInfo(Model::kVls128).distance_unit_m, 0.004f);
}

TEST(VelodynePacket, ProductIds) {
  EXPECT_TRUE(productMatches(Model::kVlp16, 0x22));
  EXPECT_TRUE(productMatches(Model::kVlp16, 0x21));  // early VLP-16 firmware (vlp16_20hz capture)
  EXPECT_TRUE(productMatches(Model::kVlp32c, 0x28));
  EXPECT_TRUE(productMatches(Model::kHdl32e, 0x21));
  EXPECT_TRUE(productMatches(Model::kVls128, 0xA1));
  EXPECT_TRUE(productMatches(Model::kVls128, 0x00));
  EXPECT_FALSE(productMatches(Model::kVlp16, 0x28));
  EXPECT_FALSE(productMatches(Model::kVlp32c, 0x22));
  EXPECT_FALSE(productMatches(Model::kHdl32e, 0xA1));
  EXPECT_EQ(productName(0x28), "VLP-32C");
  EXPECT_EQ(productName(0x7E), "0x7E");
}

// The per-firing offsets against the formulas of the user manuals, written out independently.
TEST(VelodynePacket, Vlp16FiringOffsets) {
  for (int b = 0; b < 12; ++b)
    for (int c = 0; c < 32; ++c) {
      const double single = 55.296 * (2 * b + c / 16) + 2.304 * (c % 16);
      const double dual = 55.296 * (2 * (b / 2) + c / 16) + 2.304 * (c % 16);
      EXPECT_NEAR(firingOffsetUs(Model::kVlp16, false, b, 0, c), single, 1e-9) << b << ' ' << c;
      EXPECT_NEAR(firingOffsetUs(Model::kVlp16, true, b, 0, c), dual, 1e-9) << b << ' ' << c;
    }
  // The last firing of a packet precedes the next packet (1327.1 µs single, 663.6 µs dual).
  EXPECT_NEAR(firingOffsetUs(Model::kVlp16, false, 11, 0, 31), 1306.368, 1e-9);
  EXPECT_LT(firingOffsetUs(Model::kVlp16, false, 11, 0, 31), packetPeriodUs(Model::kVlp16, false));
  EXPECT_NEAR(firingOffsetUs(Model::kVlp16, true, 11, 0, 31), 642.816, 1e-9);
  EXPECT_LT(firingOffsetUs(Model::kVlp16, true, 11, 0, 31), packetPeriodUs(Model::kVlp16, true));
  EXPECT_NEAR(packetPeriodUs(Model::kVlp16, false), 1327.104, 1e-9);
  EXPECT_NEAR(packetPeriodUs(Model::kVlp16, true), 663.552, 1e-9);
}

TEST(VelodynePacket, Hdl32eAndVlp32cFiringOffsets) {
  for (int b = 0; b < 12; ++b)
    for (int c = 0; c < 32; ++c) {
      // HDL-32E: one laser every 1.152 µs, stamped at the packet's last firing (Hdl32eTimestampIsTheLastFiring).
      EXPECT_NEAR(firingOffsetUs(Model::kHdl32e, false, b, 0, c), 46.08 * (b - 11) + 1.152 * (c - 31), 1e-9);
      EXPECT_NEAR(firingOffsetUs(Model::kHdl32e, true, b, 0, c), 46.08 * (b / 2 - 5) + 1.152 * (c - 31), 1e-9);
      EXPECT_NEAR(firingOffsetUs(Model::kVlp32c, false, b, 0, c), 55.296 * b + 2.304 * (c / 2), 1e-9);
      EXPECT_NEAR(firingOffsetUs(Model::kVlp32c, true, b, 0, c), 55.296 * (b / 2) + 2.304 * (c / 2), 1e-9);
    }
  EXPECT_NEAR(packetPeriodUs(Model::kHdl32e, false), 552.96, 1e-9);
  EXPECT_NEAR(packetPeriodUs(Model::kVlp32c, false), 663.552, 1e-9);
  EXPECT_NEAR(packetPeriodUs(Model::kVlp32c, true), 331.776, 1e-9);
}

TEST(VelodynePacket, Vls128FiringOffsets) {
  // Banks 0xEEFF/0xDDFF/0xCCFF/0xBBFF carry lasers 0-31/32-63/64-95/96-127; lasers fire eight at a
  // time in 16 groups of 2.665 µs with a maintenance slot after group 8; three sequences of 53.3 µs
  // per single-return packet, the packet time 8.7 µs after the first firing.
  for (int b = 0; b < 12; ++b) {
    const int bank = b % 4;
    for (int c = 0; c < 32; ++c) {
      const int laser = bank * 32 + c;
      const int group = laser / 8;
      const double expected = 53.3 * (b / 4) + 2.665 * (group + (group >= 8 ? 1 : 0)) - 8.7;
      EXPECT_NEAR(firingOffsetUs(Model::kVls128, false, b, bank, c), expected, 1e-9) << b << ' ' << c;
      if (b < 8) {  // dual: one sequence, block pairs hold the two returns of bank b/2
        const int g = ((b / 2) * 32 + c) / 8;
        EXPECT_NEAR(firingOffsetUs(Model::kVls128, true, b, b / 2, c), 2.665 * (g + (g >= 8 ? 1 : 0)) - 8.7, 1e-9);
      }
    }
  }
  EXPECT_NEAR(packetPeriodUs(Model::kVls128, false), 159.9, 1e-9);
  EXPECT_NEAR(packetPeriodUs(Model::kVls128, true), 53.3, 1e-9);
  EXPECT_EQ(activeBlocks(Model::kVls128, true), 8);
}

TEST(VelodynePacket, AzimuthFractionFollowsFiringTime) {
  // VLP-16: the block spans two firing sequences (110.592 µs).
  EXPECT_NEAR(azimuthFraction(Model::kVlp16, 0, 0), 0.0, 1e-12);
  EXPECT_NEAR(azimuthFraction(Model::kVlp16, 0, 16), 0.5, 1e-12);
  EXPECT_NEAR(azimuthFraction(Model::kVlp16, 0, 31), (55.296 + 15 * 2.304) / 110.592, 1e-12);
  // VLP-32C fires lasers in pairs, the HDL-32E one at a time (manual: 32 firings of 1.152 µs + recharge).
  EXPECT_NEAR(azimuthFraction(Model::kVlp32c, 0, 31), 15 * 2.304 / 55.296, 1e-12);
  EXPECT_NEAR(azimuthFraction(Model::kHdl32e, 0, 31), 31 * 1.152 / 46.08, 1e-12);
  EXPECT_NE(azimuthFraction(Model::kHdl32e, 0, 4), azimuthFraction(Model::kHdl32e, 0, 5));
  EXPECT_EQ(azimuthFraction(Model::kVlp32c, 0, 4), azimuthFraction(Model::kVlp32c, 0, 5));
  // VLS-128: group 15 fires 16 slots after group 0 (one maintenance slot).
  EXPECT_NEAR(azimuthFraction(Model::kVls128, 3, 31), 16 * 2.665 / 53.3, 1e-12);
  EXPECT_NEAR(azimuthFraction(Model::kVls128, 2, 0), 9 * 2.665 / 53.3, 1e-12);
}

TEST(VelodynePacket, Hdl32eTimestampIsTheLastFiring) {
  // HDL-32E manual, Appendix E: firing time = timestamp − 542.592 + block·46.08 + DSR·1.152 µs.
  for (int b = 0; b < 12; ++b)
    for (int c = 0; c < 32; ++c)
      EXPECT_NEAR(firingOffsetUs(Model::kHdl32e, false, b, 0, c), -542.592 + b * 46.08 + c * 1.152, 1e-9);
  EXPECT_NEAR(firingOffsetUs(Model::kHdl32e, false, 11, 0, 31), 0.0, 1e-9);
  // Dual return: 6 firing sequences per packet, both blocks of a pair fired together.
  EXPECT_NEAR(firingOffsetUs(Model::kHdl32e, true, 11, 0, 31), 0.0, 1e-9);
  EXPECT_NEAR(firingOffsetUs(Model::kHdl32e, true, 0, 0, 0), -(5 * 46.08 + 31 * 1.152), 1e-9);
  EXPECT_EQ(firingOffsetUs(Model::kHdl32e, true, 4, 0, 7), firingOffsetUs(Model::kHdl32e, true, 5, 0, 7));
}

TEST(VelodynePacket, SequencePairing) {
  EXPECT_EQ(nextSequenceBlock(Model::kVlp16, false, 3), 4);
  EXPECT_EQ(nextSequenceBlock(Model::kVlp16, true, 2), 4);
  EXPECT_EQ(nextSequenceBlock(Model::kVlp16, true, 3), 4);
  EXPECT_EQ(nextSequenceBlock(Model::kVls128, false, 5), 8);
  EXPECT_GE(nextSequenceBlock(Model::kVls128, false, 9), 12);
  EXPECT_GE(nextSequenceBlock(Model::kVls128, true, 0), 8);
}

}  // namespace
}  // namespace rigcal::drivers::velodyne
