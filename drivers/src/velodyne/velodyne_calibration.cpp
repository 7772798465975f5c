#include "rigcal/drivers/velodyne/velodyne_calibration.hpp"

#include <expat.h>
#include <yaml-cpp/yaml.h>

#include <charconv>
#include <cmath>
#include <fstream>
#include <map>
#include <numbers>
#include <sstream>
#include <stdexcept>

namespace rigcal::drivers::velodyne {
namespace {

constexpr double kDegToRad = std::numbers::pi / 180.0;

[[noreturn]] void fail(const std::string& name, const std::string& field, const std::string& what) {
  throw std::runtime_error(name + ": " + field + ": " + what);
}

std::string oneLine(std::string_view s, std::size_t max = 40) {
  std::string out;
  for (char c : s.substr(0, max)) out += (c == '\n' || c == '\r' || c == '\t') ? ' ' : c;
  if (s.size() > max) out += "...";
  return out;
}

std::optional<double> parseNumber(std::string_view text) {
  while (!text.empty() && std::isspace(static_cast<unsigned char>(text.front()))) text.remove_prefix(1);
  while (!text.empty() && std::isspace(static_cast<unsigned char>(text.back()))) text.remove_suffix(1);
  if (!text.empty() && text.front() == '+') text.remove_prefix(1);
  double v = 0;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), v);
  if (text.empty() || ec != std::errc() || end != text.data() + text.size() || !std::isfinite(v))
    return std::nullopt;
  return v;
}

// Plausibility limits: a beam elevation within ±90°, an azimuth offset within ±180°, offsets within
// a metre. Anything else is a unit mix-up (degrees given as radians, centimetres as metres).
void checkLaser(const LaserCorrection& l, const std::string& name, const std::string& where) {
  if (std::abs(l.vert_correction_rad) >= std::numbers::pi / 2)
    fail(name, where + "vert_correction", "elevation outside ±90°");
  if (std::abs(l.rot_correction_rad) > std::numbers::pi)
    fail(name, where + "rot_correction", "azimuth offset outside ±180°");
  if (std::abs(l.dist_correction_m) > 10.0) fail(name, where + "dist_correction", "more than 10 m");
  if (std::abs(l.vert_offset_m) > 1.0 || std::abs(l.horiz_offset_m) > 1.0)
    fail(name, where + "offset_correction", "beam offset over 1 m");
}

std::string countMismatch(std::size_t got, Model model, const char* what) {
  std::ostringstream os;
  os << got << ' ' << what << ", " << modelInfo(model).name << " has " << modelInfo(model).lasers
     << " lasers";
  return os.str();
}

// ---------------------------------------------------------------------------------------- YAML

double yamlNumber(const YAML::Node& laser, const char* key, const std::string& name,
                  const std::string& where, std::optional<double> fallback) {
  const YAML::Node v = laser[key];
  if (!v) {
    if (fallback) return *fallback;
    fail(name, where + key, "missing");
  }
  if (!v.IsScalar()) fail(name, where + key, "not a number");
  const auto n = parseNumber(v.Scalar());
  if (!n) fail(name, where + key, "not a number '" + oneLine(v.Scalar()) + "'");
  return *n;
}

}  // namespace

Calibration parseYamlCalibration(std::string_view text, const std::string& name, Model model) {
  YAML::Node root;
  try {
    root = YAML::Load(std::string(text));
  } catch (const YAML::Exception& e) {
    fail(name, "YAML", oneLine(e.what(), 120));
  }
  if (!root.IsMap()) fail(name, "lasers", "missing (the file is not a YAML map)");
  const YAML::Node lasers = root["lasers"];
  if (!lasers) fail(name, "lasers", "missing");
  if (!lasers.IsSequence()) fail(name, "lasers", "not a list");
  const int n = modelInfo(model).lasers;
  if (lasers.size() != static_cast<std::size_t>(n))
    fail(name, "lasers", countMismatch(lasers.size(), model, "entries"));
  if (const YAML::Node num = root["num_lasers"]) {
    const auto v = num.IsScalar() ? parseNumber(num.Scalar()) : std::nullopt;
    if (!v) fail(name, "num_lasers", "not a number");
    if (*v != n) fail(name, "num_lasers", countMismatch(static_cast<std::size_t>(std::max(0.0, *v)), model, "lasers"));
  }

  Calibration cal;
  cal.source = name;
  cal.lasers.resize(n);
  std::vector<bool> seen(n, false);
  for (std::size_t i = 0; i < lasers.size(); ++i) {
    const YAML::Node laser = lasers[i];
    const std::string where = "lasers[" + std::to_string(i) + "].";
    if (!laser.IsMap()) fail(name, "lasers[" + std::to_string(i) + "]", "not a map");
    const double id = yamlNumber(laser, "laser_id", name, where, std::nullopt);
    if (id != std::floor(id) || id < 0 || id >= n)
      fail(name, where + "laser_id", "out of range 0.." + std::to_string(n - 1));
    const int k = static_cast<int>(id);
    if (seen[k]) fail(name, where + "laser_id", "duplicate id " + std::to_string(k));
    seen[k] = true;
    LaserCorrection& l = cal.lasers[k];
    l.rot_correction_rad = yamlNumber(laser, "rot_correction", name, where, std::nullopt);
    l.vert_correction_rad = yamlNumber(laser, "vert_correction", name, where, std::nullopt);
    l.dist_correction_m = yamlNumber(laser, "dist_correction", name, where, 0.0);
    l.vert_offset_m = yamlNumber(laser, "vert_offset_correction", name, where, 0.0);
    l.horiz_offset_m = yamlNumber(laser, "horiz_offset_correction", name, where, 0.0);
    checkLaser(l, name, where);
  }
  return cal;
}

