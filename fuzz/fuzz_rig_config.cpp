// Fuzzes the rig YAML loader: any bytes as a rig file. loadRigConfig must either return a config or
// throw ConfigError (one line, with a location); any other exception or a crash is a finding.
#include <cstdint>
#include <cstdlib>
#include <cstdio>
#include <exception>
#include <string>

#include "fuzz_input_file.hpp"
#include "rigcal/config/rig_config.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static rigcal::fuzz::InputFile file("fuzz_rig_config");
  const std::string& path = file.write(data, size);
  try {
    const rigcal::config::RigConfig rig = rigcal::config::loadRigConfig(path);
    (void)rig;
  } catch (const rigcal::config::ConfigError& e) {
    const std::string what = e.what();
    if (what.empty() || what.find('\n') != std::string::npos) std::abort();  // one line, as documented
  } catch (const std::exception& e) {
    std::fprintf(stderr, "loadRigConfig threw a non-ConfigError: %s\n", e.what());
    std::abort();
  }
  return 0;
}
