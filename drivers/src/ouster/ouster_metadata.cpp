#include "rigcal/drivers/ouster/ouster_metadata.hpp"

#include <cctype>
#include <cmath>
#include <fstream>
#include <limits>
#include <nlohmann/json.hpp>
#include <sstream>
#include <stdexcept>

namespace rigcal::drivers::ouster {
namespace {

using Json = nlohmann::json;

class Reader {
 public:
  explicit Reader(std::string source) : source_(std::move(source)) {}

  [[noreturn]] void fail(const std::string& field, const std::string& what) const {
    throw std::runtime_error(source_ + ": " + field + ": " + what);
  }

  static const Json* find(const Json& obj, const char* key) {
    if (!obj.is_object()) return nullptr;
    auto it = obj.find(key);
    return it == obj.end() ? nullptr : &*it;
  }

  const Json& object(const Json& parent, const char* key, const std::string& path) const {
    const Json* j = find(parent, key);
    if (!j) fail(path, "missing");
    if (!j->is_object()) fail(path, "not a JSON object");
    return *j;
  }

  double number(const Json& j, const std::string& path) const {
    if (!j.is_number()) fail(path, "not a number");
    const double v = j.get<double>();
    if (!std::isfinite(v)) fail(path, "not finite");
    return v;
  }

  int integer(const Json& j, const std::string& path, int lo, int hi) const {
    const double v = number(j, path);
    if (v != std::floor(v) || v < lo || v > hi)
      fail(path, "expected an integer in [" + std::to_string(lo) + ", " + std::to_string(hi) + "], got " +
                     j.dump());
    return int(v);
  }

  int requiredInt(const Json& parent, const char* key, const std::string& prefix, int lo, int hi) const {
    const Json* j = find(parent, key);
    if (!j) fail(prefix + key, "missing");
    return integer(*j, prefix + key, lo, hi);
  }

  std::vector<double> numbers(const Json& j, const std::string& path) const {
    if (!j.is_array()) fail(path, "not an array of numbers");
    std::vector<double> out;
    out.reserve(j.size());
    for (std::size_t i = 0; i < j.size(); ++i) out.push_back(number(j[i], path + "[" + std::to_string(i) + "]"));
    return out;
  }

  std::array<double, 16> transform(const Json& j, const std::string& path) const {
    const std::vector<double> v = numbers(j, path);
    if (v.size() != 16) fail(path, "expected 16 numbers (row-major 4x4), got " + std::to_string(v.size()));
    if (v[12] != 0 || v[13] != 0 || v[14] != 0 || v[15] != 1) fail(path, "last row is not 0 0 0 1");
    std::array<double, 16> out{};
    for (int i = 0; i < 16; ++i) out[std::size_t(i)] = v[std::size_t(i)];
    return out;
  }

  std::string string(const Json& parent, const char* key) const {
    const Json* j = find(parent, key);
    return j && j->is_string() ? j->get<std::string>() : std::string();
  }

