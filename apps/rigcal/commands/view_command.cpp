// `rigcal view OUT_DIR --view [ADDR:]PORT`: serves a finished `rigcal calibrate --out` folder in the live
// view's page (map.pcd, each lidar's before/after clouds, report.json's summary) until Ctrl-C.
#include <filesystem>
#include <iostream>

#include "../commands.hpp"
#include "../exit_codes.hpp"
#include "../stop_signals.hpp"
#include "../view_option.hpp"
#include "rigcal/view/run_outputs.hpp"

namespace rigcal::app {
namespace {

struct ViewArgs {
  std::string dir;
  std::string spec = "8080";
  double seconds = 0.0;  // 0: until Ctrl-C
};

void run(const ViewArgs& a) {
  std::error_code ec;
  if (!std::filesystem::is_directory(a.dir, ec)) throw CommandFailed(kExitInput, a.dir + ": not a folder");
  StopSignals signals;
  const auto server = startViewServer(a.spec);
  view::RunOutputsSummary summary;
  try {
    summary = view::publishRunOutputs(*server, a.dir);
  } catch (const std::exception& e) {
    throw CommandFailed(kExitInput, e.what());
  }
  std::cout << "serving " << a.dir << ": " << summary.map_points << " map points, " << summary.lidars.size()
            << " lidars (" << summary.cloud_points << " before/after points) at " << server->url() << '\n'
            << std::flush;
  holdView(*server, a.seconds > 0 ? a.seconds : 1e12);
}

}  // namespace

void addViewCommand(CLI::App& app) {
  auto a = std::make_shared<ViewArgs>();
  auto* cmd = app.add_subcommand("view", "Show a finished calibration's outputs in a browser (read-only)");
  cmd->add_option("OUT_DIR", a->dir, "a `rigcal calibrate --out` folder (report.json, map.pcd, <lidar>_before/_after.pcd)")
      ->required();
  cmd->add_option("--view", a->spec, "[ADDR:]PORT to serve at (default 8080 on 127.0.0.1)");
  cmd->add_option("--seconds", a->seconds, "stop after this many seconds (default: until Ctrl-C)")->check(CLI::NonNegativeNumber);
  cmd->footer(kExitCodesHelp);
  cmd->callback([a] { run(*a); });
}

}  // namespace rigcal::app
