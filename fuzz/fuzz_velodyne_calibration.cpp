// libFuzzer harness: Velodyne calibration text (ROS YAML or VeloView XML). Byte 0 chooses the model
// (bits 0-1) and the parser (bit 2: XML); the rest is the file's text. A bad file must come back as
// std::runtime_error with a one-line message; anything else (another exception, a crash) is a bug.
#include <cstdint>
#include <stdexcept>
#include <string>
#include <string_view>

#include "rigcal/drivers/velodyne/velodyne_calibration.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace rigcal::drivers::velodyne;
  if (size < 1) return 0;
  const Model model = static_cast<Model>(data[0] & 3);
  const std::string_view text(reinterpret_cast<const char*>(data + 1), size - 1);
  try {
    const Calibration cal = data[0] & 4 ? parseXmlCalibration(text, "fuzz.xml", model)
                                        : parseYamlCalibration(text, "fuzz.yaml", model);
    if (static_cast<int>(cal.lasers.size()) != modelInfo(model).lasers) __builtin_trap();
  } catch (const std::runtime_error& e) {
    const std::string what = e.what();
    if (what.empty() || what.find('\n') != std::string::npos) __builtin_trap();
  }
  return 0;
}
