#include "time_offsets.hpp"

#include <cmath>
#include <cstdio>

#include "rigcal/pipeline/clock_offset_estimate.hpp"

namespace rigcal::app {

std::vector<std::string> applyTimeOffsets(config::RigConfig& rig, const std::optional<std::filesystem::path>& pcap) {
  std::vector<std::string> lines;
  char line[320];
  for (auto& s : rig.sensors) {
    if (s.estimate_time_offset) {
      if (s.name == rig.roles.mapping_lidar) {
        // The mapping lidar's clock is the rig's: there is nothing to estimate it against.
        lines.push_back(s.name + ": time_offset_ns: estimate ignored (the mapping lidar's clock is the reference)");
        continue;
      }
      if (!pcap) {
        lines.push_back(s.name + ": time_offset_ns: estimate needs --pcap (nothing to measure before a live run); "
                                 "using 0, the clock check after the run still applies");
        continue;
      }
      const auto o = pipeline::estimateClockOffset(rig.sensor(rig.roles.mapping_lidar), s, *pcap);
      if (!o) {
        lines.push_back(s.name + ": time_offset_ns: estimate found no sweeps of it and " + rig.roles.mapping_lidar +
                        " in the capture; using 0");
        continue;
      }
      s.time_offset_ns = std::llround(o->offset_ms * 1e6);
      std::snprintf(line, sizeof line,
                    "%s: time_offset_ns estimated %+.1f ms (± %.1f) against %s over %zu sweeps; its stamps corrected",
                    s.name.c_str(), o->offset_ms, o->uncertainty_ms, rig.roles.mapping_lidar.c_str(), o->sweeps);
      lines.emplace_back(line);
    } else if (s.time_offset_ns != 0) {
      std::snprintf(line, sizeof line, "%s: time_offset_ns %+.1f ms from the rig; its stamps corrected", s.name.c_str(),
                    double(s.time_offset_ns) * 1e-6);
      lines.emplace_back(line);
    }
  }
  return lines;
}

}  // namespace rigcal::app
