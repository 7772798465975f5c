// `rigcal check-config RIG.yaml`: validates a rig file and prints what it describes.
#include <iomanip>
#include <iostream>

#include "../commands.hpp"
#include "../exit_codes.hpp"
#include "../rig_loading.hpp"
#include "rigcal/config/rig_config.hpp"

namespace rigcal::app {

void addCheckConfigCommand(CLI::App& app) {
  auto* cmd = app.add_subcommand("check-config", "Validate a rig file and print its sensors and roles");
  auto file = std::make_shared<std::string>();
  cmd->add_option("rig", *file, "Rig YAML file")->required();
  cmd->footer(kExitCodesHelp);
  cmd->callback([file] {
    const config::RigConfig rig = loadRig(*file);
    for (const auto& w : rig.warnings) std::cerr << "warning: " << w << '\n';
    std::cout << "rig '" << rig.name << "': " << rig.sensors.size() << " sensors, mapping lidar '"
              << rig.roles.mapping_lidar << "', base frame '" << rig.roles.base_frame << "'\n";
    for (const auto& s : rig.sensors) {
      const XyzRpy v = toXyzRpy(rig.initial_T_base_sensor.at(s.name));
      const bool calibrated = std::find(rig.roles.calibration_lidars.begin(),
                                        rig.roles.calibration_lidars.end(),
                                        s.name) != rig.roles.calibration_lidars.end();
      std::cout << "  " << std::left << std::setw(12) << s.name << std::setw(14) << s.model << "port "
                << std::setw(6) << s.source.port
                << (s.source.topic ? "topic " + *s.source.topic + "  " : std::string())
                << (std::find(rig.extrinsics_from_bag.begin(), rig.extrinsics_from_bag.end(), s.name) !=
                            rig.extrinsics_from_bag.end()
                        ? "(initial extrinsic from_bag)  "
                        : "")
                << (s.name == rig.roles.mapping_lidar ? "mapping    " : calibrated ? "calibration" : "other      ")
                << std::fixed << std::setprecision(3) << "  xyz " << v.x << ' ' << v.y << ' ' << v.z
                << "  rpy " << v.roll << ' ' << v.pitch << ' ' << v.yaw << '\n';
    }
  });
}

}  // namespace rigcal::app
