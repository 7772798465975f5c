#pragma once
// `--view [ADDR:]PORT` and `--view-hold S` of `rigcal calibrate` / `rigcal map`: the live view of a run
// (view/), wired in a few lines: attach() before the Pipeline is built, follow() once it exists, finish()
// when its input ended, then results() and hold() after the outputs are written.
#include <CLI/CLI.hpp>

#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "rigcal/config/rig_config.hpp"
#include "rigcal/pipeline/pipeline.hpp"
#include "rigcal/view/live_view.hpp"
#include "rigcal/view/view_server.hpp"

namespace rigcal::app {

struct ViewCliOptions {
  std::string spec;     // --view: empty = no view
  double hold_s = 0.0;  // --view-hold: keep serving this long after the run (Ctrl-C ends it)
};

/// Adds --view and --view-hold to `cmd`.
void addViewOptions(CLI::App& cmd, ViewCliOptions& o);

/// Starts the server at the endpoint `spec` names, prints its URL on stderr (and a warning when it is not
/// loopback). CommandFailed(kExitUsage) for a bad spec, one it cannot bind.
std::unique_ptr<view::ViewServer> startViewServer(const std::string& spec);

/// Keeps serving for `seconds` or until Ctrl-C, saying so on stderr.
void holdView(const view::ViewServer& server, double seconds);

/// The live view of one pipeline run; does nothing without --view.
class CommandView {
 public:
  CommandView(const ViewCliOptions& options, const std::string& mode, const config::RigConfig& rig);
  /// Makes the pipeline report to the view (sets options.observer).
  void attach(pipeline::PipelineOptions& options) const;
  /// The counters' source until the returned guard goes (declare it right after the pipeline, so it
  /// goes first on every path).
  [[nodiscard]] std::shared_ptr<void> follow(const pipeline::Pipeline& pipeline);
  /// The input ended: the last updates and the final counters.
  void finish();
  /// A finished calibration's outputs in `out` (before/after clouds, report.json); a failure only warns.
  void results(const std::filesystem::path& out, const std::vector<std::string>& lidars);
  void hold() const;

 private:
  ViewCliOptions options_;
  std::unique_ptr<view::ViewServer> server_;
  std::shared_ptr<view::LiveView> live_;
};

}  // namespace rigcal::app
