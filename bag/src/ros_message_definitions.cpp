#include "rigcal/bag/ros_message_definitions.hpp"

#include <map>
#include <stdexcept>
#include <utility>
#include <vector>

namespace rigcal::bag {

namespace {

// Definitions as in the message packages (comments left out), keyed by the name dependencies use.
const std::map<std::string_view, std::string_view>& definitions() {
  static const std::map<std::string_view, std::string_view> kDefinitions = {
      {"builtin_interfaces/Time", "int32 sec\nuint32 nanosec\n"},
      {"std_msgs/Header", "builtin_interfaces/Time stamp\nstring frame_id\n"},
      {"velodyne_msgs/VelodyneScan", "std_msgs/Header header\nVelodynePacket[] packets\n"},
      {"velodyne_msgs/VelodynePacket", "builtin_interfaces/Time stamp\nuint8[1206] data\n"},
      {"pandar_msgs/PandarScan", "std_msgs/Header header\nPandarPacket[] packets\n"},
      {"pandar_msgs/PandarPacket", "builtin_interfaces/Time stamp\nuint8[1500] data\nuint32 size\n"},
      {"robosense_msgs/RobosenseScan", "std_msgs/Header header\nRobosensePacket[] packets\n"},
      {"robosense_msgs/RobosensePacket",
       "builtin_interfaces/Time stamp\nuint8 is_difop\nuint8[1500] data\nuint32 size\n"},
      {"nebula_msgs/NebulaPackets", "std_msgs/Header header\nNebulaPacket[] packets\n"},
      {"nebula_msgs/NebulaPacket", "builtin_interfaces/Time stamp\nuint8[] data\n"},
      {"ouster_sensor_msgs/PacketMsg", "uint8[] buf\n"},
      {"sensor_msgs/PointCloud2",
       "std_msgs/Header header\nuint32 height\nuint32 width\nPointField[] fields\nbool is_bigendian\n"
       "uint32 point_step\nuint32 row_step\nuint8[] data\nbool is_dense\n"},
      {"sensor_msgs/PointField",
       "uint8 INT8    = 1\nuint8 UINT8   = 2\nuint8 INT16   = 3\nuint8 UINT16  = 4\nuint8 INT32   = 5\n"
       "uint8 UINT32  = 6\nuint8 FLOAT32 = 7\nuint8 FLOAT64 = 8\n"
       "string name\nuint32 offset\nuint8 datatype\nuint32 count\n"},
      {"tf2_msgs/TFMessage", "geometry_msgs/TransformStamped[] transforms\n"},
      {"geometry_msgs/TransformStamped", "std_msgs/Header header\nstring child_frame_id\nTransform transform\n"},
      {"geometry_msgs/Transform", "Vector3 translation\nQuaternion rotation\n"},
      {"geometry_msgs/Vector3", "float64 x\nfloat64 y\nfloat64 z\n"},
      {"geometry_msgs/Quaternion", "float64 x 0\nfloat64 y 0\nfloat64 z 0\nfloat64 w 1\n"},
      {"geometry_msgs/Point", "float64 x\nfloat64 y\nfloat64 z\n"},
      {"geometry_msgs/Pose", "Point position\nQuaternion orientation\n"},
      {"geometry_msgs/PoseWithCovariance", "Pose pose\nfloat64[36] covariance\n"},
      {"geometry_msgs/Twist", "Vector3 linear\nVector3 angular\n"},
      {"geometry_msgs/TwistWithCovariance", "Twist twist\nfloat64[36] covariance\n"},
      {"nav_msgs/Odometry",
       "std_msgs/Header header\nstring child_frame_id\ngeometry_msgs/PoseWithCovariance pose\n"
       "geometry_msgs/TwistWithCovariance twist\n"},
  };
  return kDefinitions;
}

// Each type's dependencies, in the order rosbag2 appends them (depth first).
const std::map<std::string_view, std::vector<std::string_view>>& dependencies() {
  static const std::map<std::string_view, std::vector<std::string_view>> kDependencies = {
      {"velodyne_msgs/VelodyneScan", {"std_msgs/Header", "builtin_interfaces/Time", "velodyne_msgs/VelodynePacket"}},
      {"pandar_msgs/PandarScan", {"std_msgs/Header", "builtin_interfaces/Time", "pandar_msgs/PandarPacket"}},
      {"robosense_msgs/RobosenseScan",
       {"std_msgs/Header", "builtin_interfaces/Time", "robosense_msgs/RobosensePacket"}},
      {"nebula_msgs/NebulaPackets", {"std_msgs/Header", "builtin_interfaces/Time", "nebula_msgs/NebulaPacket"}},
      {"ouster_sensor_msgs/PacketMsg", {}},
      {"sensor_msgs/PointCloud2", {"std_msgs/Header", "builtin_interfaces/Time", "sensor_msgs/PointField"}},
      {"tf2_msgs/TFMessage",
       {"geometry_msgs/TransformStamped", "std_msgs/Header", "builtin_interfaces/Time", "geometry_msgs/Transform",
        "geometry_msgs/Vector3", "geometry_msgs/Quaternion"}},
      {"nav_msgs/Odometry",
       {"std_msgs/Header", "builtin_interfaces/Time", "geometry_msgs/PoseWithCovariance", "geometry_msgs/Pose",
        "geometry_msgs/Point", "geometry_msgs/Quaternion", "geometry_msgs/TwistWithCovariance",
        "geometry_msgs/Twist", "geometry_msgs/Vector3"}},
  };
  return kDependencies;
}

}  // namespace

std::string rosMessageDefinition(std::string_view type) {
  // "pkg/msg/Type" -> "pkg/Type", the form dependency headers use.
  std::string key(type);
  if (const auto at = key.find("/msg/"); at != std::string::npos) key.erase(at, 4);
  const auto deps = dependencies().find(key);
  if (deps == dependencies().end())
    throw std::invalid_argument("no message definition for " + std::string(type));
  std::string text(definitions().at(deps->first));
  for (const auto dep : deps->second) {
    text += std::string(80, '=') + "\nMSG: " + std::string(dep) + "\n";
    text += definitions().at(dep);
  }
  return text;
}

}  // namespace rigcal::bag
