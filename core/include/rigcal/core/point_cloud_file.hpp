#pragma once
// A point-cloud file of either format we read, told apart by its first bytes (a PLY file starts with
// "ply"), so a misnamed file still opens: what `rigcal register` and other cloud inputs use.
#include <filesystem>

#include "rigcal/core/point_table.hpp"

namespace rigcal {

/// PLY or PCD (every layout readPly / readPcd accept). Throws std::runtime_error "<path>: <what>".
PointTable readPointCloudFile(const std::filesystem::path& path);

}  // namespace rigcal
