#pragma once
// PLY files (one "vertex" element), ascii and binary_little_endian: what MeshLab, CloudCompare and
// lidar_align users open. Scalar properties only.
#include <filesystem>

#include "rigcal/core/point_table.hpp"

namespace rigcal {

enum class PlyEncoding { kAscii, kBinaryLittleEndian };

/// Throws std::runtime_error "<path>: <what is wrong>" on a malformed or truncated file.
PointTable readPly(const std::filesystem::path& path);
void writePly(const std::filesystem::path& path, const PointTable& table,
              PlyEncoding encoding = PlyEncoding::kBinaryLittleEndian);

}  // namespace rigcal
