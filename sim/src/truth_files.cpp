// truth.yaml and poses.csv.
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "rigcal/sim/outputs.hpp"
#include "rigcal/sim/random.hpp"
#include "rigcal/core/atomic_file.hpp"
#include "text_format.hpp"

namespace rigcal::sim {
namespace {

using detail::exact;
using detail::fixed;

// A pose as a YAML flow mapping: x y z roll pitch yaw (m, rad) and the quaternion qw qx qy qz.
std::string poseFlow(const Pose& T) {
  const XyzRpy v = toXyzRpy(T);
  const Eigen::Quaterniond q(T.linear());
  const Eigen::Quaterniond qp = q.w() < 0 ? Eigen::Quaterniond(-q.w(), -q.x(), -q.y(), -q.z()) : q;
  return "{x: " + fixed(v.x, 9) + ", y: " + fixed(v.y, 9) + ", z: " + fixed(v.z, 9) + ", roll: " + fixed(v.roll, 9) +
         ", pitch: " + fixed(v.pitch, 9) + ", yaw: " + fixed(v.yaw, 9) + ", qw: " + fixed(qp.w(), 12) +
         ", qx: " + fixed(qp.x(), 12) + ", qy: " + fixed(qp.y(), 12) + ", qz: " + fixed(qp.z(), 12) + "}";
}

}  // namespace

void writeTruthYaml(const Simulation& sim, const std::filesystem::path& file) {
  const Scenario& sc = sim.scenario();
  std::ostringstream y;
  y << "# Ground truth of a rigcal simulation. Poses are T_to_from (maps points in `from` into `to`):\n"
       "# x y z in metres, roll pitch yaw in radians with R = Rz(yaw)·Ry(pitch)·Rx(roll), and the same\n"
       "# rotation as a unit quaternion qw qx qy qz. Times are nanoseconds since the UNIX epoch.\n"
       "# A sensor's clock reads true time + clock_offset_ns; its rotor azimuth (clockwise from +x,\n"
       "# degrees) is scan_phase_deg at every whole second of its own clock.\n";
  y << "scenario: " << sc.name << "\n";
  y << "seed: " << sc.seed << "\n";
  y << "scene_seed: " << sim.sceneSeed() << "\n";
  y << "start_time_ns: " << sim.startTime() << "\n";
  y << "end_time_ns: " << sim.endTime() << "\n";
  y << "path_length_m: " << fixed(sim.trajectory().length(), 3) << "\n";
  y << "base_frame: " << sc.base_frame << "\n";
  y << "mapping_lidar: " << sc.mapping_lidar << "\n";
  y << "calibration_lidars: [";
  for (std::size_t i = 0; i < sc.calibration_lidars.size(); ++i) y << (i ? ", " : "") << sc.calibration_lidars[i];
  y << "]\n";
  y << "sensors:\n";
  for (std::size_t i = 0; i < sc.sensors.size(); ++i) {
    const SensorSpec& s = sc.sensors[i];
    y << "  " << s.name << ":\n";
    y << "    model: " << s.model << "\n";
    y << "    address: " << s.address << "\n";
    y << "    port: " << s.port << "\n";
    y << "    T_base_sensor: " << poseFlow(s.T_base_sensor) << "\n";
    y << "    clock_offset_ns: " << s.clock_offset_ns << "\n";
    y << "    scan_phase_deg: " << exact(s.scan_phase_deg) << "\n";
    y << "    time_source: " << (s.time_source_sensor ? "sensor" : "host") << "\n";
    if (!s.outages.empty()) {
      y << "    outages_ns:\n";
      for (const Outage& o : s.outages)
        y << "      - [" << sim.startTime() + fromSeconds(o.from_s) << ", " << sim.startTime() + fromSeconds(o.to_s) << "]\n";
    }
  }
  const Pose& T_base_mapping = sc.sensors[sc.sensorIndex(sc.mapping_lidar)].T_base_sensor;
  y << "T_mapping_calib:\n";
  for (const std::string& c : sc.calibration_lidars)
    y << "  " << c << ": " << poseFlow(T_base_mapping.inverse() * sc.sensors[sc.sensorIndex(c)].T_base_sensor) << "\n";
  if (sc.pose_sensor) {
    const PoseSensorSpec& p = *sc.pose_sensor;
    y << "pose_sensor:\n";
    y << "  name: " << p.name << "\n";
    y << "  rate_hz: " << exact(p.rate_hz) << "\n";
    y << "  T_base_pose: " << poseFlow(p.T_base_pose) << "\n";
    y << "  clock_offset_ns: " << p.clock_offset_ns << "\n";
    y << "  origin: [" << fixed(p.origin.x(), 6) << ", " << fixed(p.origin.y(), 6) << ", " << fixed(p.origin.z(), 6) << "]\n";
    y << "  position_noise_m: " << exact(p.position_noise_m) << "\n";
    y << "  rotation_noise_deg: " << exact(p.rotation_noise_deg) << "\n";
    // lidar_align's answer per lidar: the extrinsic between pose sensor and lidar, and the offset
    // "to add to lidar timestamps" to bring them onto the pose sensor's clock.
    y << "  lidars:\n";
    for (const SensorSpec& s : sc.sensors) {
      y << "    " << s.name << ":\n";
      y << "      T_pose_lidar: " << poseFlow(p.T_base_pose.inverse() * s.T_base_sensor) << "\n";
      y << "      time_offset_to_add_to_lidar_s: " << fixed(toSeconds(p.clock_offset_ns - s.clock_offset_ns), 9) << "\n";
    }
  }
  writeFileAtomically(file, y.str());
}

std::vector<PoseSample> poseSamples(const Simulation& sim) {
  const Scenario& sc = sim.scenario();
  const PoseSensorSpec p = sc.pose_sensor.value_or(PoseSensorSpec{"base_link"});
  Rng rng(hashKeys(sc.seed, 0x706f736573ULL));  // "poses"
  std::vector<PoseSample> out;
  const double period_ns = 1e9 / p.rate_hz;
  for (std::int64_t k = 0;; ++k) {
    const TimeNs t = sim.startTime() + TimeNs(double(k) * period_ns + 0.5);
    if (t > sim.endTime()) break;
    Pose T = sim.T_world_base(t) * p.T_base_pose;
    if (p.position_noise_m > 0 || p.rotation_noise_deg > 0) {
      // One draw per statement: the order of function arguments is unspecified (compilers differ).
      const double pz = rng.normal(), py = rng.normal(), px = rng.normal();
      const double rz = rng.normal(), ry = rng.normal(), rx = rng.normal();
      const Eigen::Vector3d dp(px, py, pz), dr(rx, ry, rz);
      T.translation() += p.position_noise_m * dp;
      T.linear() = T.linear() * expSO3(deg2rad(p.rotation_noise_deg) * dr);
    }
    T.translation() += p.origin;
    out.push_back({t + p.clock_offset_ns, T});
  }
  return out;
}

std::string poseFrame(const Simulation& sim) {
  return sim.scenario().pose_sensor ? sim.scenario().pose_sensor->name : std::string("base_link");
}

void writePosesCsv(const Simulation& sim, const std::filesystem::path& file) {
  const Scenario& sc = sim.scenario();
  const PoseSensorSpec p = sc.pose_sensor.value_or(PoseSensorSpec{"base_link"});
  std::ostringstream out;
  out << "# rigcal sim: " << p.name << " in the world frame at " << exact(p.rate_hz)
      << " Hz (lidar_align layout; positions include origin [" << fixed(p.origin.x(), 3) << ", "
      << fixed(p.origin.y(), 3) << ", " << fixed(p.origin.z(), 3) << "])\n";
  out << "# timestamp_ns, index, px, py, pz, qw, qx, qy, qz\n";
  std::int64_t k = 0;
  for (const PoseSample& sample : poseSamples(sim)) {
    const Eigen::Vector3d x = sample.T_world_pose.translation();
    Eigen::Quaterniond q(sample.T_world_pose.linear());
    if (q.w() < 0) q.coeffs() = -q.coeffs();
    out << sample.stamp_ns << ", " << k++ << ", " << fixed(x.x(), 6) << ", " << fixed(x.y(), 6) << ", "
        << fixed(x.z(), 6) << ", " << fixed(q.w(), 9) << ", " << fixed(q.x(), 9) << ", " << fixed(q.y(), 9) << ", "
        << fixed(q.z(), 9) << "\n";
  }
  writeFileAtomically(file, out.str());
}

}  // namespace rigcal::sim
