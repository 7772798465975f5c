#include "rig_loading.hpp"

#include <filesystem>
#include <fstream>

#include "commands.hpp"
#include "exit_codes.hpp"
#include "rigcal/config/config_error.hpp"
#include "rigcal/drivers/packet_decoder.hpp"
#include "rigcal/pipeline/sensor_driver.hpp"

namespace rigcal::app {

void requireInputFile(const std::string& path, const std::string& what) {
  namespace fs = std::filesystem;
  std::error_code ec;
  const auto status = fs::status(path, ec);
  if (!fs::exists(status)) throw CommandFailed(kExitInput, path + ": " + what + " not found");
  if (!fs::is_regular_file(status)) throw CommandFailed(kExitInput, path + ": " + what + " is not a regular file");
  if (!std::ifstream(path, std::ios::binary)) throw CommandFailed(kExitInput, path + ": " + what + " is not readable");
}

config::RigConfig loadRig(const std::string& path) {
  requireInputFile(path, "rig file");
  config::RigConfig rig;
  try {
    rig = config::loadRigConfig(path);
  } catch (const config::ConfigError& e) {
    throw CommandFailed(kExitConfig, e.what());
  }
  for (const auto& sensor : rig.sensors) {
    if (sensor.model == pipeline::kPointCloud2Model) {  // decoded scans from a bag: no decoder to build
      if (!sensor.source.topic)
        throw CommandFailed(kExitConfig, config::ConfigError(sensor.where, "sensor '" + sensor.name + "': model " +
                                                                               pipeline::kPointCloud2Model +
                                                                               " needs a bag topic (source: {topic: ...})")
                                             .what());
      continue;
    }
    try {
      (void)drivers::makeDecoder(pipeline::decoderConfigFor(sensor));
    } catch (const std::exception& e) {
      throw CommandFailed(kExitConfig, config::ConfigError(sensor.where, "sensor '" + sensor.name + "': " + e.what()).what());
    }
  }
  return rig;
}

}  // namespace rigcal::app
