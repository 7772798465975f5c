// The progress line names each sensor's damage as it happens: packets lost and packets dropped as
// malformed, for the mapping lidar and every calibration lidar; a clean input adds nothing.
#include <gtest/gtest.h>

#include "rigcal/pipeline/pipeline.hpp"

namespace rigcal::pipeline {
namespace {

PipelineProgress progressOf(std::uint64_t mapping_lost, std::uint64_t mapping_malformed, std::uint64_t lost,
                            std::uint64_t malformed) {
  PipelineProgress p;
  p.mapping_sensor = "top";
  p.mapping_lost_packets = mapping_lost;
  p.mapping_malformed_packets = mapping_malformed;
  LidarProgress l;
  l.sensor = "front_left";
  l.budget = 4;
  l.lost_packets = lost;
  l.malformed_packets = malformed;
  p.lidars.push_back(l);
  return p;
}

TEST(PipelineDamageProgressLine, MalformedPacketsPerSensor) {
  const std::string clean = progressOf(0, 0, 0, 0).line();
  EXPECT_EQ(clean.find("malformed"), std::string::npos) << clean;
  EXPECT_EQ(clean.find("lost 0 pkts"), std::string::npos) << clean;
  const std::string calib = progressOf(0, 0, 12, 3).line();
  EXPECT_NE(calib.find("front_left 0/4 (cand 0) (lost 12 pkts) (3 malformed)"), std::string::npos) << calib;
  const std::string mapping_only = progressOf(0, 7, 0, 0).line();
  EXPECT_NE(mapping_only.find("| top 7 malformed"), std::string::npos) << mapping_only;
  const std::string mapping_both = progressOf(5, 7, 0, 0).line();
  EXPECT_NE(mapping_both.find("| top lost 5 pkts, 7 malformed"), std::string::npos) << mapping_both;
}

}  // namespace
}  // namespace rigcal::pipeline