// ----------------------------------------------------------------------------------------- XML
namespace {

// Collects what we need from a VeloView calibration while expat walks the tree:
// boost_serialization/DB/{enabled_/item, points_/item/px/<field>}.
struct XmlState {
  std::vector<std::string> path;
  std::string text;
  std::vector<int> enabled;
  bool enabled_seen = false, points_seen = false, db_seen = false;
  std::vector<std::map<std::string, std::string>> px;
  std::map<std::string, std::string> current;
  std::string error;
  std::size_t depth_limit = 64;

  [[nodiscard]] bool at(std::initializer_list<const char*> tail) const {
    if (path.size() < tail.size()) return false;
    std::size_t i = path.size() - tail.size();
    for (const char* t : tail)
      if (path[i++] != t) return false;
    return true;
  }
};

void XMLCALL onStart(void* user, const XML_Char* name, const XML_Char**) {
  auto* s = static_cast<XmlState*>(user);
  s->path.emplace_back(name);
  s->text.clear();
  if (s->path.size() > s->depth_limit && s->error.empty()) s->error = "nested too deeply";
  if (s->at({"DB"})) s->db_seen = true;
  if (s->at({"DB", "enabled_"})) s->enabled_seen = true;
  if (s->at({"DB", "points_"})) s->points_seen = true;
  if (s->at({"DB", "points_", "item", "px"})) s->current.clear();
}

void XMLCALL onEnd(void* user, const XML_Char*) {
  auto* s = static_cast<XmlState*>(user);
  if (s->at({"DB", "enabled_", "item"})) {
    const auto v = parseNumber(s->text);
    if (!v && s->error.empty()) s->error = "enabled_/item: not a number '" + oneLine(s->text) + "'";
    s->enabled.push_back(v && *v != 0 ? 1 : 0);
  } else if (s->path.size() >= 5 && s->at({"points_", "item", "px", s->path.back().c_str()}) &&
             s->path[s->path.size() - 5] == "DB") {
    s->current[s->path.back()] = s->text;
  } else if (s->at({"DB", "points_", "item", "px"})) {
    s->px.push_back(std::move(s->current));
    s->current.clear();
  }
  if (!s->path.empty()) s->path.pop_back();
  s->text.clear();
}

void XMLCALL onText(void* user, const XML_Char* data, int len) {
  auto* s = static_cast<XmlState*>(user);
  if (s->text.size() < 256) s->text.append(data, static_cast<std::size_t>(len));
}

}  // namespace

Calibration parseXmlCalibration(std::string_view text, const std::string& name, Model model) {
  XmlState state;
  XML_Parser parser = XML_ParserCreate(nullptr);
  if (!parser) throw std::runtime_error(name + ": XML: cannot create a parser");
  XML_SetUserData(parser, &state);
  XML_SetElementHandler(parser, onStart, onEnd);
  XML_SetCharacterDataHandler(parser, onText);
  const bool ok = text.size() <= static_cast<std::size_t>(INT32_MAX) &&
                  XML_Parse(parser, text.data(), static_cast<int>(text.size()), XML_TRUE) == XML_STATUS_OK;
  std::string error;
  if (!ok)
    error = std::string(XML_ErrorString(XML_GetErrorCode(parser))) + " at line " +
            std::to_string(XML_GetCurrentLineNumber(parser));
  XML_ParserFree(parser);
  if (!ok) fail(name, "XML", error);
  if (!state.error.empty()) fail(name, "XML", state.error);
  if (!state.db_seen) fail(name, "DB", "missing (not a VeloView calibration)");
  if (!state.points_seen) fail(name, "points_", "missing");

  const int n = modelInfo(model).lasers;
  if (state.enabled_seen) {
    int count = 0;
    for (int e : state.enabled) count += e;
    if (count != n) fail(name, "enabled_", countMismatch(static_cast<std::size_t>(count), model, "lasers enabled"));
    for (int i = 0; i < n; ++i)
      if (i >= static_cast<int>(state.enabled.size()) || !state.enabled[i])
        fail(name, "enabled_", "laser " + std::to_string(i) + " disabled");
  } else if (state.px.size() != static_cast<std::size_t>(n)) {
    fail(name, "points_", countMismatch(state.px.size(), model, "entries"));
  }

  Calibration cal;
  cal.source = name;
  cal.lasers.resize(n);
  std::vector<bool> seen(n, false);
  for (std::size_t i = 0; i < state.px.size(); ++i) {
    const auto& px = state.px[i];
    const std::string where = "points_[" + std::to_string(i) + "].";
    auto number = [&](const char* key, bool required) -> double {
      const auto it = px.find(key);
      if (it == px.end()) {
        if (required) fail(name, where + key, "missing");
        return 0.0;
      }
      const auto v = parseNumber(it->second);
      if (!v) fail(name, where + key, "not a number '" + oneLine(it->second) + "'");
      return *v;
    };
    const double id = number("id_", true);
    if (id != std::floor(id) || id < 0 || id > 1e6) fail(name, where + "id_", "not a laser index");
    if (id >= n) continue;  // VeloView files list 64 slots; only the enabled ones matter
    const int k = static_cast<int>(id);
    if (seen[k]) fail(name, where + "id_", "duplicate id " + std::to_string(k));
    seen[k] = true;
    LaserCorrection& l = cal.lasers[k];
    l.rot_correction_rad = number("rotCorrection_", true) * kDegToRad;
    l.vert_correction_rad = number("vertCorrection_", true) * kDegToRad;
    l.dist_correction_m = number("distCorrection_", false) * 0.01;
    l.vert_offset_m = number("vertOffsetCorrection_", false) * 0.01;
    l.horiz_offset_m = number("horizOffsetCorrection_", false) * 0.01;
    checkLaser(l, name, where);
  }
  for (int k = 0; k < n; ++k)
    if (!seen[k]) fail(name, "points_", "no entry for laser " + std::to_string(k));
  return cal;
}