 private:
  std::string source_;
};

std::array<double, 16> identity() {
  std::array<double, 16> m{};
  m[0] = m[5] = m[10] = m[15] = 1;
  return m;
}

std::array<double, 16> defaultLidarToSensor() {
  std::array<double, 16> m = identity();
  m[0] = m[5] = -1;
  m[11] = 36.18;
  return m;
}

double defaultBeamOrigin(const std::string& prod_line) {
  if (prod_line.rfind("OS-0-", 0) == 0) return 27.67;
  if (prod_line.rfind("OS-1-", 0) == 0) return 15.806;
  if (prod_line.rfind("OS-2-", 0) == 0) return 13.762;
  return 12.163;  // gen-1 OS1
}

bool parseLidarMode(const std::string& mode, int& columns, int& fps) {
  const auto x = mode.find('x');
  if (x == std::string::npos || x == 0 || x + 1 >= mode.size()) return false;
  for (std::size_t i = 0; i < mode.size(); ++i)
    if (i != x && !std::isdigit(static_cast<unsigned char>(mode[i]))) return false;
  if (x > 5 || mode.size() - x - 1 > 3) return false;
  columns = std::stoi(mode.substr(0, x));
  fps = std::stoi(mode.substr(x + 1));
  return true;
}

bool validColumns(int w) { return w == 512 || w == 1024 || w == 2048 || w == 4096; }

void findVersion(const std::string& text, Metadata& m) {
  for (std::size_t i = 0; i + 3 < text.size(); ++i) {
    if (text[i] != 'v' || !std::isdigit(static_cast<unsigned char>(text[i + 1]))) continue;
    if (i > 0 && std::isalnum(static_cast<unsigned char>(text[i - 1]))) continue;
    int parts[3] = {-1, -1, -1};
    std::size_t j = i + 1;
    int k = 0;
    while (k < 3 && j < text.size() && std::isdigit(static_cast<unsigned char>(text[j]))) {
      int v = 0;
      while (j < text.size() && std::isdigit(static_cast<unsigned char>(text[j])) && v < 10000) v = v * 10 + (text[j++] - '0');
      parts[k++] = v;
      if (j < text.size() && text[j] == '.') ++j; else break;
    }
    if (k < 2) continue;
    m.fw_major = parts[0];
    m.fw_minor = parts[1];
    m.fw_patch = std::max(parts[2], 0);
    std::ostringstream version;
    version << 'v' << m.fw_major << '.' << m.fw_minor << '.' << m.fw_patch;
    m.firmware = version.str();
    return;
  }
}

std::uint64_t parseSerial(const std::string& s) {
  if (s.empty() || s.size() > 19) return 0;
  std::uint64_t v = 0;
  for (char c : s) {
    if (!std::isdigit(static_cast<unsigned char>(c))) return 0;
    v = v * 10 + std::uint64_t(c - '0');
  }
  return v;
}

std::vector<int> defaultPixelShift(int columns, int pixels) {
  const int base = columns / 1024 * 6 > 0 ? columns / 1024 * 6 : 3;  // 512: 3, 1024: 6, 2048: 12, 4096: 24
  std::vector<int> shift(static_cast<std::size_t>(pixels));
  for (int i = 0; i < pixels; ++i) shift[std::size_t(i)] = (3 - i % 4) * base;
  return shift;
}

struct DataFormatSeen {
  bool present = false;
  bool has_profile = false;
  bool has_fps = false;
};

/// Reads a (complete) data_format / lidar_data_format object into m.
DataFormatSeen readDataFormat(const Reader& r, const Json& df, const std::string& name, Metadata& m) {
  DataFormatSeen seen;
  seen.present = true;
  const std::string p = name + ".";
  m.pixels_per_column = r.requiredInt(df, "pixels_per_column", p, 1, 256);
  m.columns_per_packet = r.requiredInt(df, "columns_per_packet", p, 1, 4096);
  m.columns_per_frame = r.requiredInt(df, "columns_per_frame", p, 1, 65536);
  if (!validColumns(m.columns_per_frame))
    r.fail(p + "columns_per_frame", "expected 512, 1024, 2048 or 4096, got " + std::to_string(m.columns_per_frame));
  const Json* shift = Reader::find(df, "pixel_shift_by_row");
  if (!shift) r.fail(p + "pixel_shift_by_row", "missing");
  m.pixel_shift_by_row.clear();
  for (double v : r.numbers(*shift, p + "pixel_shift_by_row")) {
    if (v != std::floor(v) || std::abs(v) > m.columns_per_frame)
      r.fail(p + "pixel_shift_by_row", "not an integer shift within one frame");
    m.pixel_shift_by_row.push_back(int(v));
  }
  if (const Json* win = Reader::find(df, "column_window")) {
    if (!win->is_array() || win->size() != 2) r.fail(p + "column_window", "expected [first, last]");
    m.column_window_first = r.integer((*win)[0], p + "column_window[0]", 0, m.columns_per_frame - 1);
    m.column_window_last = r.integer((*win)[1], p + "column_window[1]", 0, m.columns_per_frame - 1);
  } else {
    m.column_window_first = 0;
    m.column_window_last = m.columns_per_frame - 1;
  }
  if (const Json* prof = Reader::find(df, "udp_profile_lidar")) {
    if (!prof->is_string()) r.fail(p + "udp_profile_lidar", "not a string");
    const auto profile = udpProfileFromString(prof->get<std::string>());
    if (!profile) r.fail(p + "udp_profile_lidar", "unknown profile \"" + prof->get<std::string>() + "\"");
    m.profile = *profile;
    seen.has_profile = true;
  }
  if (const Json* fps = Reader::find(df, "fps")) {
    m.frames_per_second = r.integer(*fps, p + "fps", 1, 100);
    seen.has_fps = true;
  }
  return seen;
}

void finish(const Reader& r, Metadata& m, const DataFormatSeen& df, const std::string& angles_prefix,
            const std::string& format_name) {
  // lidar mode ↔ data format
  int mode_cols = 0, mode_fps = 0;
  if (!m.lidar_mode.empty()) {
    if (!parseLidarMode(m.lidar_mode, mode_cols, mode_fps) || !validColumns(mode_cols) ||
        (mode_fps != 5 && mode_fps != 10 && mode_fps != 20))
      r.fail("lidar_mode", "expected e.g. \"1024x10\", got \"" + m.lidar_mode + "\"");
  }
  if (df.present) {
    if (mode_cols && mode_cols != m.columns_per_frame)
      r.fail(format_name + ".columns_per_frame", std::to_string(m.columns_per_frame) + " disagrees with lidar_mode " +
                                                    m.lidar_mode);
  } else {
    m.columns_per_frame = mode_cols ? mode_cols : 1024;
    m.pixels_per_column = int(m.beam_altitude_deg.size());
    m.columns_per_packet = 16;
    m.column_window_first = 0;
    m.column_window_last = m.columns_per_frame - 1;
    m.pixel_shift_by_row = defaultPixelShift(m.columns_per_frame, m.pixels_per_column);
  }
  if (mode_fps && !df.has_fps) m.frames_per_second = mode_fps;
  if (m.lidar_mode.empty())
    m.lidar_mode = std::to_string(m.columns_per_frame) + "x" + std::to_string(m.frames_per_second);

  // beams
  const std::size_t n = m.beam_altitude_deg.size();
  if (n == 0) r.fail(angles_prefix + "beam_altitude_angles", "empty");
  if (m.beam_azimuth_deg.size() != n)
    r.fail(angles_prefix + "beam_azimuth_angles", std::to_string(m.beam_azimuth_deg.size()) +
                                                      " angles but beam_altitude_angles has " + std::to_string(n));
  if (m.pixels_per_column < 1 || m.pixels_per_column > 256)
    r.fail(angles_prefix + "beam_altitude_angles", "unsupported beam count " + std::to_string(n));
  if (std::size_t(m.pixels_per_column) != n)
    r.fail(angles_prefix + "beam_altitude_angles", std::to_string(n) + " angles but " + format_name +
                                                       ".pixels_per_column is " + std::to_string(m.pixels_per_column));
  bool all_zero = true;
  for (std::size_t i = 0; i < n; ++i) {
    if (std::abs(m.beam_altitude_deg[i]) > 90) r.fail(angles_prefix + "beam_altitude_angles", "beyond ±90°");
    if (std::abs(m.beam_azimuth_deg[i]) > 360) r.fail(angles_prefix + "beam_azimuth_angles", "beyond ±360°");
    if (m.beam_altitude_deg[i] != 0 || m.beam_azimuth_deg[i] != 0) all_zero = false;
  }
  if (all_zero) r.fail(angles_prefix + "beam_altitude_angles", "all beam angles are zero (uncalibrated sensor)");
  if (m.pixel_shift_by_row.size() != n)
    r.fail(format_name + ".pixel_shift_by_row", std::to_string(m.pixel_shift_by_row.size()) + " rows but " +
                                                    std::to_string(n) + " beams");
  if (m.columns_per_packet > m.columns_per_frame || m.columns_per_frame % m.columns_per_packet != 0)
    r.fail(format_name + ".columns_per_packet",
           std::to_string(m.columns_per_packet) + " does not divide columns_per_frame " +
               std::to_string(m.columns_per_frame));
  try {
    PacketFormat check(m.profile, m.pixels_per_column, m.columns_per_packet);
  } catch (const std::invalid_argument& e) {
    r.fail(format_name, e.what());
  }
}

Metadata parseNested(const Reader& r, const Json& root, Metadata m) {
  m.nested_layout = true;
  const Json& si = r.object(root, "sensor_info", "sensor_info");
  if (!Reader::find(root, "calibration_status")) r.fail("calibration_status", "missing");
  const Json& bi = r.object(root, "beam_intrinsics", "beam_intrinsics");
  const Json& li = r.object(root, "lidar_intrinsics", "lidar_intrinsics");
  const Json* ldf = Reader::find(root, "lidar_data_format");
  if (!ldf) r.fail("lidar_data_format", "missing");
  if (!ldf->is_object() && !ldf->is_string()) r.fail("lidar_data_format", "not a JSON object");

  m.prod_line = r.string(si, "prod_line");
  m.serial = parseSerial(r.string(si, "prod_sn"));
  if (const Json* id = Reader::find(si, "initialization_id"))
    m.init_id = std::uint32_t(r.integer(*id, "sensor_info.initialization_id", 0, 0xffffff));
  findVersion(r.string(si, "build_rev"), m);
  if (m.fw_major < 0) findVersion(r.string(si, "image_rev"), m);

  const Json* alt = Reader::find(bi, "beam_altitude_angles");
  if (!alt) r.fail("beam_intrinsics.beam_altitude_angles", "missing");
  m.beam_altitude_deg = r.numbers(*alt, "beam_intrinsics.beam_altitude_angles");
  const Json* az = Reader::find(bi, "beam_azimuth_angles");
  if (!az) r.fail("beam_intrinsics.beam_azimuth_angles", "missing");
  m.beam_azimuth_deg = r.numbers(*az, "beam_intrinsics.beam_azimuth_angles");
  m.lidar_origin_to_beam_origin_mm = defaultBeamOrigin(m.prod_line);
  if (const Json* o = Reader::find(bi, "lidar_origin_to_beam_origin_mm"))
    m.lidar_origin_to_beam_origin_mm = r.number(*o, "beam_intrinsics.lidar_origin_to_beam_origin_mm");
  m.beam_to_lidar = identity();
  m.beam_to_lidar[3] = m.lidar_origin_to_beam_origin_mm;
  if (const Json* b = Reader::find(bi, "beam_to_lidar_transform"))
    m.beam_to_lidar = r.transform(*b, "beam_intrinsics.beam_to_lidar_transform");
  const Json* l2s = Reader::find(li, "lidar_to_sensor_transform");
  if (!l2s) r.fail("lidar_intrinsics.lidar_to_sensor_transform", "missing");
  m.lidar_to_sensor = r.transform(*l2s, "lidar_intrinsics.lidar_to_sensor_transform");

  const Json* cp = Reader::find(root, "config_params");
  if (cp && cp->is_object()) {
    m.lidar_mode = r.string(*cp, "lidar_mode");
    if (const Json* prof = Reader::find(*cp, "udp_profile_lidar"); prof && prof->is_string()) {
      const auto profile = udpProfileFromString(prof->get<std::string>());
      if (!profile) r.fail("config_params.udp_profile_lidar", "unknown profile \"" + prof->get<std::string>() + "\"");
      m.profile = *profile;
    }
  }
  DataFormatSeen seen;
  if (ldf->is_object()) {
    const UdpProfile from_config = m.profile;
    seen = readDataFormat(r, *ldf, "lidar_data_format", m);
    if (!seen.has_profile) m.profile = from_config;
  }
  finish(r, m, seen, "beam_intrinsics.", "lidar_data_format");
  return m;
}

Metadata parseLegacy(const Reader& r, const Json& root, Metadata m) {
  m.prod_line = r.string(root, "prod_line");
  m.serial = parseSerial(r.string(root, "prod_sn"));
  if (const Json* id = Reader::find(root, "initialization_id"))
    m.init_id = std::uint32_t(r.integer(*id, "initialization_id", 0, 0xffffff));
  findVersion(r.string(root, "build_rev"), m);
  if (m.fw_major < 0) findVersion(r.string(root, "image_rev"), m);

  const Json* alt = Reader::find(root, "beam_altitude_angles");
  if (!alt) r.fail("beam_altitude_angles", "missing");
  m.beam_altitude_deg = r.numbers(*alt, "beam_altitude_angles");
  const Json* az = Reader::find(root, "beam_azimuth_angles");
  if (!az) r.fail("beam_azimuth_angles", "missing");
  m.beam_azimuth_deg = r.numbers(*az, "beam_azimuth_angles");
  m.lidar_origin_to_beam_origin_mm = defaultBeamOrigin(m.prod_line);
  if (const Json* o = Reader::find(root, "lidar_origin_to_beam_origin_mm"))
    m.lidar_origin_to_beam_origin_mm = r.number(*o, "lidar_origin_to_beam_origin_mm");
  m.beam_to_lidar = identity();
  m.beam_to_lidar[3] = m.lidar_origin_to_beam_origin_mm;
  if (const Json* b = Reader::find(root, "beam_to_lidar_transform"))
    m.beam_to_lidar = r.transform(*b, "beam_to_lidar_transform");
  m.lidar_to_sensor = defaultLidarToSensor();
  if (const Json* l2s = Reader::find(root, "lidar_to_sensor_transform"))
    m.lidar_to_sensor = r.transform(*l2s, "lidar_to_sensor_transform");
  if (const Json* mode = Reader::find(root, "lidar_mode")) {
    if (!mode->is_string()) r.fail("lidar_mode", "not a string");
    m.lidar_mode = mode->get<std::string>();
  }
  DataFormatSeen seen;
  if (const Json* df = Reader::find(root, "data_format")) {
    if (!df->is_object()) r.fail("data_format", "not a JSON object");
    seen = readDataFormat(r, *df, "data_format", m);
  }
  finish(r, m, seen, "", "data_format");
  return m;
}

}  // namespace

bool Metadata::crcFooter() const {
  if (profile == UdpProfile::kLegacy || profile == UdpProfile::kFusaRng15Rfl8Nir8Dual) return false;
  return fw_major > 3 || (fw_major == 3 && fw_minor >= 1);
}

bool Metadata::columnInWindow(int column) const {
  if (column_window_first <= column_window_last)
    return column >= column_window_first && column <= column_window_last;
  return column >= column_window_first || column <= column_window_last;  // wraps through 0
}

bool Metadata::slotInWindow(int slot) const {
  for (int c = slot * columns_per_packet; c < (slot + 1) * columns_per_packet; ++c)
    if (columnInWindow(c)) return true;
  return false;
}

Metadata parseMetadata(std::string_view json_text, const std::string& source) {
  Reader r(source);
  const Json root = Json::parse(json_text.begin(), json_text.end(), nullptr, /*allow_exceptions=*/false);
  if (root.is_discarded()) r.fail("(file)", "not valid JSON");
  if (!root.is_object()) r.fail("(file)", "not a JSON object");
  Metadata m;
  m.source = source;
  static constexpr const char* kNested[] = {"sensor_info",   "beam_intrinsics",    "lidar_intrinsics",
                                            "lidar_data_format", "calibration_status", "config_params",
                                            "imu_intrinsics"};
  for (const char* key : kNested)
    if (root.contains(key)) return parseNested(r, root, std::move(m));
  return parseLegacy(r, root, std::move(m));
}

Metadata parseMetadataFile(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw std::runtime_error(file.string() + ": cannot open Ouster metadata file");
  std::ostringstream text;
  text << in.rdbuf();
  return parseMetadata(text.str(), file.string());
}

}  // namespace rigcal::drivers::ouster
