#include "rigcal/calib/lidar_pose/lidar_pose_output.hpp"

#include <fstream>
#include <iomanip>
#include <sstream>
#include <stdexcept>

#include <Eigen/Geometry>

#include "rigcal/core/ply_io.hpp"
#include "rigcal/core/point_table.hpp"
#include "rigcal/core/atomic_file.hpp"

namespace rigcal::calib {
namespace {

void writeText(const std::filesystem::path& path, const std::string& text) {
  writeFileAtomically(path, [&](std::ostream& out) { out << text; });
}

}  // namespace

std::string lidarPoseCalibrationText(const LidarPoseResult& r, const Eigen::Vector3d& origin) {
  const Pose& T = r.T_pose_lidar;
  const Eigen::Vector3d t = T.translation();
  const Eigen::Vector3d w = logSO3(T.linear());
  const Eigen::Quaterniond q(T.linear());
  std::ostringstream o;
  o << std::setprecision(9);
  // lidar_align's headings, word for word (including its double space), so existing parsers work.
  o << "Active Transformation Vector (x,y,z,rx,ry,rz) from the Pose Sensor Frame to  the Lidar Frame:\n"
    << "[" << t.x() << ", " << t.y() << ", " << t.z() << ", " << w.x() << ", " << w.y() << ", " << w.z()
    << "]\n\n";
  o << "Active Transformation Matrix from the Pose Sensor Frame to  the Lidar Frame:\n"
    << T.matrix() << "\n\n";
  o << "Active Translation Vector (x,y,z) from the Pose Sensor Frame to  the Lidar Frame:\n"
    << "[" << t.x() << ", " << t.y() << ", " << t.z() << "]\n\n";
  o << "Active Hamiltonen Quaternion (w,x,y,z) the Pose Sensor Frame to  the Lidar Frame:\n"
    << "[" << q.w() << ", " << q.x() << ", " << q.y() << ", " << q.z() << "]\n\n";
  o << "Time offset that must be added to lidar timestamps in seconds:\n" << r.time_offset_s << "\n\n";
  o << "ROS Static TF Publisher: <node pkg=\"tf\" type=\"static_transform_publisher\" "
       "name=\"pose_lidar_broadcaster\" args=\""
    << t.x() << " " << t.y() << " " << t.z() << " " << q.x() << " " << q.y() << " " << q.z() << " "
    << q.w() << " POSE_FRAME LIDAR_FRAME 100\" />\n\n";

  // Ours: what lidar_align never said.
  const XyzRpy v = toXyzRpy(T);
  o << "Roll, pitch, yaw (degrees, R = Rz·Ry·Rx):\n[" << rad2deg(v.roll) << ", " << rad2deg(v.pitch)
    << ", " << rad2deg(v.yaw) << "]\n\n";
  o << "Cost (sum of min(d^2, max) in m^2): initial " << r.initial_cost << ", global " << r.global_cost
    << " (" << r.global_evaluations << " evaluations, " << r.global_status << "), final "
    << r.final_cost << " (" << r.local_evaluations << " evaluations, " << r.coarse_evaluations
    << " of them at the global cap: " << r.coarse_status << ", " << r.local_status << ")\n";
  o << std::setprecision(4) << "Time (s): selection " << r.select_seconds << ", global "
    << r.global_seconds << ", local " << r.local_seconds << ", total " << r.total_seconds << "\n";
  const auto& c = r.points.counts;
  o << "Points: " << c.input << " returns in " << c.scans << " scans; " << c.not_sampled
    << " not sampled, " << c.low_intensity << " below min_return_intensity, " << c.out_of_range
    << " out of range or not finite, " << c.outside_poses << " outside the pose time range; "
    << c.kept << " used\n";
  o << std::setprecision(12) << "Pose positions re-centred by subtracting [" << origin.x() << ", "
    << origin.y() << ", " << origin.z() << "]\n\n";
  o << "Observability:\n" << r.observability.text();
  for (std::size_t i = 0; i < kLidarPoseParams; ++i)
    if (r.held[i])
      o << "held at the initial guess: " << lidarPoseParamName(static_cast<LidarPoseParam>(i)) << "\n";
  return o.str();
}

void writeLidarPoseCalibrationText(const std::filesystem::path& path, const LidarPoseResult& result,
                                   const Eigen::Vector3d& origin) {
  writeText(path, lidarPoseCalibrationText(result, origin));
}

void writeLidarPoseCloud(const std::filesystem::path& path, const LidarPoints& points,
                         const PoseTrajectory& trajectory, const Pose& T_pose_lidar, double time_offset_s) {
  std::vector<double> x, y, z, intensity, time;
  x.reserve(points.size());
  y.reserve(points.size());
  z.reserve(points.size());
  intensity.reserve(points.size());
  time.reserve(points.size());
  std::size_t hint = 0;
  for (std::size_t i = 0; i < points.size(); ++i) {
    const auto T_world_pose = trajectory.at(points.time_ns[i], time_offset_s, &hint);
    if (!T_world_pose) continue;
    const Eigen::Vector3d p =
        *T_world_pose * (T_pose_lidar * Eigen::Vector3d(points.x[i], points.y[i], points.z[i]));
    // Stored as the float column it is written as, so the PLY holds exactly these values.
    x.push_back(static_cast<float>(p.x()));
    y.push_back(static_cast<float>(p.y()));
    z.push_back(static_cast<float>(p.z()));
    intensity.push_back(points.intensity[i]);
    time.push_back(toSeconds(points.time_ns[i]) + time_offset_s);
  }
  PointTable table;
  table.add("x", FieldType::kF32, std::move(x));
  table.add("y", FieldType::kF32, std::move(y));
  table.add("z", FieldType::kF32, std::move(z));
  table.add("intensity", FieldType::kF32, std::move(intensity));
  table.add("time", FieldType::kF64, std::move(time));
  writePly(path, table, PlyEncoding::kBinaryLittleEndian);
}

}  // namespace rigcal::calib
