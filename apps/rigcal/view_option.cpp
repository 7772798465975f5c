#include "view_option.hpp"

#include <chrono>
#include <iostream>
#include <thread>

#include "commands.hpp"
#include "exit_codes.hpp"
#include "stop_signals.hpp"
#include "rigcal/view/run_outputs.hpp"
#include "rigcal/view/view_endpoint.hpp"

namespace rigcal::app {

void addViewOptions(CLI::App& cmd, ViewCliOptions& o) {
  cmd.add_option("--view", o.spec,
                 "serve a live view of the run in a browser at [ADDR:]PORT (default address 127.0.0.1)");
  cmd.add_option("--view-hold", o.hold_s, "with --view: keep serving this many seconds after the run (Ctrl-C ends it)")
      ->check(CLI::NonNegativeNumber);
}

std::unique_ptr<view::ViewServer> startViewServer(const std::string& spec) {
  view::ViewEndpoint endpoint;
  try {
    endpoint = view::parseViewEndpoint(spec);
  } catch (const std::invalid_argument& e) {
    throw CommandFailed(kExitUsage, e.what());
  }
  std::unique_ptr<view::ViewServer> server;
  try {
    server = std::make_unique<view::ViewServer>(endpoint);
  } catch (const std::exception& e) {
    throw CommandFailed(kExitUsage, std::string("--view: ") + e.what());
  }
  if (!endpoint.loopback())
    std::cerr << "warning: the view listens on " << endpoint.address
              << ", reachable from other machines (no authentication; read-only)\n";
  std::cerr << "view: " << server->url() << '\n';
  return server;
}

void holdView(const view::ViewServer& server, double seconds) {
  if (seconds <= 0 || StopSignals::requested()) return;
  std::cerr << "view: serving " << server.url();
  if (seconds < 1e9) std::cerr << " for " << seconds << " s";
  std::cerr << " (Ctrl-C ends it)\n";
  const auto until = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
  while (std::chrono::steady_clock::now() < until && !StopSignals::requested())
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
}

CommandView::CommandView(const ViewCliOptions& options, const std::string& mode, const config::RigConfig& rig)
    : options_(options) {
  if (options_.spec.empty()) return;
  server_ = startViewServer(options_.spec);
  live_ = std::make_shared<view::LiveView>(*server_, mode, rig.roles.calibration_lidars);
}

void CommandView::attach(pipeline::PipelineOptions& options) const { options.observer = live_; }

std::shared_ptr<void> CommandView::follow(const pipeline::Pipeline& pipeline) {
  if (!live_) return nullptr;
  live_->setProgressSource([&pipeline] { return pipeline.progress(); });
  return std::shared_ptr<void>(nullptr, [live = live_](void*) { live->setProgressSource(nullptr); });
}

void CommandView::finish() {
  if (live_) live_->finish();
}

void CommandView::results(const std::filesystem::path& out, const std::vector<std::string>& lidars) {
  if (!server_) return;
  try {
    view::publishRunOutputs(*server_, out, lidars, false);
  } catch (const std::exception& e) {
    std::cerr << "warning: view: " << e.what() << '\n';
  }
}

void CommandView::hold() const {
  if (server_) holdView(*server_, options_.hold_s);
}

}  // namespace rigcal::app
