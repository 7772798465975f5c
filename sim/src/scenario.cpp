#include "rigcal/sim/scenario.hpp"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <set>
#include <sstream>
#include <string_view>

#include "rigcal/sim/lidar_model.hpp"

namespace rigcal::sim {
namespace detail {
const std::vector<std::pair<std::string_view, std::string_view>>& embeddedScenarios();
}

std::size_t Scenario::sensorIndex(const std::string& sensor) const {
  for (std::size_t i = 0; i < sensors.size(); ++i)
    if (sensors[i].name == sensor) return i;
  throw std::out_of_range("scenario '" + name + "' has no sensor '" + sensor + "'");
}

namespace {

// Turns every mistake into a ScenarioError at the offending node.
class Reader {
 public:
  explicit Reader(std::string origin) : origin_(std::move(origin)) {}

  [[noreturn]] void fail(const YAML::Node& n, const std::string& what) const {
    std::ostringstream s;
    s << origin_;
    if (const YAML::Mark m = n.Mark(); !m.is_null()) s << ':' << m.line + 1 << ':' << m.column + 1;
    throw ScenarioError(s.str() + ": " + what);
  }
  void map(const YAML::Node& n, const std::string& what, const std::vector<std::string>& keys) const {
    if (!n.IsMap()) fail(n, what + " must be a mapping");
    for (const auto& kv : n) {
      const std::string key = kv.first.as<std::string>();
      if (std::find(keys.begin(), keys.end(), key) == keys.end()) {
        std::string allowed;
        for (const auto& k : keys) allowed += (allowed.empty() ? "" : ", ") + k;
        fail(kv.first, "unknown key '" + key + "' in " + what + " (allowed: " + allowed + ")");
      }
    }
  }
  YAML::Node need(const YAML::Node& n, const std::string& key, const std::string& what) const {
    const YAML::Node v = n[key];
    if (!v) fail(n, what + " needs '" + key + "'");
    return v;
  }
  double number(const YAML::Node& n, const std::string& key, double lo = -1e300, double hi = 1e300) const {
    double v = 0;
    if (!n.IsScalar() || !YAML::convert<double>::decode(n, v) || !std::isfinite(v))
      fail(n, "'" + key + "' must be a number");
    if (v < lo || v > hi) {
      std::ostringstream s;
      s << "'" << key << "' = " << v << " is out of range [" << lo << ", " << hi << "]";
      fail(n, s.str());
    }
    return v;
  }
  double number(const YAML::Node& parent, const std::string& key, double fallback, double lo, double hi) const {
    return parent[key] ? number(parent[key], key, lo, hi) : fallback;
  }
  std::string text(const YAML::Node& n, const std::string& key) const {
    if (!n.IsScalar()) fail(n, "'" + key + "' must be a string");
    return n.Scalar();
  }
  bool boolean(const YAML::Node& n, const std::string& key) const {
    bool v = false;
    if (!n.IsScalar() || !YAML::convert<bool>::decode(n, v)) fail(n, "'" + key + "' must be true or false");
    return v;
  }
  Eigen::Vector2d vec2(const YAML::Node& n, const std::string& key) const {
    if (!n.IsSequence() || n.size() != 2) fail(n, "'" + key + "' must be a list [x, y]");
    return {number(n[0], key), number(n[1], key)};
  }
  Pose extrinsic(const YAML::Node& n, const std::string& what) const {
    map(n, what, {"x", "y", "z", "roll_deg", "pitch_deg", "yaw_deg"});
    XyzRpy v;
    v.x = number(n, "x", 0, -100, 100);
    v.y = number(n, "y", 0, -100, 100);
    v.z = number(n, "z", 0, -100, 100);
    v.roll = deg2rad(number(n, "roll_deg", 0, -180, 180));
    v.pitch = deg2rad(number(n, "pitch_deg", 0, -90, 90));
    v.yaw = deg2rad(number(n, "yaw_deg", 0, -360, 360));
    return fromXyzRpy(v);
  }

