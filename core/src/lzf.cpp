#include "rigcal/core/lzf.hpp"

#include <stdexcept>

namespace rigcal {
namespace {

[[noreturn]] void fail(std::size_t at, const std::string& what) {
  throw std::runtime_error("corrupt LZF data at compressed byte " + std::to_string(at) + ": " + what);
}

}  // namespace

// The stream is a sequence of runs, each starting with a control byte c:
//   c < 32:  a literal run of c + 1 bytes copied from the input;
//   c >= 32: a back-reference of length (c >> 5) + 2 (when c >> 5 == 7 the next byte adds to the length),
//            at distance ((c & 31) << 8) + next byte + 1 behind the output's end (it may overlap itself).
std::vector<std::uint8_t> lzfDecompress(std::span<const std::uint8_t> in, std::size_t expected_size) {
  std::vector<std::uint8_t> out;
  out.reserve(expected_size);
  std::size_t i = 0;
  while (i < in.size()) {
    const std::size_t ctrl_at = i;
    const unsigned ctrl = in[i++];
    if (ctrl < 32) {
      const std::size_t len = ctrl + 1;
      if (len > in.size() - i) fail(ctrl_at, "literal run of " + std::to_string(len) + " bytes past the end");
      if (len > expected_size - out.size()) fail(ctrl_at, "output longer than " + std::to_string(expected_size));
      out.insert(out.end(), in.begin() + std::ptrdiff_t(i), in.begin() + std::ptrdiff_t(i + len));
      i += len;
      continue;
    }
    std::size_t len = ctrl >> 5;
    if (len == 7) {
      if (i >= in.size()) fail(ctrl_at, "back-reference length byte past the end");
      len += in[i++];
    }
    len += 2;
    if (i >= in.size()) fail(ctrl_at, "back-reference distance byte past the end");
    const std::size_t distance = ((std::size_t(ctrl & 31U) << 8) | in[i++]) + 1;
    if (distance > out.size())
      fail(ctrl_at, "back-reference " + std::to_string(distance) + " bytes behind an output of " +
                        std::to_string(out.size()));
    if (len > expected_size - out.size()) fail(ctrl_at, "output longer than " + std::to_string(expected_size));
    // Byte by byte: a reference may overlap the bytes it produces (a run).
    std::size_t from = out.size() - distance;
    for (std::size_t k = 0; k < len; ++k) out.push_back(out[from++]);
  }
  if (out.size() != expected_size)
    fail(in.size(), "decompressed to " + std::to_string(out.size()) + " bytes, the header says " +
                        std::to_string(expected_size));
  return out;
}

}  // namespace rigcal
