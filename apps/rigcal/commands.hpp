#pragma once
// Each subcommand lives in its own commands/<name>_command.cpp and adds itself to the app. A command's
// callback reports failure by throwing CommandFailed with its exit code and one-line message.
#include <CLI/CLI.hpp>

#include <stdexcept>
#include <string>

namespace rigcal::app {

struct CommandFailed : std::runtime_error {
  CommandFailed(int exit_code, const std::string& message)
      : std::runtime_error(message), code(exit_code) {}
  int code;
};

void addCheckConfigCommand(CLI::App& app);
void addDecodeCommand(CLI::App& app);
void addDriverCommand(CLI::App& app);
void addReplayCommand(CLI::App& app);
void addMonitorCommand(CLI::App& app);
void addSimCommand(CLI::App& app);
void addMapCommand(CLI::App& app);
void addCompareCommand(CLI::App& app);
void addCalibratePoseCommand(CLI::App& app);
void addCalibrateCommand(CLI::App& app);
void addInspectCommand(CLI::App& app);
void addRegisterCommand(CLI::App& app);
void addRigFromBagCommand(CLI::App& app);
void addViewCommand(CLI::App& app);

}  // namespace rigcal::app
