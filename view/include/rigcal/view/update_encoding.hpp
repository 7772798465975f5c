#pragma once
// The binary WebSocket messages of the live view. Each is an 8-byte header, then float32 values
// (little-endian, as every browser's Float32Array reads them):
//   byte 0: UpdateKind, byte 1: lane (a calibration lidar's index, 255 = none), bytes 2-3: 0,
//   bytes 4-7: uint32 item count, then count × stride(kind) float32.
// Status (counters, lidar names, the report) travels as JSON text messages instead.
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace rigcal::view {

enum class UpdateKind : std::uint8_t {
  kMapPoints = 1,     // x y z: new map points (map frame, decimated)
  kTrajectory = 2,    // x y z code: new mapping-lidar poses; code = FrameCode
  kCandidate = 3,     // x y z accepted(0/1): one candidate of `lane`
  kSelected = 4,      // x y z: the whole current selection of `lane` (replaces the previous one)
  kCloudBefore = 5,   // x y z: `lane`'s points through the initial guess (map frame of the outputs)
  kCloudAfter = 6,    // x y z: `lane`'s points through the calibrated extrinsic
};

/// What a trajectory pose is, for its marker.
enum class FrameCode : std::uint8_t { kFrame = 0, kKeyframe = 1, kStopped = 2, kLost = 3 };

constexpr std::uint8_t kNoLane = 255;
constexpr std::size_t kHeaderBytes = 8;

/// Floats per item of `kind` (3 or 4).
std::size_t strideOf(UpdateKind kind);

/// Encodes `values` (a multiple of strideOf(kind) floats) as one binary message.
std::string encodeUpdate(UpdateKind kind, std::uint8_t lane, const std::vector<float>& values);

struct DecodedUpdate {
  UpdateKind kind{};
  std::uint8_t lane = kNoLane;
  std::vector<float> values;
};

/// The inverse of encodeUpdate; nullopt for a message that is not one (wrong kind, size or count).
std::optional<DecodedUpdate> decodeUpdate(std::string_view message);

}  // namespace rigcal::view
