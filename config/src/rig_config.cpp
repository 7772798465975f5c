#include "rigcal/config/rig_config.hpp"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <set>
#include <sstream>
#include <utility>

#include "parameter_table.hpp"
#include "yaml_node_reader.hpp"

namespace rigcal::config {

const SensorConfig& RigConfig::sensor(const std::string& name) const {
  for (const auto& s : sensors)
    if (s.name == name) return s;
  throw ConfigError({file}, "no sensor named '" + name + "'");
}

namespace {

SensorConfig readSensor(const YamlNodeReader& r, const YAML::Node& n) {
  r.requireMap(n, "a sensor");
  r.checkKeys(n, {"name", "model", "source", "calibration", "metadata", "time_source", "cut_angle",
                  "time_offset_ns"},
              "sensor");
  SensorConfig s;
  s.where = r.at(n);
  const YAML::Node name = r.required(n, "name", "a sensor");
  s.name = r.text(name, "name");
  // The name becomes output file names (<name>_after.pcd) and ring names: no path, no surprises.
  const bool plain = !s.name.empty() && s.name.size() <= kMaxSensorNameLength && s.name != "." && s.name != ".." &&
                     std::all_of(s.name.begin(), s.name.end(), [](char c) {
                       return std::isalnum(static_cast<unsigned char>(c)) != 0 || c == '_' || c == '.' || c == '-';
                     });
  if (!plain)
    r.fail(name, "sensor name '" + s.name + "' is not allowed; use 1 to " + std::to_string(kMaxSensorNameLength) +
                     " letters, digits, '_', '.', '-' (not '.' or '..')");
  s.model = r.text(r.required(n, "model", "sensor '" + s.name + "'"), "model");

  const YAML::Node src = r.required(n, "source", "sensor '" + s.name + "'");
  r.requireMap(src, "source");
  r.checkKeys(src, {"port", "address", "multicast_group", "bind", "info_port", "topic", "frame"},
              "source of sensor '" + s.name + "'");
  if (src["topic"]) s.source.topic = r.text(src["topic"], "topic");
  if (src["frame"]) s.source.frame = r.text(src["frame"], "frame");
  // A bag topic alone is a complete source (bag input only); otherwise the UDP port is required.
  if (!s.source.topic || src["port"]) {
    const YAML::Node port = r.required(src, "port", "source of sensor '" + s.name + "' (or a bag 'topic')");
    const long long p = r.integer(port, "port");
    r.inRange(port, "port", double(p), 1, 65535);
    s.source.port = std::uint16_t(p);
  }
  if (src["address"]) s.source.address = r.ipv4(src["address"], "address");
  if (src["multicast_group"]) s.source.multicast_group = r.ipv4(src["multicast_group"], "multicast_group", true);
  if (src["bind"]) s.source.bind = r.ipv4(src["bind"], "bind");
  if (const YAML::Node info = src["info_port"]) {
    const long long ip = r.integer(info, "info_port");
    r.inRange(info, "info_port", double(ip), 1, 65535);
    s.source.info_port = std::uint16_t(ip);
  }

  if (n["calibration"]) s.calibration = r.existingFile(n["calibration"], "calibration");
  if (n["metadata"]) s.metadata = r.existingFile(n["metadata"], "metadata");
  if (const YAML::Node ts = n["time_source"]) {
    const std::string v = r.text(ts, "time_source");
    if (v == "sensor")
      s.time_source = TimeSource::kSensorClock;
    else if (v == "host")
      s.time_source = TimeSource::kHostReceive;
    else
      r.fail(ts, "'time_source' must be 'sensor' or 'host', got '" + v + "'");
  }
  if (const YAML::Node c = n["cut_angle"]) {
    s.cut_angle_deg = r.number(c, "cut_angle");
    r.inRange(c, "cut_angle", s.cut_angle_deg, 0, 360);
  }
  if (const YAML::Node t = n["time_offset_ns"]) {
    // A clock more than a minute off is not a residual offset but an unsynchronised sensor.
    constexpr long long kMaxOffsetNs = 60'000'000'000LL;
    if (t.IsScalar() && t.Scalar() == "estimate") {
      s.estimate_time_offset = true;
    } else {
      long long v = 0;
      if (!t.IsScalar() || !YAML::convert<long long>::decode(t, v))
        r.fail(t, "'time_offset_ns' must be an integer (nanoseconds) or 'estimate'");
      r.inRange(t, "time_offset_ns", double(v), double(-kMaxOffsetNs), double(kMaxOffsetNs));
      s.time_offset_ns = v;
    }
  }
  return s;
}

Pose readExtrinsic(const YamlNodeReader& r, const YAML::Node& n, const std::string& sensor) {
  r.requireMap(n, "the initial extrinsic of '" + sensor + "'");
  const std::vector<std::string> keys = {"x", "y", "z", "roll", "pitch", "yaw"};
  r.checkKeys(n, keys, "initial_extrinsics of '" + sensor + "'");
  double v[6] = {};
  for (std::size_t i = 0; i < keys.size(); ++i)
    if (n[keys[i]]) v[i] = r.number(n[keys[i]], keys[i]);
  for (int i = 3; i < 6; ++i)
    if (std::abs(v[i]) > 2 * M_PI)
      r.fail(n[keys[std::size_t(i)]], "'" + keys[std::size_t(i)] + "' is in radians; allowed [-2π, 2π]");
  return fromXyzRpy({v[0], v[1], v[2], v[3], v[4], v[5]});
}

VehicleFootprint readVehicle(const YamlNodeReader& r, const YAML::Node& n) {
  r.requireMap(n, "vehicle");
  r.checkKeys(n, {"length", "width", "rear_overhang"}, "vehicle");
  VehicleFootprint f;
  const auto positive = [&](const char* key, double& value, double max) {
    if (!n[key]) return;
    value = r.number(n[key], key);
    r.inRange(n[key], key, value, 0.1, max);
  };
  positive("length", f.length, 100.0);
  positive("width", f.width, 20.0);
  if (n["rear_overhang"]) {
    f.rear_overhang = r.number(n["rear_overhang"], "rear_overhang");
    r.inRange(n["rear_overhang"], "rear_overhang", f.rear_overhang, -100.0, 100.0);
  }
  if (f.rear_overhang >= f.length) {
    std::ostringstream msg;
    msg << "vehicle: rear_overhang (" << f.rear_overhang << " m) must be less than length (" << f.length
        << " m): base_link would lie ahead of the front bumper";
    r.fail(n, msg.str());
  }
  return f;
}

void readParameters(const YamlNodeReader& r, const YAML::Node& n, Parameters& params,
                    std::vector<std::string>& warnings) {
  r.requireMap(n, "parameters");
  const auto& specs = detail::parameterSpecs();
  const auto& ignored = detail::ignoredUpstreamParameters();
  std::vector<std::string> names;
  for (const auto& s : specs) names.push_back(s.name);

  for (const auto& kv : n) {
    const std::string key = kv.first.as<std::string>();
    const auto spec = std::find_if(specs.begin(), specs.end(), [&](const auto& s) { return key == s.name; });
    if (spec == specs.end()) {
      if (std::find(ignored.begin(), ignored.end(), key) != ignored.end()) {
        warnings.push_back(r.at(kv.first).str() + ": upstream parameter '" + key +
                           "' is not used by rigcal; ignored");
        continue;
      }
      std::string msg = "unknown parameter '" + key + "'";
      if (const std::string near = closestName(key, names); !near.empty())
        msg += " (did you mean '" + near + "'?)";
      r.fail(kv.first, msg);
    }
    const YAML::Node& value = kv.second;
    std::visit(
        [&](auto member) {
          using T = std::remove_reference_t<decltype(params.*member)>;
          if constexpr (std::is_same_v<T, double>) {
            const double v = r.number(value, key);
            r.inRange(value, key, v, spec->min, spec->max);
            params.*member = v;
          } else if constexpr (std::is_same_v<T, int>) {
            const long long v = r.integer(value, key);
            r.inRange(value, key, double(v), spec->min, spec->max);
            params.*member = int(v);
          } else if constexpr (std::is_same_v<T, bool>) {
            params.*member = r.boolean(value, key);
          } else {
            const std::string v = r.text(value, key);
            if (std::find(spec->choices.begin(), spec->choices.end(), v) == spec->choices.end()) {
              std::string allowed;
              for (const auto& c : spec->choices) allowed += (allowed.empty() ? "" : ", ") + c;
              r.fail(value, "'" + key + "' = '" + v + "' is not allowed; allowed: " + allowed);
            }
            params.*member = v;
          }
        },
        spec->member);
  }
}

/// Two sensors on one port must be told apart by their source addresses: otherwise one driver would
/// take both streams (and calibrate a mixture).
void checkDistinctSources(const YamlNodeReader& r, const YAML::Node& nodes, const std::vector<SensorConfig>& sensors) {
  for (std::size_t j = 0; j < sensors.size(); ++j)
    for (std::size_t i = 0; i < j; ++i) {
      const SensorSource &a = sensors[i].source, &b = sensors[j].source;
      if (a.port == 0 || b.port == 0) continue;  // bag-topic-only sensors: no port to share
      // On a loopback bind the address filter is off: then only the port tells sensors apart.
      const bool filtered = !a.bindsLoopback() && !b.bindsLoopback();
      if (a.port != b.port || (filtered && a.address && b.address && *a.address != *b.address)) continue;
      r.fail(nodes[j], "sensors '" + sensors[i].name + "' and '" + sensors[j].name + "' both receive on port " +
                           std::to_string(a.port) +
                           (!filtered ? std::string(" on a loopback bind (no address filter)")
                            : a.address && b.address ? " from the same address " + *a.address
                                                     : std::string(" without distinct source addresses")) +
                           ": give each its own port or its own 'address'");
    }
}

void checkConsistency(const YamlNodeReader& r, const YAML::Node& root, const RigConfig& rig) {
  const Parameters& p = rig.parameters;
  const YAML::Node params = root["parameters"] ? root["parameters"] : root;
  if (p.mapping_min_range >= p.mapping_max_range)
    r.fail(params, "mapping_min_range must be below mapping_max_range");
  if (p.min_calibration_range >= p.max_calibration_range)
    r.fail(params, "min_calibration_range must be below max_calibration_range");
  if (p.lidar_calibration_min_frames > p.lidar_calibration_max_frames)
    r.fail(params, "lidar_calibration_min_frames must not exceed lidar_calibration_max_frames");
  const std::pair<double, double> crop[] = {{p.base_lidar_crop_box_min_x, p.base_lidar_crop_box_max_x},
                                            {p.base_lidar_crop_box_min_y, p.base_lidar_crop_box_max_y},
                                            {p.base_lidar_crop_box_min_z, p.base_lidar_crop_box_max_z}};
  for (int axis = 0; axis < 3; ++axis)
    if (crop[axis].first >= crop[axis].second) {
      const char name = "xyz"[axis];
      std::ostringstream msg;
      msg << "base_lidar_crop_box_min_" << name << " (" << crop[axis].first << ") must be below base_lidar_crop_box_max_"
          << name << " (" << crop[axis].second << ")" << (root["vehicle"] ? " (the vehicle footprint sets the bounds not named)" : "");
      r.fail(params, msg.str());
    }
}

}  // namespace

namespace {

RigConfig loadRigConfigUnchecked(const std::filesystem::path& file) {
  if (!std::filesystem::is_regular_file(file)) throw ConfigError({file}, "rig file not found");
  // Checked before parsing: a huge file would take gigabytes and a minute before any other error.
  std::error_code ec;
  if (const auto size = std::filesystem::file_size(file, ec); !ec && size > kMaxRigFileBytes)
    throw ConfigError({file}, "rig file is " + std::to_string(size) + " bytes; the limit is " +
                                  std::to_string(kMaxRigFileBytes));
  const YamlNodeReader r(file);
  YAML::Node root;
  try {
    root = YAML::LoadFile(file.string());
  } catch (const YAML::Exception& e) {
    throw ConfigError({file, e.mark.line + 1, e.mark.column + 1}, "YAML syntax error: " + e.msg);
  }
  r.requireMap(root, "a rig file");
  r.checkDuplicateKeys(root);
  r.checkKeys(root, {"rig", "sensors", "roles", "initial_extrinsics", "vehicle", "parameters"}, "the rig file");

  RigConfig rig;
  rig.file = file;
  if (root["rig"]) rig.name = r.text(root["rig"], "rig");

  const YAML::Node sensors = r.required(root, "sensors", "the rig file");
  if (!sensors.IsSequence() || sensors.size() == 0) r.fail(sensors, "'sensors' must be a non-empty list");
  if (sensors.size() > kMaxSensors)
    r.fail(sensors, "'sensors' lists " + std::to_string(sensors.size()) + " sensors; the limit is " +
                        std::to_string(kMaxSensors));
  std::set<std::string> names;
  for (const auto& n : sensors) {
    SensorConfig s = readSensor(r, n);
    if (!names.insert(s.name).second) r.fail(n, "sensor name '" + s.name + "' is used twice");
    rig.sensors.push_back(std::move(s));
  }
  checkDistinctSources(r, sensors, rig.sensors);
  const std::vector<std::string> sensor_names(names.begin(), names.end());
  const auto requireSensor = [&](const YAML::Node& n, const std::string& name) {
    if (names.count(name)) return;
    std::string msg = "no sensor named '" + name + "'";
    if (const std::string near = closestName(name, sensor_names); !near.empty())
      msg += " (did you mean '" + near + "'?)";
    r.fail(n, msg);
  };

  const YAML::Node roles = r.required(root, "roles", "the rig file");
  r.requireMap(roles, "roles");
  r.checkKeys(roles, {"mapping_lidar", "calibration_lidars", "base_frame"}, "roles");
  const YAML::Node mapping = r.required(roles, "mapping_lidar", "roles");
  rig.roles.mapping_lidar = r.text(mapping, "mapping_lidar");
  requireSensor(mapping, rig.roles.mapping_lidar);
  if (const YAML::Node calib = roles["calibration_lidars"]) {
    if (!calib.IsSequence()) r.fail(calib, "'calibration_lidars' must be a list of sensor names");
    for (const auto& c : calib) {
      const std::string name = r.text(c, "calibration_lidars");
      requireSensor(c, name);
      if (name == rig.roles.mapping_lidar) r.fail(c, "'" + name + "' is the mapping lidar; it cannot also be calibrated against itself");
      rig.roles.calibration_lidars.push_back(name);
    }
  }
  if (roles["base_frame"]) rig.roles.base_frame = r.text(roles["base_frame"], "base_frame");

  for (const auto& s : rig.sensors) rig.initial_T_base_sensor[s.name] = Pose::Identity();
  if (const YAML::Node ex = root["initial_extrinsics"]) {
    // `from_bag`: every sensor's from the bag's tf tree; per sensor, `name: from_bag` likewise.
    if (ex.IsScalar()) {
      if (ex.Scalar() != kExtrinsicsFromBag)
        r.fail(ex, "'initial_extrinsics' must be a mapping of sensor names or '" + std::string(kExtrinsicsFromBag) +
                       "', got '" + ex.Scalar() + "'");
      for (const auto& s : rig.sensors) rig.extrinsics_from_bag.push_back(s.name);
    } else {
      r.requireMap(ex, "initial_extrinsics");
      for (const auto& kv : ex) {
        const std::string name = kv.first.as<std::string>();
        requireSensor(kv.first, name);
        if (kv.second.IsScalar() && kv.second.Scalar() == kExtrinsicsFromBag)
          rig.extrinsics_from_bag.push_back(name);
        else
          rig.initial_T_base_sensor[name] = readExtrinsic(r, kv.second, name);
      }
    }
  }

  // The footprint first: a base_lidar_crop_box_* parameter named in the file then overrides its bound.
  if (const YAML::Node vehicle = root["vehicle"]) rig.vehicle = readVehicle(r, vehicle);
  setCropBoxFromFootprint(rig.vehicle, rig.parameters);
  if (const YAML::Node params = root["parameters"]) readParameters(r, params, rig.parameters, rig.warnings);
  checkConsistency(r, root, rig);
  return rig;
}

}  // namespace

RigConfig loadRigConfig(const std::filesystem::path& file) {
  try {
    return loadRigConfigUnchecked(file);
  } catch (const YAML::Exception& e) {
    // A node of the wrong kind where a plain value is read (e.g. a complex mapping key `? [a]`).
    throw ConfigError({file, e.mark.line + 1, e.mark.column + 1},
                      "expected a plain value here (" + e.msg + ")");
  }
}

}  // namespace rigcal::config
