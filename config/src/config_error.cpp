#include "rigcal/config/config_error.hpp"

#include <algorithm>
#include <sstream>
#include <vector>

namespace rigcal::config {

std::string SourceLocation::str() const {
  std::ostringstream s;
  s << file.string();
  if (line > 0) s << ':' << line << ':' << column;
  return s.str();
}

namespace {
// Messages quote the user's text (keys, values, yaml-cpp's offending character): keep them one line.
std::string oneLine(std::string text) {
  for (char& c : text)
    if (static_cast<unsigned char>(c) < 0x20) c = ' ';
  return text;
}
}  // namespace

ConfigError::ConfigError(const SourceLocation& where, const std::string& what)
    : std::runtime_error(oneLine(where.str() + ": " + what)), where_(where) {}

namespace {
std::size_t editDistance(const std::string& a, const std::string& b) {
  std::vector<std::size_t> row(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    std::size_t diagonal = row[0];
    row[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t up = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (a[i - 1] != b[j - 1])});
      diagonal = up;
    }
  }
  return row[b.size()];
}
}  // namespace

std::string closestName(const std::string& name, const std::vector<std::string>& candidates) {
  std::string best;
  std::size_t best_distance = std::max<std::size_t>(3, name.size() / 3) + 1;
  for (const auto& c : candidates) {
    const std::size_t d = editDistance(name, c);
    if (d < best_distance) {
      best_distance = d;
      best = c;
    }
  }
  return best;
}

}  // namespace rigcal::config
