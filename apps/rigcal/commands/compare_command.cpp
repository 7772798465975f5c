// `rigcal compare --truth truth.yaml --result calibration.yaml [--initial rig.yaml] [--max-cm C --max-deg D]`:
// a calibration next to the simulator's ground truth (and the initial guess it started from). What each
// calibration can know is compared: every calibration lidar's T_mapping_calib in full; for the mapping lidar
// only z, roll and pitch (the ground fixes those; x, y and yaw are kept from the guess).
#include <cmath>
#include <iomanip>
#include <iostream>
#include <numbers>
#include <optional>
#include <sstream>

#include <yaml-cpp/yaml.h>

#include "../commands.hpp"
#include "../exit_codes.hpp"
#include "../rig_loading.hpp"
#include "rigcal/config/config_error.hpp"
#include "rigcal/config/rig_config.hpp"
#include "rigcal/core/pose.hpp"

namespace rigcal::app {

namespace {

struct CompareOptions {
  std::string truth, result, initial;
  std::optional<double> max_cm, max_deg;
};

constexpr double kDeg = 180.0 / std::numbers::pi;

YAML::Node loadYaml(const std::string& path) {
  try {
    return YAML::LoadFile(path);
  } catch (const YAML::Exception& e) {
    throw CommandFailed(kExitInput, path + ": " + e.what());
  }
}

Pose readXyzRpy(const YAML::Node& node, const std::string& where) {
  XyzRpy v;
  try {
    v.x = node["x"].as<double>();
    v.y = node["y"].as<double>();
    v.z = node["z"].as<double>();
    v.roll = node["roll"].as<double>();
    v.pitch = node["pitch"].as<double>();
    v.yaw = node["yaw"].as<double>();
  } catch (const YAML::Exception&) {
    throw CommandFailed(kExitInput, where + ": needs x, y, z, roll, pitch, yaw");
  }
  return fromXyzRpy(v);
}

std::string formatPose(const Pose& T) {
  const XyzRpy v = toXyzRpy(T);
  std::ostringstream s;
  s << std::fixed << std::setprecision(4) << std::showpos << v.x << " " << v.y << " " << v.z << " m  "
    << std::setprecision(3) << v.roll * kDeg << " " << v.pitch * kDeg << " " << v.yaw * kDeg << " deg";
  return s.str();
}

struct Error {
  double cm = 0, deg = 0;
};

Error fullError(const Pose& estimate, const Pose& truth) {
  return {100.0 * (estimate.translation() - truth.translation()).norm(), rotationAngleBetween(estimate, truth) * kDeg};
}

/// z, roll and pitch only: the part of T_base_mapping the ground plane determines.
Error groundError(const Pose& estimate, const Pose& truth) {
  const XyzRpy e = toXyzRpy(estimate), t = toXyzRpy(truth);
  return {100.0 * std::abs(e.z - t.z), std::max(std::abs(e.roll - t.roll), std::abs(e.pitch - t.pitch)) * kDeg};
}

std::string formatError(const Error& e) {
  std::ostringstream s;
  s << std::fixed << std::setprecision(3) << e.cm << " cm " << e.deg << " deg";
  return s.str();
}

void run(const CompareOptions& o) {
  requireInputFile(o.truth, "truth file");
  requireInputFile(o.result, "result file");
  if (!o.initial.empty()) requireInputFile(o.initial, "rig file");
  const YAML::Node truth = loadYaml(o.truth);
  const YAML::Node result = loadYaml(o.result);
  if (!truth["sensors"] || !truth["mapping_lidar"])
    throw CommandFailed(kExitInput, o.truth + ": not a rigcal sim truth.yaml (needs sensors and mapping_lidar)");
  if (!result["T_base_sensor"])
    throw CommandFailed(kExitInput, o.result + ": not a rigcal calibration.yaml (needs T_base_sensor)");
  std::optional<config::RigConfig> rig;
  if (!o.initial.empty()) {
    try {
      rig = config::loadRigConfig(o.initial);
    } catch (const config::ConfigError& e) {
      throw CommandFailed(kExitConfig, e.what());
    }
  }

  const auto truthBaseSensor = [&](const std::string& name) {
    const YAML::Node n = truth["sensors"][name];
    if (!n) throw CommandFailed(kExitInput, o.truth + ": no sensor '" + name + "'");
    return readXyzRpy(n["T_base_sensor"], o.truth + ": sensors." + name + ".T_base_sensor");
  };
  const auto resultBaseSensor = [&](const std::string& name) {
    const YAML::Node n = result["T_base_sensor"][name];
    if (!n) throw CommandFailed(kExitInput, o.result + ": T_base_sensor has no '" + name + "'");
    return readXyzRpy(n, o.result + ": T_base_sensor." + name);
  };
  const auto initialBaseSensor = [&](const std::string& name) -> std::optional<Pose> {
    if (!rig) return std::nullopt;
    const auto it = rig->initial_T_base_sensor.find(name);
    return it == rig->initial_T_base_sensor.end() ? std::nullopt : std::optional(it->second);
  };

  const std::string mapping = truth["mapping_lidar"].as<std::string>();
  const Pose truth_base_mapping = truthBaseSensor(mapping);
  const Pose result_base_mapping = resultBaseSensor(mapping);
  const auto initial_base_mapping = initialBaseSensor(mapping);

  bool within = true;
  const auto check = [&](const Error& e) {
    if ((o.max_cm && e.cm > *o.max_cm) || (o.max_deg && e.deg > *o.max_deg)) within = false;
  };
  std::cout << std::left;
  const auto row = [](const std::string& a, const std::string& b, const std::string& c) {
    std::cout << "  " << std::setw(10) << a << std::setw(52) << b << "  " << c << "\n";
  };
  std::cout << "truth " << o.truth << "\nresult " << o.result << "\n";

  for (const auto& node : truth["calibration_lidars"]) {
    const std::string calib = node.as<std::string>();
    const Pose truth_T = truth_base_mapping.inverse() * truthBaseSensor(calib);
    const Pose result_T = result_base_mapping.inverse() * resultBaseSensor(calib);
    const Error error = fullError(result_T, truth_T);
    check(error);
    std::cout << "\nT_" << mapping << "_" << calib << " (x y z, roll pitch yaw)\n";
    row("truth", formatPose(truth_T), "");
    if (const auto init_calib = initialBaseSensor(calib); init_calib && initial_base_mapping)
      row("initial", formatPose(initial_base_mapping->inverse() * *init_calib),
          "error " + formatError(fullError(initial_base_mapping->inverse() * *init_calib, truth_T)));
    row("result", formatPose(result_T), "error " + formatError(error));
  }

  const Error ground = groundError(result_base_mapping, truth_base_mapping);
  check(ground);
  std::cout << "\nT_base_" << mapping << " (z, roll, pitch from the ground; x, y, yaw kept from the guess)\n";
  row("truth", formatPose(truth_base_mapping), "");
  if (initial_base_mapping)
    row("initial", formatPose(*initial_base_mapping),
        "z/roll/pitch error " + formatError(groundError(*initial_base_mapping, truth_base_mapping)));
  row("result", formatPose(result_base_mapping), "z/roll/pitch error " + formatError(ground));

  if (o.max_cm || o.max_deg) {
    std::ostringstream bound;
    if (o.max_cm) bound << *o.max_cm << " cm";
    if (o.max_cm && o.max_deg) bound << " / ";
    if (o.max_deg) bound << *o.max_deg << " deg";
    std::cout << "\n" << (within ? "every error within " : "NOT within ") << bound.str() << "\n";
    if (!within) throw CommandFailed(kExitFailure, "calibration error above " + bound.str());
  }
}

}  // namespace

void addCompareCommand(CLI::App& app) {
  auto o = std::make_shared<CompareOptions>();
  auto* cmd = app.add_subcommand("compare", "Compare a calibration.yaml with a simulation's truth.yaml");
  cmd->add_option("--truth", o->truth, "truth.yaml written by rigcal sim")->required();
  cmd->add_option("--result", o->result, "calibration.yaml written by rigcal calibrate")
      ->required();
  cmd->add_option("--initial", o->initial, "The rig file the calibration started from, to show its guess");
  cmd->add_option("--max-cm", o->max_cm, "Fail (exit 1) when a translation error exceeds this")->check(CLI::PositiveNumber);
  cmd->add_option("--max-deg", o->max_deg, "Fail (exit 1) when a rotation error exceeds this")->check(CLI::PositiveNumber);
  cmd->footer(kExitCodesHelp);
  cmd->callback([o] { run(*o); });
}

}  // namespace rigcal::app
