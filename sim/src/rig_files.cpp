// rig.yaml (perturbed initial extrinsics) and the vendor calibration/metadata files it names.
#include <fstream>
#include <sstream>
#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "rigcal/sim/outputs.hpp"
#include "rigcal/sim/random.hpp"
#include "rigcal/sim/recording.hpp"
#include "rigcal/core/atomic_file.hpp"
#include "encoders/ouster_identity.hpp"
#include "text_format.hpp"

namespace rigcal::sim {
namespace {

using detail::exact;
using detail::fixed;

/// T moved by exactly `translation` metres and rotated by exactly `angle` radians (right-multiplied:
/// about the frame's own axes), both in seeded random directions.
Pose perturb(const Pose& T, double translation, double angle, Rng& rng) {
  const Eigen::Vector3d dt = rng.unitVector(), axis = rng.unitVector();
  Pose out = T;
  out.translation() += translation * dt;
  out.linear() = T.linear() * expSO3(angle * axis);
  return out;
}

std::string velodyneYaml(const LidarModel& m) {
  std::ostringstream y;
  y << "# " << m.name << " laser angles used by rigcal sim (radians; rot_correction = −azimuth offset).\n";
  y << "lasers:\n";
  for (std::size_t i = 0; i < m.beams.size(); ++i) {
    y << "  - {dist_correction: 0.0, dist_correction_x: 0.0, dist_correction_y: 0.0, focal_distance: 0.0, "
         "focal_slope: 0.0, horiz_offset_correction: 0.0, laser_id: "
      << i << ", rot_correction: " << exact(-deg2rad(m.beams[i].azimuth_offset_deg))
      << ", vert_correction: " << exact(deg2rad(m.beams[i].elevation_deg)) << ", vert_offset_correction: 0.0}\n";
  }
  y << "num_lasers: " << m.beams.size() << "\n";
  y << "distance_resolution: " << exact(m.distance_unit_m) << "\n";
  return y.str();
}

std::string hesaiCsv(const LidarModel& m) {
  std::ostringstream c;
  c << "Channel,Elevation,Azimuth\n";
  for (std::size_t i = 0; i < m.beams.size(); ++i)
    c << i + 1 << ',' << fixed(m.beams[i].elevation_deg, 6) << ',' << fixed(m.beams[i].azimuth_offset_deg, 6) << '\n';
  return c.str();
}

std::string jsonList(const std::vector<double>& v, int decimals) {
  std::string s = "[";
  for (std::size_t i = 0; i < v.size(); ++i) s += (i ? ", " : "") + (decimals < 0 ? exact(v[i]) : fixed(v[i], decimals));
  return s + "]";
}

// sensor_info in the firmware 2.x layout, with what a decoder needs: beam angles, beam origin,
// lidar-to-sensor transform, data format (RNG19 or LEGACY profile, 16 columns per packet), ports.
std::string ousterJson(const SensorSpec& s, const LidarModel& m) {
  std::vector<double> alt, az, shift;
  for (const auto& b : m.beams) {
    alt.push_back(b.elevation_deg);
    az.push_back(b.azimuth_offset_deg);
    shift.push_back(std::round(b.azimuth_offset_deg * m.columns_per_frame / 360.0));
  }
  const double n_mm = m.beam_origin_radius_m * 1000.0;
  const std::string line = m.name == "OS1-128" ? "OS-1-128" : "OS-1-64";
  const char* profile = s.ouster_legacy ? "LEGACY" : "RNG19_RFL8_SIG16_NIR16";
  std::ostringstream j;
  j << "{\n";
  j << "  \"beam_intrinsics\": {\n";
  j << "    \"beam_altitude_angles\": " << jsonList(alt, -1) << ",\n";
  j << "    \"beam_azimuth_angles\": " << jsonList(az, -1) << ",\n";
  j << "    \"beam_to_lidar_transform\": [1, 0, 0, " << exact(n_mm) << ", 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1],\n";
  j << "    \"lidar_origin_to_beam_origin_mm\": " << exact(n_mm) << "\n";
  j << "  },\n";
  j << "  \"calibration_status\": {\"reflectivity\": {\"timestamp\": \"\", \"valid\": false}},\n";
  j << "  \"config_params\": {\n";
  j << "    \"columns_per_packet\": 16,\n";
  j << "    \"lidar_mode\": \"" << m.columns_per_frame << "x" << exact(m.rotation_hz) << "\",\n";
  j << "    \"timestamp_mode\": \"TIME_FROM_PTP_1588\",\n";
  j << "    \"udp_port_imu\": " << s.port + 1 << ",\n";
  j << "    \"udp_port_lidar\": " << s.port << ",\n";
  j << "    \"udp_profile_imu\": \"LEGACY\",\n";
  j << "    \"udp_profile_lidar\": \"" << profile << "\"\n";
  j << "  },\n";
  j << "  \"lidar_data_format\": {\n";
  j << "    \"column_window\": [0, " << m.columns_per_frame - 1 << "],\n";
  j << "    \"columns_per_frame\": " << m.columns_per_frame << ",\n";
  j << "    \"columns_per_packet\": 16,\n";
  j << "    \"pixel_shift_by_row\": " << jsonList(shift, 0) << ",\n";
  j << "    \"pixels_per_column\": " << m.beams.size() << ",\n";
  j << "    \"udp_profile_imu\": \"LEGACY\",\n";
  j << "    \"udp_profile_lidar\": \"" << profile << "\"\n";
  j << "  },\n";
  j << "  \"lidar_intrinsics\": {\n";
  j << "    \"lidar_to_sensor_transform\": [-1, 0, 0, 0, 0, -1, 0, 0, 0, 0, 1, " << fixed(m.beam_origin_z_m * 1000.0, 2)
    << ", 0, 0, 0, 1]\n";
  j << "  },\n";
  j << "  \"sensor_info\": {\n";
  j << "    \"build_rev\": \"v2.5.0\",\n";
  j << "    \"prod_line\": \"" << line << "\",\n";
  const encoders::OusterIdentity id = encoders::ousterIdentity(s.name, s.port);
  j << "    \"initialization_id\": " << id.init_id << ",\n";
  j << "    \"prod_sn\": \"" << id.serial << "\",\n";
  j << "    \"status\": \"RUNNING\"\n";
  j << "  }\n";
  j << "}\n";
  return j.str();
}

}  // namespace

std::map<std::string, Pose> perturbedExtrinsics(const Scenario& sc) {
  Rng rng(hashKeys(sc.seed, 0x7065727475726bULL));  // "perturb"
  const double dt = sc.perturbation.translation_m, da = deg2rad(sc.perturbation.rotation_deg);
  std::map<std::string, Pose> out;
  const Pose& T_bm = sc.sensors[sc.sensorIndex(sc.mapping_lidar)].T_base_sensor;
  const Pose T_bm_init = sc.perturbation.mapping_lidar ? perturb(T_bm, dt, da, rng) : T_bm;
  // Draw in sensor order so a sensor's perturbation does not depend on the role list's order.
  for (const SensorSpec& s : sc.sensors) {
    if (s.name == sc.mapping_lidar) {
      out[s.name] = T_bm_init;
      continue;
    }
    const bool calib = std::find(sc.calibration_lidars.begin(), sc.calibration_lidars.end(), s.name) !=
                       sc.calibration_lidars.end();
    if (calib)
      out[s.name] = T_bm_init * perturb(T_bm.inverse() * s.T_base_sensor, dt, da, rng);
    else
      out[s.name] = perturb(s.T_base_sensor, dt, da, rng);
  }
  return out;
}

std::pair<std::string, std::string> vendorFile(const SensorSpec& s, const LidarModel& m) {
  switch (m.vendor) {
    case LidarVendor::kVelodyne: return {s.name + ".calibration.yaml", velodyneYaml(m)};
    case LidarVendor::kHesai: return {s.name + ".angles.csv", hesaiCsv(m)};
    case LidarVendor::kOuster: return {s.name + ".json", ousterJson(s, m)};
    case LidarVendor::kRobosense: return {};  // its angles come in the DIFOP packets
  }
  return {};
}

std::vector<std::filesystem::path> writeRigFiles(const Simulation& sim, const std::filesystem::path& dir) {
  const Scenario& sc = sim.scenario();
  std::vector<std::filesystem::path> written;
  const auto initial = perturbedExtrinsics(sc);
  std::ostringstream y;
  y << "# Generated by `rigcal sim` (scenario " << sc.name << ", seed " << sc.seed << ").\n";
  y << "# Initial extrinsics are the truth perturbed by " << exact(sc.perturbation.translation_m) << " m and "
    << exact(sc.perturbation.rotation_deg) << " deg in random directions; the truth is in truth.yaml.\n";
  y << "# Live input (--live) receives on 127.0.0.1 (bind), from `rigcal replay recording.pcap --to 127.0.0.1`.\n";
  y << "rig: " << sc.rig_name << "\n";
  y << "sensors:\n";
  for (std::size_t i = 0; i < sc.sensors.size(); ++i) {
    const SensorSpec& s = sc.sensors[i];
    const LidarModel& m = sim.model(i);
    const auto [name, text] = vendorFile(s, m);
    if (!name.empty()) {
      writeFileAtomically(dir / name, text);
      written.push_back(dir / name);
    }
    y << "  - name: " << s.name << "\n";
    y << "    model: " << s.model << "\n";
    y << "    source: {port: " << s.port;
    if (const std::uint16_t info = infoPort(s, m)) y << ", info_port: " << info;
    y << ", address: " << s.address << ", bind: 127.0.0.1}\n";
    if (!name.empty())
      y << "    " << (m.vendor == LidarVendor::kOuster ? "metadata" : "calibration") << ": " << name << "\n";
    y << "    time_source: " << (s.time_source_sensor ? "sensor" : "host") << "\n";
  }
  y << "roles:\n";
  y << "  mapping_lidar: " << sc.mapping_lidar << "\n";
  y << "  calibration_lidars: [";
  for (std::size_t i = 0; i < sc.calibration_lidars.size(); ++i) y << (i ? ", " : "") << sc.calibration_lidars[i];
  y << "]\n";
  y << "  base_frame: " << sc.base_frame << "\n";
  y << "initial_extrinsics:\n";
  for (const SensorSpec& s : sc.sensors) y << "  " << s.name << ": " << detail::xyzRpyFlow(initial.at(s.name)) << "\n";
  if (!sc.rig_parameters.empty()) {
    y << "parameters:\n";
    for (const auto& [key, value] : sc.rig_parameters) y << "  " << key << ": " << value << "\n";
  }
  writeFileAtomically(dir / "rig.yaml", y.str());
  written.push_back(dir / "rig.yaml");
  return written;
}

}  // namespace rigcal::sim
