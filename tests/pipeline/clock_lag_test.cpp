// The packet-clock check's measurement on a simulated capture of sensors with different packet rates
// (the street: VLS-128 ~ 9 000 packets/s, VLP-16 ~ 750, OS1-64 640, PandarXT32 on host time), each with its
// own small clock offset: the estimated offset of each against the mapping lidar must be the simulated one.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <stdexcept>

#include "rigcal/pipeline/clock_offset_estimate.hpp"
#include "rigcal/sim/recording.hpp"
#include "rigcal/sim/scenario.hpp"
#include "sanitizers.hpp"
#include "sim_pipeline_util.hpp"

namespace rigcal::pipeline {
namespace {

TEST(ClockLag, EveryModelsLagGivesItsTrueClockOffsetWhateverItsPacketRate) {
  sim::Simulation sim(sim::loadScenario("street"));
  rigcal::test::TempDir dir;
  const config::RigConfig rig = test::rigFor(sim, dir.path());
  sim::SimulationOptions so;
  so.build_scans = false;
  so.max_duration_ns = fromSeconds(RIGCAL_SANITIZED ? 0.8 : 2.0);
  sim::writeRecording(sim, sim::makeEncoders(sim), dir / "recording.pcap", so);

  const auto& specs = sim.scenario().sensors;
  const auto spec = [&](const std::string& name) {
    for (const auto& s : specs)
      if (s.name == name) return s;
    throw std::runtime_error("no sensor " + name);
  };
  const sim::SensorSpec mapping = spec(rig.roles.mapping_lidar);
  ASSERT_TRUE(mapping.time_source_sensor);
  int checked = 0;
  for (const auto& name : rig.roles.calibration_lidars) {
    const sim::SensorSpec s = spec(name);
    // Sensor time = true time + its offset; a host-time sensor's stamps come from the receive times.
    const double truth_ms = (s.time_source_sensor ? double(s.clock_offset_ns) : 0.0) * 1e-6 - double(mapping.clock_offset_ns) * 1e-6;
    const auto o = estimateClockOffset(rig.sensor(rig.roles.mapping_lidar), rig.sensor(name), dir / "recording.pcap");
    ASSERT_TRUE(o.has_value()) << name;
    EXPECT_GE(o->sweeps, RIGCAL_SANITIZED ? 5u : 15u) << name;
    // A few tenths of a ms: the wire time of a datagram and the firing after a packet's last point.
    EXPECT_NEAR(o->offset_ms, truth_ms, 0.5) << name << " (" << s.model << ")";
    std::printf("%-6s %-11s offset %+.3f ms (truth %+.3f) ± %.3f over %zu sweeps\n", name.c_str(), s.model.c_str(),
                o->offset_ms, truth_ms, o->uncertainty_ms, o->sweeps);
    ++checked;
  }
  EXPECT_EQ(checked, 3);
}

}  // namespace
}  // namespace rigcal::pipeline
