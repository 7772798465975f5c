#include "parameter_table.hpp"

#include <limits>

namespace rigcal::config::detail {

namespace {
constexpr double kInf = std::numeric_limits<double>::infinity();
using P = Parameters;
}  // namespace

const std::vector<ParameterSpec>& parameterSpecs() {
  static const std::vector<ParameterSpec> specs = {
      {"mapping_registrator", &P::mapping_registrator, 0, 0, {"gicp", "ndt"}},
      {"mapping_max_frames", &P::mapping_max_frames, 10, 100000, {}},
      {"local_map_num_keyframes", &P::local_map_num_keyframes, 1, 1000, {}},
      {"dense_pointcloud_num_keyframes", &P::dense_pointcloud_num_keyframes, 0, 1000, {}},
      {"mapping_min_range", &P::mapping_min_range, 0, 1000, {}},
      {"mapping_max_range", &P::mapping_max_range, 0.1, 1000, {}},
      {"min_mapping_pointcloud_size", &P::min_mapping_pointcloud_size, 1, 10'000'000, {}},
      {"min_calibration_pointcloud_size", &P::min_calibration_pointcloud_size, 1, 10'000'000, {}},
      {"mapping_lost_timeout", &P::mapping_lost_timeout, 0.01, 3600, {}},
      {"mapper_resolution", &P::mapper_resolution, 0.05, 100, {}},
      {"mapper_step_size", &P::mapper_step_size, 1e-4, 10, {}},
      {"mapper_max_iterations", &P::mapper_max_iterations, 1, 10000, {}},
      {"mapper_num_threads", &P::mapper_num_threads, 1, 2, {}},
      {"mapper_max_correspondence_distance", &P::mapper_max_correspondence_distance, 1e-3, 100, {}},
      {"leaf_size_input", &P::leaf_size_input, 0, 10, {}},
      {"leaf_size_local_map", &P::leaf_size_local_map, 0, 10, {}},
      {"leaf_size_dense_map", &P::leaf_size_dense_map, 0, 10, {}},
      {"new_keyframe_min_distance", &P::new_keyframe_min_distance, 0, 1000, {}},
      {"new_frame_min_distance", &P::new_frame_min_distance, 0, 1000, {}},
      {"frame_stopped_distance", &P::frame_stopped_distance, 0, 1000, {}},
      {"frames_since_stopped_force_frame", &P::frames_since_stopped_force_frame, 1, 10000, {}},
      {"calibration_skip_keyframes", &P::calibration_skip_keyframes, 0, 100000, {}},
      {"max_allowed_interpolated_time", &P::max_allowed_interpolated_time, 0, 10, {}},
      {"max_allowed_interpolated_distance", &P::max_allowed_interpolated_distance, 0, 100, {}},
      {"max_allowed_interpolated_angle", &P::max_allowed_interpolated_angle, 0, 180, {}},
      {"max_allowed_interpolated_speed", &P::max_allowed_interpolated_speed, 0, 100, {}},
      {"max_allowed_interpolated_accel", &P::max_allowed_interpolated_accel, 0, 100, {}},
      {"max_allowed_interpolated_distance_straight", &P::max_allowed_interpolated_distance_straight, 0, 100, {}},
      {"max_allowed_interpolated_angle_straight", &P::max_allowed_interpolated_angle_straight, 0, 180, {}},
      {"max_allowed_interpolated_speed_straight", &P::max_allowed_interpolated_speed_straight, 0, 100, {}},
      {"max_allowed_interpolated_accel_straight", &P::max_allowed_interpolated_accel_straight, 0, 100, {}},
      {"lost_frame_max_angle_diff", &P::lost_frame_max_angle_diff, 0, 180, {}},
      {"lost_frame_interpolation_error", &P::lost_frame_interpolation_error, 0, 100, {}},
      {"lost_frame_max_acceleration", &P::lost_frame_max_acceleration, 0, 1000, {}},
      {"crop_z_calibration_pointclouds", &P::crop_z_calibration_pointclouds, 0, 0, {}},
      {"crop_z_calibration_pointclouds_value", &P::crop_z_calibration_pointclouds_value, -100, 100, {}},
      {"calibration_use_only_stopped", &P::calibration_use_only_stopped, 0, 0, {}},
      {"max_calibration_range", &P::max_calibration_range, 0.1, 1000, {}},
      {"min_calibration_range", &P::min_calibration_range, 0, 1000, {}},
      {"calibration_min_pca_eigenvalue", &P::calibration_min_pca_eigenvalue, 0, 1000, {}},
      {"calibration_min_distance_between_frames", &P::calibration_min_distance_between_frames, 0, 10000, {}},
      {"calibration_frame_ranking", &P::calibration_frame_ranking, 0, 0, {"information", "pca"}},
      {"calibration_eval_max_corr_distance", &P::calibration_eval_max_corr_distance, 1e-3, 10, {}},
      {"solver_iterations", &P::solver_iterations, 1, 100000, {}},
      {"max_corr_dist_coarse", &P::max_corr_dist_coarse, 1e-3, 100, {}},
      {"max_corr_dist_fine", &P::max_corr_dist_fine, 1e-3, 100, {}},
      {"max_corr_dist_ultra_fine", &P::max_corr_dist_ultra_fine, 1e-3, 100, {}},
      {"lidar_calibration_min_frames", &P::lidar_calibration_min_frames, 1, 1000, {}},
      {"lidar_calibration_max_frames", &P::lidar_calibration_max_frames, 1, 1000, {}},
      {"calibration_deadline_s", &P::calibration_deadline_s, 0.1, 3600, {}},
      {"calibrate_base_frame", &P::calibrate_base_frame, 0, 0, {}},
      {"base_lidar_crop_box_min_x", &P::base_lidar_crop_box_min_x, -kInf, kInf, {}},
      {"base_lidar_crop_box_min_y", &P::base_lidar_crop_box_min_y, -kInf, kInf, {}},
      {"base_lidar_crop_box_min_z", &P::base_lidar_crop_box_min_z, -kInf, kInf, {}},
      {"base_lidar_crop_box_max_x", &P::base_lidar_crop_box_max_x, -kInf, kInf, {}},
      {"base_lidar_crop_box_max_y", &P::base_lidar_crop_box_max_y, -kInf, kInf, {}},
      {"base_lidar_crop_box_max_z", &P::base_lidar_crop_box_max_z, -kInf, kInf, {}},
      {"base_lidar_max_inlier_distance", &P::base_lidar_max_inlier_distance, 1e-4, 10, {}},
      {"base_lidar_max_iterations", &P::base_lidar_max_iterations, 1, 1'000'000, {}},
      {"base_lidar_min_plane_points", &P::base_lidar_min_plane_points, 3, 100'000'000, {}},
      {"base_lidar_min_plane_points_percentage", &P::base_lidar_min_plane_points_percentage, 0, 100, {}},
      {"base_lidar_max_cos_distance", &P::base_lidar_max_cos_distance, 0, 1, {}},
      {"base_lidar_overwrite_xy_yaw", &P::base_lidar_overwrite_xy_yaw, 0, 0, {}},
      {"base_link_from_motion", &P::base_link_from_motion, 0, 0, {"off", "yaw", "yaw_x"}},
      {"static_capture_s", &P::static_capture_s, 0.1, 600, {}},
      {"static_max_motion_m", &P::static_max_motion_m, 1e-4, 10, {}},
      {"static_max_motion_deg", &P::static_max_motion_deg, 1e-3, 180, {}},
  };
  return specs;
}

const std::vector<std::string>& ignoredUpstreamParameters() {
  static const std::vector<std::string> names = {
      "base_frame", "map_frame", "mapping_lidar_frame", "calibration_lidar_frames",
      "calibration_pointcloud_topics", "calibration_camera_optical_link_frames",
      "calibration_camera_info_topics", "calibration_image_topics", "use_rosbag", "mapping_verbose",
      "mapping_viz_leaf_size", "calibration_viz_leaf_size", "filter_detections",
      "detection_max_time_tolerance", "detection_size_tolerance", "camera_calibration_min_frames",
      "camera_calibration_max_frames", "pc_features_min_distance", "pc_features_max_distance",
      // Read by upstream, not by rigcal: our GICP/NDT stop on their own step criteria (not
      // mapper_epsilon), there is no visualiser (viz_max_range), and pairing has no last-frames mode.
      "mapper_epsilon", "viz_max_range", "calibration_use_only_last_frames",
  };
  return names;
}

}  // namespace rigcal::config::detail
