#pragma once
// PCD v0.7 files (the format PCL and most lidar tools read), unorganised or organised. Read: ascii, binary
// and PCL's binary_compressed (LZF, see lzf.hpp), any field order, COUNT > 1 expanded to name_0, name_1, ...
// Written: ascii and binary.
#include <filesystem>

#include "rigcal/core/point_table.hpp"

namespace rigcal {

enum class PcdEncoding { kAscii, kBinary };

/// Throws std::runtime_error "<path>: <what is wrong>" on a malformed or truncated file.
PointTable readPcd(const std::filesystem::path& path);
void writePcd(const std::filesystem::path& path, const PointTable& table,
              PcdEncoding encoding = PcdEncoding::kBinary);

}  // namespace rigcal
