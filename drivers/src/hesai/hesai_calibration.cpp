#include "rigcal/drivers/hesai/hesai_calibration.hpp"

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>

namespace rigcal::drivers::hesai {
namespace {

std::string_view trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t' || s.front() == '\r' || s.front() == '\xEF' ||
                        s.front() == '\xBB' || s.front() == '\xBF'))
    s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t' || s.back() == '\r')) s.remove_suffix(1);
  return s;
}

std::vector<std::string_view> splitFields(std::string_view line) {
  std::vector<std::string_view> fields;
  std::size_t start = 0;
  while (true) {
    const std::size_t comma = line.find(',', start);
    fields.push_back(trim(line.substr(start, comma == std::string_view::npos ? line.npos : comma - start)));
    if (comma == std::string_view::npos) break;
    start = comma + 1;
  }
  // Trailing empty columns ("1,15,0,,") are tolerated, as spreadsheet exports produce them.
  while (fields.size() > 1 && fields.back().empty()) fields.pop_back();
  return fields;
}

bool parseNumber(std::string_view field, double& value) {
  if (field.empty()) return false;
  const std::string s(field);
  char* end = nullptr;
  errno = 0;
  value = std::strtod(s.c_str(), &end);
  return errno == 0 && end == s.c_str() + s.size() && std::isfinite(value);
}

[[noreturn]] void fail(std::string_view name, std::size_t line, const std::string& what) {
  throw std::runtime_error(std::string(name) + ":" + std::to_string(line) + ": " + what);
}

std::string quoted(std::string_view field) {
  std::string s(field.substr(0, 40));
  for (char& c : s)
    if (static_cast<unsigned char>(c) < 0x20 || static_cast<unsigned char>(c) >= 0x7F) c = '?';
  return "'" + s + "'";
}

}  // namespace

Calibration parseCalibrationCsv(std::string_view text, std::string_view name, std::size_t channels) {
  Calibration cal;
  std::size_t line_no = 0;
  std::size_t last_line = 1;
  bool header_seen = false;
  std::size_t pos = 0;
  while (pos <= text.size()) {
    std::size_t nl = text.find('\n', pos);
    if (nl == std::string_view::npos) nl = text.size();
    const std::string_view line = trim(text.substr(pos, nl - pos));
    pos = nl + 1;
    ++line_no;
    if (line.empty()) continue;
    last_line = line_no;
    const auto fields = splitFields(line);
    double first = 0;
    if (!parseNumber(fields[0], first)) {
      // The one header line, before any data row.
      if (!header_seen && cal.channels() == 0) {
        header_seen = true;
        continue;
      }
      fail(name, line_no, "channel " + quoted(fields[0]) + " is not a number");
    }
    if (fields.size() != 3)
      fail(name, line_no, "expected 3 columns (channel, elevation, azimuth), got " + std::to_string(fields.size()));
    const std::size_t expected_channel = cal.channels() + 1;
    if (first != static_cast<double>(expected_channel))
      fail(name, line_no, "channel " + quoted(fields[0]) + ", expected " + std::to_string(expected_channel));
    double elevation = 0, azimuth = 0;
    if (!parseNumber(fields[1], elevation)) fail(name, line_no, "elevation " + quoted(fields[1]) + " is not a number");
    if (!parseNumber(fields[2], azimuth)) fail(name, line_no, "azimuth " + quoted(fields[2]) + " is not a number");
    if (std::abs(elevation) > 90.0)
      fail(name, line_no, "elevation " + std::string(fields[1]) + " deg outside [-90, 90]");
    if (std::abs(azimuth) > 180.0)
      fail(name, line_no, "azimuth offset " + std::string(fields[2]) + " deg outside [-180, 180]");
    if (expected_channel > channels)
      fail(name, line_no, "channel " + std::to_string(expected_channel) + " beyond the model's " +
                              std::to_string(channels) + " channels");
    cal.elevation_deg.push_back(elevation);
    cal.azimuth_offset_deg.push_back(azimuth);
  }
  if (cal.channels() != channels)
    fail(name, last_line, "file ends after " + std::to_string(cal.channels()) + " channel rows, expected " +
                              std::to_string(channels));
  return cal;
}

Calibration readCalibrationCsv(const std::filesystem::path& file, std::size_t channels) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw std::runtime_error(file.string() + ": cannot open the angle-correction file");
  std::ostringstream buffer;
  buffer << in.rdbuf();
  if (in.bad()) throw std::runtime_error(file.string() + ": read error");
  return parseCalibrationCsv(buffer.str(), file.string(), channels);
}

Calibration nominalCalibration(const ModelSpec& spec) {
  Calibration cal;
  switch (spec.model) {
    case Model::kXT16:
      for (int i = 0; i < 16; ++i) cal.elevation_deg.push_back(15.0 - 2.0 * i);
      break;
    case Model::kXT32:
      for (int i = 0; i < 32; ++i) cal.elevation_deg.push_back(15.0 - 1.0 * i);
      break;
    case Model::kQT128:  // no nominal table here: these need their angle-correction file
    case Model::kPandar40P:
    case Model::kPandar64:
    case Model::kQT64:
    case Model::kXT32M:
      throw std::runtime_error(std::string(spec.name) +
                               ": an angle-correction CSV is required (DecoderConfig::calibration is empty)");
  }
  cal.azimuth_offset_deg.assign(cal.elevation_deg.size(), 0.0);
  return cal;
}

}  // namespace rigcal::drivers::hesai
