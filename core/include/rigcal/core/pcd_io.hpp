#pragma once
// PCD v0.7 files (the format PCL and most lidar tools read), ascii and binary, unorganised or organised.
// binary_compressed is refused with a clear error: nothing we exchange uses it.
#include <filesystem>

#include "rigcal/core/point_table.hpp"

namespace rigcal {

enum class PcdEncoding { kAscii, kBinary };

/// Throws std::runtime_error "<path>: <what is wrong>" on a malformed or truncated file.
PointTable readPcd(const std::filesystem::path& path);
void writePcd(const std::filesystem::path& path, const PointTable& table,
              PcdEncoding encoding = PcdEncoding::kBinary);

}  // namespace rigcal
