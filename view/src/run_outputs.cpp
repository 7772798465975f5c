#include "rigcal/view/run_outputs.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <stdexcept>
#include <unordered_set>

#include "rigcal/core/pcd_io.hpp"
#include "rigcal/core/point_table.hpp"
#include "rigcal/view/update_encoding.hpp"

namespace rigcal::view {

namespace fs = std::filesystem;

namespace {

constexpr std::string_view kBeforeSuffix = "_before.pcd";

/// x y z of a PCD, one point per `voxel` cell (first come), as float triples.
std::vector<float> decimatedCloud(const fs::path& file, double voxel) {
  const PointTable t = readPcd(file);
  const auto& x = t.column("x");
  const auto& y = t.column("y");
  const auto& z = t.column("z");
  std::unordered_set<std::uint64_t> cells;
  std::vector<float> out;
  const auto axis = [&](double v) { return std::uint64_t(std::int64_t(std::floor(v / voxel)) & 0x1FFFFF); };
  for (std::size_t i = 0; i < t.size(); ++i) {
    if (!std::isfinite(x[i]) || !std::isfinite(y[i]) || !std::isfinite(z[i])) continue;
    if (!cells.insert(axis(x[i]) | (axis(y[i]) << 21) | (axis(z[i]) << 42)).second) continue;
    out.insert(out.end(), {float(x[i]), float(y[i]), float(z[i])});
  }
  return out;
}

std::string readReport(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw std::runtime_error(file.string() + ": cannot read (is this a `rigcal calibrate --out` folder?)");
  std::ostringstream text;
  text << in.rdbuf();
  if (!nlohmann::json::accept(text.str())) throw std::runtime_error(file.string() + ": not valid JSON");
  return text.str();
}

}  // namespace

std::vector<std::string> lidarsOfRun(const fs::path& dir, const std::string& report_json) {
  std::vector<std::string> names;
  const auto report = nlohmann::json::parse(report_json, nullptr, false);
  if (report.is_object() && report.contains("lidars") && report["lidars"].is_array())
    for (const auto& l : report["lidars"])
      if (l.is_object() && l.contains("sensor") && l["sensor"].is_string()) names.push_back(l["sensor"].get<std::string>());
  if (!names.empty()) return names;
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(dir, ec)) {
    const std::string name = entry.path().filename().string();
    if (name.size() > kBeforeSuffix.size() && name.ends_with(kBeforeSuffix))
      names.push_back(name.substr(0, name.size() - kBeforeSuffix.size()));
  }
  std::sort(names.begin(), names.end());
  return names;
}

RunOutputsSummary publishRunOutputs(ViewServer& server, const fs::path& dir, std::vector<std::string> lidars,
                                    bool with_map, double voxel_m) {
  const std::string report = readReport(dir / "report.json");
  RunOutputsSummary summary;
  summary.lidars = lidars.empty() ? lidarsOfRun(dir, report) : std::move(lidars);
  if (with_map) server.publish(nlohmann::json{{"type", "lidars"}, {"names", summary.lidars}}.dump(), false, true);
  const auto cloud = [&](const fs::path& file) -> std::vector<float> {
    std::error_code ec;
    if (!fs::is_regular_file(file, ec)) return {};
    try {
      return decimatedCloud(file, voxel_m);
    } catch (const std::exception& e) {
      throw std::runtime_error(file.string() + ": " + e.what());
    }
  };
  if (with_map) {
    const auto map = cloud(dir / "map.pcd");
    summary.map_points = map.size() / 3;
    // In chunks, so a browser draws the map while the rest arrives.
    constexpr std::size_t kChunk = 3 * 50'000;
    for (std::size_t i = 0; i < map.size(); i += kChunk)
      server.publish(encodeUpdate(UpdateKind::kMapPoints, kNoLane,
                                  std::vector<float>(map.begin() + std::ptrdiff_t(i),
                                                     map.begin() + std::ptrdiff_t(std::min(map.size(), i + kChunk)))),
                     true, true);
  }
  for (std::size_t lane = 0; lane < summary.lidars.size() && lane < kNoLane; ++lane) {
    const std::string& name = summary.lidars[lane];
    // Sensor names are file names (config validation); anything else in a report is not followed.
    if (name.empty() || name == "." || name == ".." ||
        name.find_first_not_of("ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789_.-") != std::string::npos)
      continue;
    for (const auto& [suffix, kind] : {std::pair{"_before.pcd", UpdateKind::kCloudBefore}, std::pair{"_after.pcd", UpdateKind::kCloudAfter}}) {
      const auto points = cloud(dir / (name + suffix));
      summary.cloud_points += points.size() / 3;
      server.publish(encodeUpdate(kind, std::uint8_t(lane), points), true, true);
    }
  }
  server.publishReport(report);
  return summary;
}

}  // namespace rigcal::view
