#pragma once
// The calibration parameters, named as in the upstream mapping_based_calibrator so its users feel at
// home; defaults are the upstream code defaults (see ../shared/reference/upstream-notes.md).
#include <string>

namespace rigcal::config {

struct Parameters {
  // Mapping (mapping lidar)
  std::string mapping_registrator = "gicp";  // "gicp" | "ndt"
  int mapping_max_frames = 500;
  int local_map_num_keyframes = 15;
  int dense_pointcloud_num_keyframes = 10;
  double mapping_min_range = 0.5;
  double mapping_max_range = 60.0;
  int min_mapping_pointcloud_size = 10000;
  int min_calibration_pointcloud_size = 500;
  double mapping_lost_timeout = 1.0;
  double mapper_resolution = 5.0;
  double mapper_step_size = 0.1;
  int mapper_max_iterations = 35;
  int mapper_num_threads = 2;  // upstream 8; a 2-core target is the norm here
  double mapper_max_correspondence_distance = 0.1;
  double leaf_size_input = 0.1;
  double leaf_size_local_map = 0.1;
  double leaf_size_dense_map = 0.05;
  double new_keyframe_min_distance = 1.0;
  double new_frame_min_distance = 0.05;
  double frame_stopped_distance = 0.02;
  int frames_since_stopped_force_frame = 5;
  int calibration_skip_keyframes = 5;

  // Calibration criteria: standard and straight sets
  double max_allowed_interpolated_time = 0.05;
  double max_allowed_interpolated_distance = 0.05;
  double max_allowed_interpolated_angle = 1.0;
  double max_allowed_interpolated_speed = 3.0;
  double max_allowed_interpolated_accel = 0.4;
  double max_allowed_interpolated_distance_straight = 0.08;
  double max_allowed_interpolated_angle_straight = 0.5;
  double max_allowed_interpolated_speed_straight = 5.0;
  double max_allowed_interpolated_accel_straight = 0.1;
  double lost_frame_max_angle_diff = 25.0;
  double lost_frame_interpolation_error = 0.05;
  double lost_frame_max_acceleration = 8.0;
  bool crop_z_calibration_pointclouds = true;
  double crop_z_calibration_pointclouds_value = 2.0;
  bool calibration_use_only_stopped = false;
  double max_calibration_range = 80.0;
  double min_calibration_range = 1.5;
  double calibration_min_pca_eigenvalue = 0.25;
  double calibration_min_distance_between_frames = 5.0;
  // rigcal: the order in which calibration frames are chosen (and prepared under the deadline). "information":
  // greedily, each next frame the one that most raises the weakest direction of the point-to-plane information
  // of the frames chosen so far (frame_information.hpp); "pca": by pcaInformation() alone (upstream's).
  std::string calibration_frame_ranking = "information";
  double calibration_eval_max_corr_distance = 0.1;

  // Calibration (registration ensemble)
  int solver_iterations = 200;
  double max_corr_dist_coarse = 0.5;
  double max_corr_dist_fine = 0.1;
  double max_corr_dist_ultra_fine = 0.05;
  int lidar_calibration_min_frames = 2;
  int lidar_calibration_max_frames = 10;
  // rigcal: bounds the whole lidar-lidar calibration's running time, shared by the calibration lidars (README).
  double calibration_deadline_s = 10.0;

  // Base-lidar calibration
  bool calibrate_base_frame = false;
  // The crop box (base_link) defaults to the default VehicleFootprint's (vehicle_footprint.hpp), not
  // upstream's ±20 m: on bumpy ground a wide box fits the terrain's mean tilt, not the wheels' ground.
  // A rig's `vehicle:` section derives all six; a base_lidar_crop_box_* parameter overrides its one bound.
  double base_lidar_crop_box_min_x = -1.5;
  double base_lidar_crop_box_min_y = -1.5;
  double base_lidar_crop_box_min_z = -1.0;
  double base_lidar_crop_box_max_x = 4.0;
  double base_lidar_crop_box_max_y = 1.5;
  double base_lidar_crop_box_max_z = 0.5;
  double base_lidar_max_inlier_distance = 0.01;
  int base_lidar_max_iterations = 1000;
  int base_lidar_min_plane_points = 1000;
  double base_lidar_min_plane_points_percentage = 10.0;
  double base_lidar_max_cos_distance = 0.5;
  bool base_lidar_overwrite_xy_yaw = false;
  // rigcal: base_link yaw ("yaw") or yaw and x ("yaw_x") from the mapping lidar's motion (rear-axle
  // base_link, no side slip); "off" keeps them from the initial guess (README).
  std::string base_link_from_motion = "off";

  // rigcal: static calibration (`rigcal calibrate --static`, README): seconds of every lidar accumulated
  // while the vehicle stands still, and how far the mapping lidar may move (against its first sweep)
  // before the capture is refused.
  double static_capture_s = 2.0;
  double static_max_motion_m = 0.03;
  double static_max_motion_deg = 0.3;
};

}  // namespace rigcal::config
