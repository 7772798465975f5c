#pragma once
// A LidarScan-like accumulator of the raw Ouster channel fields of one frame: H×W images (row = beam,
// column = measurement id, NOT destaggered) of RANGE (mm), REFLECTIVITY, SIGNAL, NEAR_IR and, for the
// dual profiles, RANGE2 / REFLECTIVITY2 / SIGNAL2, plus per-column TIMESTAMP, STATUS and MEASUREMENT_ID.
// Columns are stored as the packets carry them, whatever their status, exactly like ouster-sdk's
// LidarScan; columns that never arrived stay zero. Used to check the decoder field by field against
// ouster-sdk digests, and for images (destagger() aligns each row by pixel_shift_by_row).
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "rigcal/drivers/ouster/ouster_metadata.hpp"
#include "rigcal/drivers/ouster/ouster_packet_format.hpp"

namespace rigcal::drivers::ouster {

class RawScan {
 public:
  explicit RawScan(const Metadata& metadata);

  enum class AddResult {
    kAdded,       // the packet's columns were written
    kOtherFrame,  // the packet belongs to another frame than the one being filled: nothing written
    kRejected,    // not a lidar packet of this format (see error())
  };
  /// Writes one lidar packet's columns. The first packet sets the frame id.
  AddResult add(std::span<const std::uint8_t> payload);
  /// Clears every field and forgets the frame id.
  void reset();

  [[nodiscard]] int width() const { return w_; }
  [[nodiscard]] int height() const { return h_; }
  [[nodiscard]] std::optional<std::uint32_t> frameId() const { return frame_id_; }
  [[nodiscard]] const std::string& error() const { return error_; }
  [[nodiscard]] std::size_t packets() const { return packets_; }

  // Row-major H×W images.
  std::vector<std::uint32_t> range, range2;
  std::vector<std::uint8_t> reflectivity, reflectivity2;
  std::vector<std::uint16_t> signal, signal2, near_ir;
  // Per column.
  std::vector<std::uint64_t> timestamp, status;
  std::vector<std::uint16_t> measurement_id;

  /// Destaggered copy of an H×W image: row u is shifted right by pixel_shift_by_row[u] (mod W), so that
  /// one column of the result is one azimuth.
  template <class T>
  [[nodiscard]] std::vector<T> destagger(const std::vector<T>& image) const {
    std::vector<T> out(image.size());
    for (int u = 0; u < h_; ++u) {
      const int s = ((shift_[std::size_t(u)] % w_) + w_) % w_;
      for (int v = 0; v < w_; ++v)
        out[std::size_t(u) * std::size_t(w_) + std::size_t((v + s) % w_)] = image[std::size_t(u) * std::size_t(w_) + std::size_t(v)];
    }
    return out;
  }

 private:
  PacketFormat format_;
  int w_, h_;
  std::vector<int> shift_;
  std::optional<std::uint32_t> frame_id_;
  std::string error_;
  std::size_t packets_ = 0;
};

}  // namespace rigcal::drivers::ouster
