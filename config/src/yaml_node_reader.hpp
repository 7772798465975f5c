#pragma once
// Reads a rig file's YAML nodes with every mistake turned into a ConfigError at the offending node
// (file:line:column, the closest valid key, the allowed range): the checks rig_config.cpp's readers share.
#include <arpa/inet.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "rigcal/config/config_error.hpp"
#include "rigcal/config/rig_config.hpp"

namespace rigcal::config {

// Walks the YAML tree and turns every mistake into a ConfigError at the offending node.
class YamlNodeReader {
 public:
  explicit YamlNodeReader(std::filesystem::path file) : file_(std::move(file)) {}

  [[nodiscard]] SourceLocation at(const YAML::Node& node) const {
    const YAML::Mark m = node.Mark();
    if (m.is_null()) return {file_};
    return {file_, m.line + 1, m.column + 1};
  }
  [[noreturn]] void fail(const YAML::Node& node, const std::string& what) const {
    throw ConfigError(at(node), what);
  }

  void requireMap(const YAML::Node& node, const std::string& what) const {
    if (!node.IsMap()) fail(node, what + " must be a mapping of key: value");
  }

  /// Refuses keys outside `allowed`, naming the closest allowed one.
  void checkKeys(const YAML::Node& map, const std::vector<std::string>& allowed,
                 const std::string& section) const {
    for (const auto& kv : map) {
      const std::string key = kv.first.as<std::string>();
      if (std::find(allowed.begin(), allowed.end(), key) != allowed.end()) continue;
      std::string msg = "unknown key '" + key + "' in " + section;
      if (const std::string near = closestName(key, allowed); !near.empty())
        msg += " (did you mean '" + near + "'?)";
      fail(kv.first, msg);
    }
  }

  const YAML::Node required(const YAML::Node& map, const std::string& key, const std::string& section) const {
    const YAML::Node n = map[key];
    if (!n) fail(map, section + " needs '" + key + "'");
    return n;
  }

  std::string text(const YAML::Node& n, const std::string& key) const {
    if (!n.IsScalar()) fail(n, "'" + key + "' must be a string");
    return n.as<std::string>();
  }

  double number(const YAML::Node& n, const std::string& key) const {
    double v = 0;
    if (!n.IsScalar() || !YAML::convert<double>::decode(n, v) || !std::isfinite(v))
      fail(n, "'" + key + "' must be a finite number, got '" + scalarText(n) + "'");
    return v;
  }

  long long integer(const YAML::Node& n, const std::string& key) const {
    long long v = 0;
    if (!n.IsScalar() || !YAML::convert<long long>::decode(n, v))
      fail(n, "'" + key + "' must be an integer, got '" + scalarText(n) + "'");
    return v;
  }

  bool boolean(const YAML::Node& n, const std::string& key) const {
    bool v = false;
    if (!n.IsScalar() || !YAML::convert<bool>::decode(n, v))
      fail(n, "'" + key + "' must be true or false, got '" + scalarText(n) + "'");
    return v;
  }

  void inRange(const YAML::Node& n, const std::string& key, double v, double lo, double hi) const {
    if (v < lo || v > hi) {
      std::ostringstream msg;
      msg << "'" << key << "' = " << v << " is out of range; allowed [" << lo << ", " << hi << "]";
      fail(n, msg.str());
    }
  }

  /// A file the config refers to: resolved against the config's folder; it must be a readable regular
  /// file no larger than kMaxReferencedFileBytes (not a folder, a device, a pipe).
  std::filesystem::path existingFile(const YAML::Node& n, const std::string& key) const {
    std::filesystem::path p = text(n, key);
    if (p.is_relative()) p = file_.parent_path() / p;
    p = p.lexically_normal();
    const std::string named = key + " file '" + n.as<std::string>() + "'";
    std::error_code ec;
    const auto status = std::filesystem::status(p, ec);
    if (!std::filesystem::exists(status))
      fail(n, named + " not found (looked for " + p.string() + ")");
    if (!std::filesystem::is_regular_file(status))
      fail(n, named + " is not a regular file (" + p.string() + ")");
    if (const auto size = std::filesystem::file_size(p, ec); !ec && size > kMaxReferencedFileBytes)
      fail(n, named + " is " + std::to_string(size) + " bytes; the limit is " +
                  std::to_string(kMaxReferencedFileBytes) + " (" + p.string() + ")");
    if (!std::ifstream(p, std::ios::binary)) fail(n, named + " is not readable (" + p.string() + ")");
    return p;
  }

  /// An IPv4 address in dotted form; `multicast` also requires 224.0.0.0/4.
  std::string ipv4(const YAML::Node& n, const std::string& key, bool multicast = false) const {
    const std::string v = text(n, key);
    in_addr a{};
    if (inet_pton(AF_INET, v.c_str(), &a) != 1) fail(n, "'" + key + "' = '" + v + "' is not an IPv4 address");
    if (multicast && (ntohl(a.s_addr) >> 28) != 0xE)
      fail(n, "'" + key + "' = '" + v + "' is not a multicast address (224.0.0.0 to 239.255.255.255)");
    return v;
  }

  /// Refuses a mapping that names the same key twice (yaml-cpp would keep one silently), anywhere.
  void checkDuplicateKeys(const YAML::Node& node) const {
    if (node.IsSequence()) {
      for (const auto& child : node) checkDuplicateKeys(child);
    } else if (node.IsMap()) {
      std::set<std::string> seen;
      for (const auto& kv : node) {
        if (kv.first.IsScalar() && !seen.insert(kv.first.Scalar()).second)
          fail(kv.first, "key '" + kv.first.Scalar() + "' appears twice in the same mapping");
        checkDuplicateKeys(kv.second);
      }
    }
  }

 private:
  static std::string scalarText(const YAML::Node& n) {
    if (n.IsScalar()) return n.Scalar();
    return n.IsSequence() ? "a list" : n.IsMap() ? "a mapping" : "nothing";
  }
  std::filesystem::path file_;
};

}  // namespace rigcal::config