 private:
  std::string origin_;
};

bool validIpv4(const std::string& s) {
  int parts = 0, value = -1;
  for (const char c : s + ".") {
    if (c == '.') {
      if (value < 0 || value > 255) return false;
      ++parts;
      value = -1;
    } else if (c >= '0' && c <= '9') {
      value = (value < 0 ? 0 : value * 10) + (c - '0');
      if (value > 255) return false;
    } else {
      return false;
    }
  }
  return parts == 4;
}

SensorSpec readSensor(const Reader& r, const YAML::Node& n) {
  r.map(n, "a sensor", {"name", "model", "address", "port", "extrinsic", "scan_phase_deg", "clock_offset_ms",
                        "time_source", "outages", "udp_profile"});
  SensorSpec s;
  s.name = r.text(r.need(n, "name", "a sensor"), "name");
  const YAML::Node model = r.need(n, "model", "sensor '" + s.name + "'");
  s.model = r.text(model, "model");
  try {
    (void)lidarModel(s.model);
  } catch (const std::invalid_argument& e) {
    r.fail(model, e.what());
  }
  const YAML::Node address = r.need(n, "address", "sensor '" + s.name + "'");
  s.address = r.text(address, "address");
  if (!validIpv4(s.address)) r.fail(address, "'" + s.address + "' is not an IPv4 address");
  s.port = std::uint16_t(r.number(r.need(n, "port", "sensor '" + s.name + "'"), "port", 1, 65535));
  s.T_base_sensor = r.extrinsic(r.need(n, "extrinsic", "sensor '" + s.name + "'"), "extrinsic of '" + s.name + "'");
  s.scan_phase_deg = r.number(n, "scan_phase_deg", 0.0, 0, 360);
  s.clock_offset_ns = fromSeconds(r.number(n, "clock_offset_ms", 0.0, -1e6, 1e6) * 1e-3);
  if (const YAML::Node ts = n["time_source"]) {
    const std::string v = r.text(ts, "time_source");
    if (v != "sensor" && v != "host") r.fail(ts, "'time_source' must be 'sensor' or 'host'");
    s.time_source_sensor = v == "sensor";
  }
  if (const YAML::Node profile = n["udp_profile"]) {
    const std::string v = r.text(profile, "udp_profile");
    if (lidarModel(s.model).vendor != LidarVendor::kOuster) r.fail(profile, "'udp_profile' is for Ouster sensors only");
    if (v != "RNG19_RFL8_SIG16_NIR16" && v != "LEGACY")
      r.fail(profile, "'udp_profile' must be RNG19_RFL8_SIG16_NIR16 or LEGACY");
    s.ouster_legacy = v == "LEGACY";
  }
  if (const YAML::Node outages = n["outages"]) {
    if (!outages.IsSequence()) r.fail(outages, "'outages' must be a list of {from, to}");
    for (const auto& o : outages) {
      r.map(o, "an outage", {"from", "to"});
      Outage out{r.number(r.need(o, "from", "an outage"), "from", 0, 1e6), r.number(r.need(o, "to", "an outage"), "to", 0, 1e6)};
      if (out.to_s <= out.from_s) r.fail(o, "an outage must end after it starts");
      s.outages.push_back(out);
    }
  }
  return s;
}

TrajectorySpec readTrajectory(const Reader& r, const YAML::Node& n) {
  r.map(n, "trajectory", {"start", "wheelbase_m", "track_m", "excitation", "segments", "base_link", "side_slip_deg_per_g"});
  TrajectorySpec t;
  if (const YAML::Node s = n["start"]) {
    r.map(s, "trajectory start", {"x", "y", "yaw_deg", "speed_kmh"});
    t.start_xy = {r.number(s, "x", 0, -1e4, 1e4), r.number(s, "y", 0, -1e4, 1e4)};
    t.start_yaw_rad = deg2rad(r.number(s, "yaw_deg", 0, -360, 360));
    t.start_speed_mps = r.number(s, "speed_kmh", 0, 0, 200) / 3.6;
  }
  t.wheelbase_m = r.number(n, "wheelbase_m", t.wheelbase_m, 0.5, 10);
  t.track_m = r.number(n, "track_m", t.track_m, 0.5, 5);
  if (const YAML::Node b = n["base_link"]) {
    const std::string where = r.text(b, "base_link");
    if (where != "centre" && where != "rear_axle") r.fail(b, "base_link '" + where + "' is not one of centre, rear_axle");
    t.base_link_on_rear_axle = where == "rear_axle";
  }
  t.side_slip_rad_per_g = deg2rad(r.number(n, "side_slip_deg_per_g", 0, 0, 30));
  if (const YAML::Node e = n["excitation"]) {
    r.map(e, "excitation", {"roll_deg", "pitch_deg", "heave_m", "roll_period_s", "pitch_period_s", "heave_period_s"});
    Excitation& x = t.excitation;
    x.roll_amplitude_rad = deg2rad(r.number(e, "roll_deg", 0, 0, 30));
    x.pitch_amplitude_rad = deg2rad(r.number(e, "pitch_deg", 0, 0, 30));
    x.heave_amplitude_m = r.number(e, "heave_m", 0, 0, 1);
    x.roll_period_s = r.number(e, "roll_period_s", x.roll_period_s, 0.2, 60);
    x.pitch_period_s = r.number(e, "pitch_period_s", x.pitch_period_s, 0.2, 60);
    x.heave_period_s = r.number(e, "heave_period_s", x.heave_period_s, 0.2, 60);
  }
  const YAML::Node segs = r.need(n, "segments", "trajectory");
  if (!segs.IsSequence() || segs.size() == 0) r.fail(segs, "'segments' must be a non-empty list");
  for (const auto& s : segs) {
    r.map(s, "a trajectory segment", {"type", "duration", "to_kmh", "turn_deg"});
    const YAML::Node type = r.need(s, "type", "a trajectory segment");
    const std::string k = r.text(type, "type");
    TrajectorySegment seg;
    using K = TrajectorySegment::Kind;
    if (k == "accelerate" || k == "decelerate") seg.kind = K::kAccelerate;
    else if (k == "cruise") seg.kind = K::kCruise;
    else if (k == "stop") seg.kind = K::kStop;
    else if (k == "turn") seg.kind = K::kTurn;
    else if (k == "jerk") seg.kind = K::kJerk;
    else r.fail(type, "segment type '" + k + "' is not one of accelerate, decelerate, cruise, stop, turn, jerk");
    seg.duration_s = r.number(r.need(s, "duration", "a trajectory segment"), "duration", 1e-3, 3600);
    // Negative: reversing (at most 30 km/h backwards, like a car's reverse gear).
    if (s["to_kmh"]) seg.to_speed_mps = r.number(s["to_kmh"], "to_kmh", -30, 200) / 3.6;
    seg.turn_rad = deg2rad(r.number(s, "turn_deg", 0, -720, 720));
    if ((seg.kind == K::kAccelerate || seg.kind == K::kJerk) && !seg.to_speed_mps)
      r.fail(s, "a '" + k + "' segment needs 'to_kmh'");
    if (seg.kind == K::kTurn && seg.turn_rad == 0) r.fail(s, "a 'turn' segment needs 'turn_deg'");
    t.segments.push_back(seg);
  }
  return t;
}

}  // namespace

Scenario parseScenario(const std::string& text, const std::string& origin) {
  const Reader r(origin);
  YAML::Node root;
  try {
    root = YAML::Load(text);
  } catch (const YAML::Exception& e) {
    throw ScenarioError(origin + ":" + std::to_string(e.mark.line + 1) + ":" + std::to_string(e.mark.column + 1) +
                        ": YAML syntax error: " + e.msg);
  }
  r.map(root, "a scenario", {"scenario", "description", "seed", "start_time", "rig", "pose_sensor", "scene",
                             "trajectory", "noise", "perturbation"});
  Scenario sc;
  sc.name = r.text(r.need(root, "scenario", "a scenario"), "scenario");
  if (root["description"]) sc.description = r.text(root["description"], "description");
  if (root["seed"]) sc.seed = std::uint64_t(r.number(root["seed"], "seed", 0, 9.0e15));
  if (root["start_time"]) sc.start_time_ns = fromSeconds(r.number(root["start_time"], "start_time", 0, 4.0e9));

  const YAML::Node rig = r.need(root, "rig", "a scenario");
  r.map(rig, "rig", {"name", "base_frame", "mapping_lidar", "calibration_lidars", "sensors", "parameters"});
  sc.rig_name = rig["name"] ? r.text(rig["name"], "name") : "sim-" + sc.name;
  if (rig["base_frame"]) sc.base_frame = r.text(rig["base_frame"], "base_frame");
  const YAML::Node sensors = r.need(rig, "sensors", "rig");
  if (!sensors.IsSequence() || sensors.size() == 0) r.fail(sensors, "'sensors' must be a non-empty list");
  std::set<std::string> names;
  std::set<std::pair<std::string, std::uint16_t>> endpoints;
  for (const auto& n : sensors) {
    SensorSpec s = readSensor(r, n);
    if (!names.insert(s.name).second) r.fail(n, "sensor name '" + s.name + "' is used twice");
    if (!endpoints.insert({s.address, s.port}).second)
      r.fail(n, "two sensors send from " + s.address + " to port " + std::to_string(s.port));
    sc.sensors.push_back(std::move(s));
  }
  const YAML::Node mapping = r.need(rig, "mapping_lidar", "rig");
  sc.mapping_lidar = r.text(mapping, "mapping_lidar");
  if (!names.count(sc.mapping_lidar)) r.fail(mapping, "no sensor named '" + sc.mapping_lidar + "'");
  if (const YAML::Node calib = rig["calibration_lidars"]) {
    if (!calib.IsSequence()) r.fail(calib, "'calibration_lidars' must be a list");
    for (const auto& c : calib) {
      const std::string name = r.text(c, "calibration_lidars");
      if (!names.count(name) || name == sc.mapping_lidar) r.fail(c, "'" + name + "' is not a calibration lidar of this rig");
      sc.calibration_lidars.push_back(name);
    }
  }
  if (const YAML::Node params = rig["parameters"]) {
    if (!params.IsMap()) r.fail(params, "'parameters' must be a mapping");
    for (const auto& kv : params) sc.rig_parameters.emplace_back(kv.first.as<std::string>(), r.text(kv.second, kv.first.as<std::string>()));
  }

  if (const YAML::Node p = root["pose_sensor"]) {
    r.map(p, "pose_sensor", {"name", "extrinsic", "rate_hz", "position_noise_m", "rotation_noise_deg",
                             "clock_offset_ms", "origin"});
    PoseSensorSpec ps;
    if (p["name"]) ps.name = r.text(p["name"], "name");
    if (p["extrinsic"]) ps.T_base_pose = r.extrinsic(p["extrinsic"], "extrinsic of the pose sensor");
    ps.rate_hz = r.number(p, "rate_hz", ps.rate_hz, 1, 1000);
    ps.position_noise_m = r.number(p, "position_noise_m", 0, 0, 1);
    ps.rotation_noise_deg = r.number(p, "rotation_noise_deg", 0, 0, 10);
    ps.clock_offset_ns = fromSeconds(r.number(p, "clock_offset_ms", 0.0, -1e6, 1e6) * 1e-3);
    if (const YAML::Node o = p["origin"]) {
      if (!o.IsSequence() || o.size() != 3) r.fail(o, "'origin' must be a list [x, y, z]");
      ps.origin = {r.number(o[0], "origin"), r.number(o[1], "origin"), r.number(o[2], "origin")};
    }
    sc.pose_sensor = ps;
  }

  const YAML::Node scene = r.need(root, "scene", "a scenario");
  r.map(scene, "scene", {"layout", "center", "size", "slope_percent", "bump_amplitude_m", "bump_spacing_m",
                         "clearance_m", "grid_cell_m", "seed"});
  SceneSpec& ss = sc.scene;
  if (scene["layout"]) {
    ss.layout = r.text(scene["layout"], "layout");
    const auto layouts = sceneLayouts();
    if (std::find(layouts.begin(), layouts.end(), ss.layout) == layouts.end())
      r.fail(scene["layout"], "unknown layout '" + ss.layout + "' (parking-lot, street, container-yard, empty, calibration-bay, bay-one-wall)");
  }
  if (scene["center"]) ss.center = r.vec2(scene["center"], "center");
  if (scene["size"]) ss.size = r.vec2(scene["size"], "size");
  ss.slope_percent = r.number(scene, "slope_percent", ss.slope_percent, 0, 15);
  ss.bump_amplitude_m = r.number(scene, "bump_amplitude_m", ss.bump_amplitude_m, 0, 0.5);
  ss.bump_spacing_m = r.number(scene, "bump_spacing_m", ss.bump_spacing_m, 0.5, 100);
  ss.clearance_m = r.number(scene, "clearance_m", ss.clearance_m, 1, 20);
  ss.grid_cell_m = r.number(scene, "grid_cell_m", ss.grid_cell_m, 0.25, 50);
  if (scene["seed"]) ss.seed = std::uint64_t(r.number(scene["seed"], "seed", 0, 9.0e15));

  sc.trajectory = readTrajectory(r, r.need(root, "trajectory", "a scenario"));
  if (const YAML::Node n = root["noise"]) {
    r.map(n, "noise", {"range_sigma_m", "dropout", "intensity_sigma"});
    sc.noise.range_sigma_m = r.number(n, "range_sigma_m", sc.noise.range_sigma_m, 0, 1);
    sc.noise.dropout = r.number(n, "dropout", sc.noise.dropout, 0, 1);
    sc.noise.intensity_sigma = r.number(n, "intensity_sigma", sc.noise.intensity_sigma, 0, 100);
  }
  if (const YAML::Node p = root["perturbation"]) {
    r.map(p, "perturbation", {"translation_m", "rotation_deg", "mapping_lidar"});
    sc.perturbation.translation_m = r.number(p, "translation_m", sc.perturbation.translation_m, 0, 10);
    sc.perturbation.rotation_deg = r.number(p, "rotation_deg", sc.perturbation.rotation_deg, 0, 90);
    if (p["mapping_lidar"]) sc.perturbation.mapping_lidar = r.boolean(p["mapping_lidar"], "mapping_lidar");
  }
  return sc;
}

std::vector<std::string> builtinScenarioNames() {
  std::vector<std::string> names;
  for (const auto& [name, text] : detail::embeddedScenarios()) names.emplace_back(name);
  return names;
}

Scenario loadScenario(const std::string& name_or_file) {
  for (const auto& [name, text] : detail::embeddedScenarios())
    if (name == name_or_file) return parseScenario(std::string(text), "scenario '" + std::string(name) + "'");
  const std::filesystem::path file(name_or_file);
  const bool looks_like_file = name_or_file.find('/') != std::string::npos || file.extension() == ".yaml" ||
                               file.extension() == ".yml";
  if (!looks_like_file || !std::filesystem::is_regular_file(file)) {
    std::string known;
    for (const auto& n : builtinScenarioNames()) known += (known.empty() ? "" : ", ") + n;
    throw ScenarioError("no scenario '" + name_or_file + "': not a preset (" + known + ") nor a readable file");
  }
  std::ifstream in(file);
  if (!in) throw ScenarioError(file.string() + ": cannot read the file");
  std::stringstream buffer;
  buffer << in.rdbuf();
  Scenario sc = parseScenario(buffer.str(), file.string());
  sc.file = file;
  return sc;
}

}  // namespace rigcal::sim
