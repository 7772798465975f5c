#include "rigcal/calib/lidar_pose/pose_csv.hpp"

#include <array>
#include <charconv>
#include <cmath>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string_view>

namespace rigcal::calib {
namespace {

constexpr std::array<const char*, 9> kColumns{"timestamp_ns", "index", "px", "py", "pz",
                                              "qw",           "qx",    "qy", "qz"};

[[noreturn]] void failLine(const std::string& name, std::size_t line, const std::string& what) {
  throw std::runtime_error(name + ":" + std::to_string(line) + ": " + what);
}

std::string_view trim(std::string_view s) {
  const auto first = s.find_first_not_of(" \t\r");
  if (first == std::string_view::npos) return {};
  const auto last = s.find_last_not_of(" \t\r");
  return s.substr(first, last - first + 1);
}

template <class T>
bool parseNumber(std::string_view cell, T& value) {
  if (!cell.empty() && cell.front() == '+') cell.remove_prefix(1);  // from_chars refuses a leading '+'
  const auto [end, ec] = std::from_chars(cell.data(), cell.data() + cell.size(), value);
  return ec == std::errc() && end == cell.data() + cell.size() && !cell.empty();
}

std::string describeCell(std::size_t column, std::string_view cell) {
  return "column " + std::to_string(column + 1) + " (" + kColumns[column] + "): '" +
         std::string(cell) + "'";
}

}  // namespace

PoseCsv parsePoseCsv(std::istream& in, const std::string& name, const PoseCsvOptions& options) {
  PoseCsv out;
  std::string text;
  std::size_t line_no = 0;
  std::vector<std::size_t> line_of_pose;
  std::vector<Eigen::Vector3d> positions;
  std::vector<Eigen::Quaterniond> rotations;
  while (std::getline(in, text)) {
    ++line_no;
    const std::string_view line = trim(text);
    if (line.empty() || line.front() == '#') {
      ++out.skipped_lines;
      continue;
    }
    std::array<std::string_view, kColumns.size()> cells;
    std::size_t count = 0, start = 0;
    while (true) {
      const std::size_t comma = line.find(',', start);
      const std::string_view cell =
          trim(line.substr(start, comma == std::string_view::npos ? line.npos : comma - start));
      if (count < cells.size()) cells[count] = cell;
      ++count;
      if (comma == std::string_view::npos) break;
      start = comma + 1;
    }
    if (count != kColumns.size())
      failLine(name, line_no,
               "expected 9 comma-separated columns (timestamp_ns, index, px, py, pz, qw, qx, qy, qz), "
               "found " + std::to_string(count));

    TimeNs stamp = 0;
    if (!parseNumber(cells[0], stamp))
      failLine(name, line_no, describeCell(0, cells[0]) + " is not an integer nanosecond timestamp");
    std::array<double, 8> v{};
    for (std::size_t c = 1; c < kColumns.size(); ++c) {
      if (!parseNumber(cells[c], v[c - 1]) || !std::isfinite(v[c - 1]))
        failLine(name, line_no, describeCell(c, cells[c]) + " is not a finite number");
    }
    for (std::size_t c = 2; c <= 4; ++c)
      if (std::abs(v[c - 1]) > options.max_abs_position_m) {
        std::ostringstream what;
        what << describeCell(c, cells[c]) << " is beyond " << options.max_abs_position_m << " m";
        failLine(name, line_no, what.str());
      }
    Eigen::Quaterniond q(v[4], v[5], v[6], v[7]);
    const double norm = q.norm();
    if (std::abs(norm - 1.0) > options.quaternion_norm_tolerance) {
      std::ostringstream what;
      what << "quaternion (qw, qx, qy, qz) has norm " << norm << ", not 1 (tolerance "
           << options.quaternion_norm_tolerance << ")";
      failLine(name, line_no, what.str());
    }
    if (!out.stamps.empty() && stamp <= out.stamps.back())
      failLine(name, line_no,
               "timestamp " + std::to_string(stamp) + " is not after the previous pose's " +
                   std::to_string(out.stamps.back()) + " (line " +
                   std::to_string(line_of_pose.back()) + ")");
    const Eigen::Vector3d position(v[1], v[2], v[3]);
    if (!positions.empty()) {
      const double dt_s = double(stamp - out.stamps.back()) * 1e-9;
      const double jump = (position - positions.back()).norm();
      if (!(jump <= options.max_speed_mps * dt_s + options.jump_allowance_m)) {
        std::ostringstream what;
        what << "position jumps " << jump << " m in " << dt_s << " s since line " << line_of_pose.back()
             << " (" << jump / dt_s << " m/s; the limit is " << options.max_speed_mps << " m/s plus "
             << options.jump_allowance_m << " m)";
        failLine(name, line_no, what.str());
      }
    }
    out.stamps.push_back(stamp);
    line_of_pose.push_back(line_no);
    positions.push_back(position);
    rotations.push_back(q.normalized());
  }
  if (in.bad()) throw std::runtime_error(name + ": read error");
  if (out.stamps.empty()) throw std::runtime_error(name + ": no pose (every line is blank or a comment)");

  // Re-centre on the first position (whole metres, so the offset is easy to read back and add).
  if (options.recentre_above_m >= 0.0 &&
      positions.front().cwiseAbs().maxCoeff() > options.recentre_above_m)
    out.origin = positions.front().array().round().matrix();
  out.poses.reserve(positions.size());
  for (std::size_t i = 0; i < positions.size(); ++i) {
    Pose T = Pose::Identity();
    T.linear() = rotations[i].toRotationMatrix();
    T.translation() = positions[i] - out.origin;
    out.poses.push_back(T);
  }
  return out;
}

PoseCsv readPoseCsv(const std::filesystem::path& path, const PoseCsvOptions& options) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error(path.string() + ": cannot open");
  return parsePoseCsv(in, path.string(), options);
}

}  // namespace rigcal::calib
