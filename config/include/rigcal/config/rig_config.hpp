#pragma once
// One YAML file per rig: its sensors and where their packets come from, the roles of each sensor,
// the initial extrinsics, and the calibration parameters. See config/rigs/ for examples.
#include <cstdint>
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "rigcal/config/config_error.hpp"
#include "rigcal/config/parameters.hpp"
#include "rigcal/config/vehicle_footprint.hpp"
#include "rigcal/core/pose.hpp"
#include "rigcal/core/time.hpp"

namespace rigcal::config {

/// Bounds on what a rig file may ask for (a mistake or a hostile file fails at once, clearly).
inline constexpr std::uintmax_t kMaxRigFileBytes = 1 << 20;          // a real rig file is a few kB
inline constexpr std::size_t kMaxSensors = 64;
inline constexpr std::size_t kMaxSensorNameLength = 64;             // names are [A-Za-z0-9_.-]+
inline constexpr std::uintmax_t kMaxReferencedFileBytes = 16 << 20;  // calibration / metadata files
inline constexpr const char* kExtrinsicsFromBag = "from_bag";       // initial_extrinsics from the bag's tf

/// Where a sensor's packets come from: a live UDP port, or the same port/address filter in a pcap; or
/// a ROS 2 bag topic (packets or sensor_msgs/PointCloud2) when reading a bag.
struct SensorSource {
  std::uint16_t port = 0;                      // 0: none (a bag-topic-only sensor)
  std::optional<std::string> topic;            // bag input: the sensor's topic
  std::optional<std::string> frame;            // bag input: its tf frame (default: its messages' frame_id)
  std::optional<std::string> address;          // the sensor's IPv4 address (source filter)
  std::optional<std::string> multicast_group;  // live only: join this group
  /// Live only: the local IPv4 address to receive on (default any, 0.0.0.0). A loopback address
  /// (127.0.0.0/8) receives from this host alone, e.g. `rigcal replay --to 127.0.0.1`: the `address`
  /// filter is then not applied (replayed datagrams come from 127.0.0.1, not from the sensor).
  std::optional<std::string> bind;
  [[nodiscard]] bool bindsLoopback() const { return bind && bind->rfind("127.", 0) == 0; }
  std::optional<std::uint16_t> info_port = std::nullopt;  // a second port of the sensor: RoboSense DIFOP (7788)
};

struct SensorConfig {
  std::string name;
  std::string model;                  // validated by the drivers when the decoder is built
  SensorSource source;
  std::filesystem::path calibration;  // absolute, or empty
  std::filesystem::path metadata;     // absolute, or empty
  TimeSource time_source = TimeSource::kSensorClock;
  double cut_angle_deg = 0.0;
  /// How far this sensor's clock runs ahead of the rig's (the mapping lidar's): its scan stamps are
  /// corrected by subtracting it. `time_offset_ns: estimate` measures it before a pcap run
  /// (estimate_time_offset; see pipeline/clock_offset_estimate.hpp).
  TimeNs time_offset_ns = 0;
  bool estimate_time_offset = false;
  SourceLocation where;               // the sensor's entry, for later error messages
};

struct Roles {
  std::string mapping_lidar;
  std::vector<std::string> calibration_lidars;
  std::string base_frame = "base_link";
};

struct RigConfig {
  std::filesystem::path file;
  std::string name;
  std::vector<SensorConfig> sensors;
  Roles roles;
  std::map<std::string, Pose> initial_T_base_sensor;  // every sensor has one
  /// Sensors whose initial extrinsic is `from_bag`: the bag's tf tree replaces their identity placeholder
  /// when a command reads a bag (ExtrinsicsFromBag in apps/rigcal).
  std::vector<std::string> extrinsics_from_bag;
  VehicleFootprint vehicle;                           // `vehicle:`, else the default outline
  Parameters parameters;                              // crop box: from `vehicle`, unless set by name
  std::vector<std::string> warnings;                  // accepted but noteworthy (ignored upstream keys)

  [[nodiscard]] const SensorConfig& sensor(const std::string& name) const;
};

/// Reads and validates a rig file. Relative calibration/metadata paths are resolved against the rig
/// file's folder. Throws ConfigError (file:line:column, one line) on the first mistake.
RigConfig loadRigConfig(const std::filesystem::path& file);

}  // namespace rigcal::config
