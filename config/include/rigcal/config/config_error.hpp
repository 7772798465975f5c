#pragma once
// A configuration mistake, reported on one line as "<file>:<line>:<column>: <what and what is allowed>".
#include <filesystem>
#include <stdexcept>
#include <string>
#include <vector>

namespace rigcal::config {

struct SourceLocation {
  std::filesystem::path file;
  int line = 0;    // 1-based; 0 when unknown
  int column = 0;  // 1-based
  [[nodiscard]] std::string str() const;
};

class ConfigError : public std::runtime_error {
 public:
  ConfigError(const SourceLocation& where, const std::string& what);
  [[nodiscard]] const SourceLocation& where() const { return where_; }

 private:
  SourceLocation where_;
};

/// The candidate closest to `name` by edit distance, or "" when none is plausibly meant.
std::string closestName(const std::string& name, const std::vector<std::string>& candidates);

}  // namespace rigcal::config
