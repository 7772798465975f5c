#include "rigcal/view/update_encoding.hpp"

#include <bit>
#include <cstring>

namespace rigcal::view {

static_assert(std::endian::native == std::endian::little, "the view's float32 buffers are little-endian");

std::size_t strideOf(UpdateKind kind) {
  return kind == UpdateKind::kTrajectory || kind == UpdateKind::kCandidate ? 4 : 3;
}

std::string encodeUpdate(UpdateKind kind, std::uint8_t lane, const std::vector<float>& values) {
  const auto count = static_cast<std::uint32_t>(values.size() / strideOf(kind));
  std::string out(kHeaderBytes + std::size_t(count) * strideOf(kind) * sizeof(float), '\0');
  out[0] = static_cast<char>(kind);
  out[1] = static_cast<char>(lane);
  std::memcpy(out.data() + 4, &count, sizeof count);
  if (count > 0) std::memcpy(out.data() + kHeaderBytes, values.data(), out.size() - kHeaderBytes);
  return out;
}

std::optional<DecodedUpdate> decodeUpdate(std::string_view message) {
  if (message.size() < kHeaderBytes) return std::nullopt;
  const auto kind_byte = static_cast<std::uint8_t>(message[0]);
  if (kind_byte < 1 || kind_byte > 6) return std::nullopt;
  DecodedUpdate d;
  d.kind = static_cast<UpdateKind>(kind_byte);
  d.lane = static_cast<std::uint8_t>(message[1]);
  std::uint32_t count = 0;
  std::memcpy(&count, message.data() + 4, sizeof count);
  const std::size_t floats = std::size_t(count) * strideOf(d.kind);
  if (message.size() != kHeaderBytes + floats * sizeof(float)) return std::nullopt;
  d.values.resize(floats);
  if (floats > 0) std::memcpy(d.values.data(), message.data() + kHeaderBytes, floats * sizeof(float));
  return d;
}

}  // namespace rigcal::view
