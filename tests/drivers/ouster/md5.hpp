#pragma once
// A compact MD5 (RFC 1321) for comparing decoded fields with ouster-sdk's digests. Test support only.
#include <array>
#include <cstddef>
#include <cstdint>
#include <string>

namespace rigcal::test {

class Md5 {
 public:
  Md5();
  void update(const void* data, std::size_t size);
  /// Finishes and returns the lowercase hex digest; the object must not be updated afterwards.
  std::string hex();

 private:
  void block(const std::uint8_t* p);
  std::array<std::uint32_t, 4> s_;
  std::array<std::uint8_t, 64> buf_{};
  std::size_t buffered_ = 0;
  std::uint64_t total_ = 0;
};

/// md5 hex of a byte range.
std::string md5Hex(const void* data, std::size_t size);

}  // namespace rigcal::test
