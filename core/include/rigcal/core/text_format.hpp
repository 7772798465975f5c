#pragma once
// Numbers as text, independent of the locale (std::to_chars): what a summary line, a message or a
// generated file prints is the same on every machine.
#include <charconv>
#include <string>

namespace rigcal {

/// Fixed-point with `decimals` digits; a value that rounds to zero is written without a sign ("0.000",
/// not "-0.000").
inline std::string fixed(double v, int decimals) {
  char buf[512];  // the longest double in fixed notation (about 310 digits) and the decimals asked for
  const auto r = std::to_chars(buf, buf + sizeof buf, v, std::chars_format::fixed, decimals);
  if (r.ec != std::errc{}) return std::to_string(v);  // only for absurd `decimals`
  std::string s(buf, r.ptr);
  if (s.front() == '-' && s.find_first_not_of("-0.") == std::string::npos) s.erase(0, 1);
  return s;
}

/// Shortest text that reads back to exactly v.
inline std::string exact(double v) {
  char buf[64];
  const auto r = std::to_chars(buf, buf + sizeof buf, v);
  return std::string(buf, r.ptr);
}

}  // namespace rigcal
