// libFuzzer harness: the Hesai angle-correction CSV parser. Byte 0 picks the channel count.
#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <string_view>

#include "rigcal/drivers/hesai/hesai_calibration.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 1) return 0;
  static constexpr std::size_t kChannels[] = {16, 32, 128, 1};
  const std::size_t channels = kChannels[data[0] % 4];
  const std::string_view text(reinterpret_cast<const char*>(data + 1), size - 1);
  try {
    const auto cal = rigcal::drivers::hesai::parseCalibrationCsv(text, "fuzz.csv", channels);
    if (cal.channels() != channels || cal.azimuth_offset_deg.size() != channels) __builtin_trap();
  } catch (const std::runtime_error& e) {
    if (std::string_view(e.what()).find('\n') != std::string_view::npos) __builtin_trap();
  }
  return 0;
}
