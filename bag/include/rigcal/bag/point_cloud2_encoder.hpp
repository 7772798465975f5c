#pragma once
// A Scan serialised as sensor_msgs/PointCloud2 (unorganised: height 1) in the field layouts the common
// ROS drivers publish, so that tests and `rigcal sim` produce the clouds users' bags hold:
//   kVelodyne: x y z intensity f32, ring u16, time f32 s after the stamp          (velodyne_pointcloud, step 32)
//   kOuster:   x y z intensity f32, t u32 ns after the stamp, reflectivity ring ambient u16, range u32 (ouster-ros, 48)
//   kHesai:    x y z intensity f32, timestamp f64 absolute s, ring u16           (hesai ROS driver, step 48)
//   kLivox:    x y z intensity f32, offset_time u32 ns after the stamp           (livox, step 20)
//   kNebula:   x y z f32, intensity u8, return_type u8, channel u16, azimuth elevation distance f32,
//              time_stamp u32 ns after the stamp                                 (Autoware nebula, step 32)
//   kRigcal:   x y z intensity f32, t u32 ns, ring u16, return_type u8: every Scan field exactly (step 24)
// The header stamp is the scan's stamp (its earliest point).
#include <cstdint>
#include <string_view>
#include <vector>

#include "rigcal/core/scan.hpp"

namespace rigcal::bag {

enum class PointCloud2Layout { kVelodyne, kOuster, kHesai, kLivox, kNebula, kRigcal };

/// "velodyne", "ouster", "hesai", "livox", "nebula", "rigcal".
std::string_view pointCloud2LayoutName(PointCloud2Layout layout);

std::vector<std::uint8_t> encodePointCloud2(const Scan& scan, std::string_view frame_id, PointCloud2Layout layout);

}  // namespace rigcal::bag
