#include "rigcal/core/point_cloud_file.hpp"

#include <fstream>

#include "rigcal/core/pcd_io.hpp"
#include "rigcal/core/ply_io.hpp"
#include "table_rows.hpp"

namespace rigcal {

PointTable readPointCloudFile(const std::filesystem::path& path) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) detail::failFile(path, "is a directory, not a point-cloud file");
  std::ifstream in(path, std::ios::binary);
  if (!in) detail::failFile(path, "cannot open");
  char magic[3] = {};
  in.read(magic, 3);
  if (in.gcount() == 3 && magic[0] == 'p' && magic[1] == 'l' && magic[2] == 'y') return readPly(path);
  return readPcd(path);
}

}  // namespace rigcal
