#pragma once
// The rig's per-sensor time_offset_ns as a run applies it: given values as they are, `estimate` measured
// from the capture before the run (pipeline::estimateClockOffset against the mapping lidar).
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "rigcal/config/rig_config.hpp"

namespace rigcal::app {

/// Fills time_offset_ns of every sensor whose rig entry says `estimate`, from `pcap` (nullopt: live or
/// shared-memory input, where nothing can be measured before the run: the offset stays 0 with a warning).
/// Returns one line per sensor with an applied offset (given or estimated), for the user and the summary.
std::vector<std::string> applyTimeOffsets(config::RigConfig& rig, const std::optional<std::filesystem::path>& pcap);

}  // namespace rigcal::app
