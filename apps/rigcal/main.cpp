// rigcal: one executable, one subcommand per job. The subcommands only wire the libraries.
#include <iostream>

#include "commands.hpp"
#include "exit_codes.hpp"

int main(int argc, char** argv) {
  using namespace rigcal::app;
  CLI::App app{"rigcal: online extrinsic calibration of a vehicle's lidar rig from sensor packets."};
  app.set_version_flag("--version", RIGCAL_VERSION);
  app.require_subcommand(1);
  app.footer(kExitCodesHelp);

  addCheckConfigCommand(app);
  addDecodeCommand(app);
  addDriverCommand(app);
  addReplayCommand(app);
  addMonitorCommand(app);
  addSimCommand(app);
  addMapCommand(app);
  addCompareCommand(app);
  addCalibratePoseCommand(app);
  addCalibrateCommand(app);
  addInspectCommand(app);
  addRegisterCommand(app);
  addRigFromBagCommand(app);
  addViewCommand(app);

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int rc = app.exit(e);
    return rc == 0 ? kExitOk : kExitUsage;
  } catch (const CommandFailed& e) {
    std::cerr << "rigcal: " << e.what() << '\n';
    return e.code;
  } catch (const std::exception& e) {
    std::cerr << "rigcal: " << e.what() << '\n';
    return kExitFailure;
  }
  return kExitOk;
}
