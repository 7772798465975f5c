#include "calibrate_chain.hpp"

#include <gtest/gtest.h>

#include <chrono>
#include <cstdlib>
#include <fstream>
#include <sstream>

#include "sanitizers.hpp"

namespace rigcal::test {

nlohmann::json readJson(const std::filesystem::path& path) {
  std::ifstream in(path);
  return nlohmann::json::parse(in);
}

bool longTests() { return std::getenv("RIGCAL_LONG_TESTS") != nullptr && !RIGCAL_SANITIZED; }

void simulate(const std::string& scenario, const std::filesystem::path& sim_dir, double* seconds) {
  const auto t0 = std::chrono::steady_clock::now();
  const auto simulated = runRigcal({"sim", "--scenario", scenario, "--out", sim_dir.string()});
  if (seconds != nullptr) *seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  ASSERT_EQ(simulated.exit_code, 0) << "rigcal sim --scenario " << scenario << ": " << simulated.err;
}

void simulateYaml(const std::string& yaml, const std::filesystem::path& sim_dir, double* seconds) {
  std::filesystem::create_directories(sim_dir);
  const auto file = sim_dir / "scenario.yaml";
  std::ofstream(file) << yaml;
  simulate(file.string(), sim_dir, seconds);
}

std::vector<std::string> calibrateArgs(const std::filesystem::path& sim_dir, const std::filesystem::path& out_dir,
                                       const std::vector<std::string>& extra) {
  std::vector<std::string> args{"calibrate", "--config", (sim_dir / "rig.yaml").string(), "--pcap",
                                (sim_dir / "recording.pcap").string(), "--out", out_dir.string()};
  args.insert(args.end(), extra.begin(), extra.end());
  return args;
}

CommandResult compareWithTruth(const std::filesystem::path& sim_dir, const std::filesystem::path& out_dir,
                               double max_cm, double max_deg) {
  std::ostringstream cm, deg;
  cm << max_cm;
  deg << max_deg;
  return runRigcal({"compare", "--truth", (sim_dir / "truth.yaml").string(), "--result",
                    (out_dir / "calibration.yaml").string(), "--initial", (sim_dir / "rig.yaml").string(),
                    "--max-cm", cm.str(), "--max-deg", deg.str()});
}

std::string presetText(const std::string& name) {
  return fileContents(std::filesystem::path(RIGCAL_SCENARIOS_DIR) / (name + ".yaml"));
}

std::string shortenedPreset(const std::string& preset, const std::string& segments, const std::string& parameters) {
  std::string text = presetText(preset);
  const std::size_t params = text.find("  parameters:\n");
  const std::size_t drive = text.find("  segments:\n");
  if (params == std::string::npos || drive == std::string::npos || params > drive) return {};
  std::size_t end = text.find("\n", drive + 12);
  while (end != std::string::npos && text.compare(end + 1, 4, "    ") == 0) end = text.find("\n", end + 1);
  text = text.substr(0, drive) + "  segments:\n" + segments + (end == std::string::npos ? "" : text.substr(end + 1));
  // Each given parameter replaces the preset's line of the same name.
  std::istringstream given(parameters);
  for (std::string line; std::getline(given, line);) {
    const std::string key = line.substr(0, line.find(':') + 1);
    const std::size_t at = text.find("\n" + key, params);
    if (at != std::string::npos) text.erase(at + 1, text.find('\n', at + 1) - at);
  }
  text.insert(params + 14, parameters);
  return text;
}

}  // namespace rigcal::test