Calibration loadCalibration(const std::filesystem::path& file, Model model) {
  const std::string name = file.string();
  std::ifstream in(file, std::ios::binary);
  if (!in) fail(name, "file", "cannot be opened");
  std::ostringstream buffer;
  buffer << in.rdbuf();
  const std::string text = buffer.str();
  if (text.size() > (64u << 20)) fail(name, "file", "larger than 64 MiB");
  std::size_t first = text.find_first_not_of(" \t\r\n\xEF\xBB\xBF");
  if (first != std::string::npos && text[first] == '<') return parseXmlCalibration(text, name, model);
  return parseYamlCalibration(text, name, model);
}

// ------------------------------------------------------------------------------------ nominal
namespace {

Calibration fromDegrees(const char* name, const double* elevation, const double* azimuth_offset, int n) {
  Calibration cal;
  cal.source = std::string("nominal ") + name;
  cal.lasers.resize(n);
  for (int i = 0; i < n; ++i) {
    cal.lasers[i].vert_correction_rad = elevation[i] * kDegToRad;
    // The manuals give the offset to add to the azimuth; the correction is subtracted.
    cal.lasers[i].rot_correction_rad = azimuth_offset ? -azimuth_offset[i] * kDegToRad : 0.0;
  }
  return cal;
}

// VLP-16 user manual, laser ID → vertical angle.
constexpr double kVlp16Elevation[16] = {-15, 1, -13, 3, -11, 5, -9, 7, -7, 9, -5, 11, -3, 13, -1, 15};

// HDL-32E user manual, laser ID → vertical angle.
constexpr double kHdl32eElevation[32] = {
    -30.67, -9.33, -29.33, -8.00, -28.00, -6.67, -26.67, -5.33, -25.33, -4.00, -24.00,
    -2.67,  -22.67, -1.33, -21.33, 0.00,  -20.00, 1.33,  -18.67, 2.67,  -17.33, 4.00,
    -16.00, 5.33,  -14.67, 6.67,  -13.33, 8.00,  -12.00, 9.33,  -10.67, 10.67};

// VLP-32C user manual, laser ID → vertical angle and azimuth offset.
constexpr double kVlp32cElevation[32] = {
    -25,    -1,     -1.667, -15.639, -11.31, 0,      -0.667, -8.843, -7.254, 0.333, -0.333,
    -6.148, -5.333, 1.333,  0.667,   -4,     -4.667, 1.667,  1,      -3.667, -3.333, 3.333,
    2.333,  -2.667, -3,     7,       4.667,  -2.333, -2,     15,     10.333, -1.333};
constexpr double kVlp32cAzimuthOffset[32] = {
    1.4, -4.2, 1.4, -1.4, 1.4, -1.4, 4.2, -1.4, 1.4, -4.2, 1.4, -1.4, 4.2, -1.4, 4.2, -1.4,
    1.4, -4.2, 1.4, -4.2, 4.2, -1.4, 1.4, -1.4, 1.4, -1.4, 1.4, -4.2, 4.2, -1.4, 1.4, -1.4};

}  // namespace

std::optional<Calibration> nominalCalibration(Model model) {
  switch (model) {
    case Model::kVlp16: return fromDegrees("VLP-16", kVlp16Elevation, nullptr, 16);
    case Model::kHdl32e: return fromDegrees("HDL-32E", kHdl32eElevation, nullptr, 32);
    case Model::kVlp32c: return fromDegrees("VLP-32C", kVlp32cElevation, kVlp32cAzimuthOffset, 32);
    case Model::kVls128: return std::nullopt;
  }
  return std::nullopt;
}

}  // namespace rigcal::drivers::velodyne
