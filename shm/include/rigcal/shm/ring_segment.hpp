#pragma once
// Segment names: "<prefix><sensor>" in /dev/shm, prefix "rigcal." unless $RIGCAL_SHM_PREFIX or the caller
// says otherwise (tests use a unique prefix so parallel runs never meet).
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace rigcal::shm {

inline constexpr const char* kDefaultNamePrefix = "rigcal.";
inline constexpr const char* kShmDir = "/dev/shm";

/// $RIGCAL_SHM_PREFIX when set and non-empty, else "rigcal.".
std::string defaultNamePrefix();

/// "<prefix><sensor>" (no leading slash). Throws std::invalid_argument for an empty name or one with '/'.
std::string segmentName(const std::string& sensor, const std::optional<std::string>& prefix = {});

/// /dev/shm/<segment>.
std::filesystem::path segmentPath(const std::string& segment);

/// The segments in /dev/shm whose name starts with `prefix`, sorted.
std::vector<std::string> listSegments(const std::string& prefix);

/// Removes a segment by name (what `rm /dev/shm/<segment>` does); false if it did not exist.
bool removeSegment(const std::string& segment);

}  // namespace rigcal::shm
