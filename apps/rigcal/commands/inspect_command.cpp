// `rigcal inspect BAG`: what a ROS 2 bag holds, read in one streaming pass: each topic's type, message
// count, rate and frame id, and the tf tree's edges, so a user can see which topics to calibrate from.
#include "../bag_summary.hpp"
#include "../commands.hpp"
#include "../exit_codes.hpp"
#include "rigcal/bag/bag_error.hpp"

namespace rigcal::app {

namespace {

void run(const std::string& path) {
  BagSummary summary;
  try {
    summary = summarizeBag(path);
  } catch (const bag::BagError& e) {
    throw CommandFailed(kExitInput, e.what());
  }
  printBagSummary(summary);
  if (summary.total == 0) throw CommandFailed(kExitNotEnoughData, path + ": the bag holds no messages");
}

}  // namespace

void addInspectCommand(CLI::App& app) {
  auto path = std::make_shared<std::string>();
  auto* cmd = app.add_subcommand("inspect", "List a ROS 2 bag's topics, types, counts, rates, frame ids and tf edges");
  cmd->add_option("bag", *path, "rosbag2 folder, .mcap or .db3")->required();
  cmd->footer(kExitCodesHelp);
  cmd->callback([path] { run(*path); });
}

}  // namespace rigcal::app
