#pragma once
// The sim → calibrate → compare chain the `rigcal calibrate` binary tests share (CalibratePresets*,
// CalibrateInteractive): simulate a preset or a scenario file with `rigcal sim`, the arguments that
// calibrate its capture, `rigcal compare` against its truth, and reading the outputs back.
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "../apps/run_command.hpp"

namespace rigcal::test {

nlohmann::json readJson(const std::filesystem::path& path);

/// RIGCAL_LONG_TESTS=1 in an optimised build: the full-length presets run.
bool longTests();

/// `rigcal sim --scenario SCENARIO --out SIM_DIR` (a preset name or a scenario YAML file); a fatal test
/// failure when it does not exit 0 (call it through ASSERT_NO_FATAL_FAILURE). Its seconds in `seconds`.
void simulate(const std::string& scenario, const std::filesystem::path& sim_dir, double* seconds = nullptr);
/// Writes `yaml` to SIM_DIR/scenario.yaml and simulates it into SIM_DIR.
void simulateYaml(const std::string& yaml, const std::filesystem::path& sim_dir, double* seconds = nullptr);

/// `calibrate --config SIM/rig.yaml --pcap SIM/recording.pcap --out OUT` followed by `extra`.
std::vector<std::string> calibrateArgs(const std::filesystem::path& sim_dir, const std::filesystem::path& out_dir,
                                       const std::vector<std::string>& extra = {});

/// `rigcal compare` of OUT/calibration.yaml with SIM/truth.yaml (and SIM/rig.yaml as the initial guess).
CommandResult compareWithTruth(const std::filesystem::path& sim_dir, const std::filesystem::path& out_dir,
                               double max_cm, double max_deg);

/// The text of the simulator preset `name` (sim/scenarios/<name>.yaml).
std::string presetText(const std::string& name);

/// The preset `preset` of RIGCAL_SCENARIOS_DIR with its drive replaced by `segments` and each line of
/// `parameters` replacing (or adding) the rig parameter of that name. Empty when the preset's layout is
/// not as expected.
std::string shortenedPreset(const std::string& preset, const std::string& segments, const std::string& parameters);

}  // namespace rigcal::test
