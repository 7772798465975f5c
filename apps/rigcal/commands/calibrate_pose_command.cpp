// `rigcal calibrate-pose (--pcap F | --bag B [--topic T]) (--poses CSV | --pose-topic T | --pose-tf P:C) (--config rig.yaml --sensor NAME | --model M ...) [--out DIR]`:
// lidar-to-pose-sensor calibration with time offset (the lidar_align successor). Decodes one lidar's
// packets (every point keeps its own time), selects lidar_align's subset of the returns as the scans
// arrive, calibrates against the poses and writes lidar_align's text, calibration.yaml and the fused
// cloud as PLY.
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <memory>
#include <optional>
#include <sstream>

#include "../commands.hpp"
#include "../exit_codes.hpp"
#include "../rig_loading.hpp"
#include "../output_folder.hpp"
#include "rigcal/bag/bag_cloud_source.hpp"
#include "rigcal/bag/bag_packet_source.hpp"
#include "rigcal/bag/lidar_topic.hpp"
#include "rigcal/bag/pose_message.hpp"
#include "rigcal/calib/lidar_pose/lidar_pose_calibration.hpp"
#include "rigcal/calib/lidar_pose/lidar_pose_output.hpp"
#include "rigcal/calib/lidar_pose/pose_csv.hpp"
#include "rigcal/calib/outputs/calibration_yaml_writer.hpp"
#include "rigcal/config/config_error.hpp"
#include "rigcal/config/rig_config.hpp"
#include "rigcal/drivers/packet_decoder.hpp"
#include "rigcal/drivers/pcap_source.hpp"
#include "rigcal/drivers/scan_assembler.hpp"
#include "rigcal/drivers/scan_pump.hpp"
#include "rigcal/pipeline/sensor_driver.hpp"

namespace rigcal::app {
namespace {

namespace fs = std::filesystem;

struct CalibratePoseArgs {
  std::string pcap, bag, topic, poses, pose_topic, pose_tf, pose_bag, config, sensor, model, calibration, metadata, address, out;
  std::string time_source = "sensor";
  int port = 0;
  std::uint64_t seed = 0;
  std::vector<double> initial;  // x y z (m) roll pitch yaw (deg)
  double initial_time_offset_s = 0.0;
  calib::LidarPoseSettings settings;
  bool optimise_all = false;
};

// Joins the parts of a message (std::ostringstream: GCC 12 warns falsely on std::string operator+).
template <typename... Parts>
std::string cat(const Parts&... parts) {
  std::ostringstream o;
  (o << ... << parts);
  return o.str();
}

struct Decoded {
  calib::LidarPoints points;
  std::string name;  // the lidar's frame name in calibration.yaml
  std::size_t packets = 0, malformed = 0, lost = 0;
  std::string warning;
};

// Decodes the capture, selecting each scan's returns as it arrives (nothing else is kept).
Decoded decode(const CalibratePoseArgs& a, const calib::LidarPointSelection& selection) {
  Decoded d;
  const auto on_scan = [&](Scan&& scan) { calib::appendLidarPoints(scan, selection, d.points); };
  if (!a.config.empty()) {
    const config::RigConfig rig = loadRig(a.config);
    const config::SensorConfig* sensor = nullptr;
    try {
      sensor = &rig.sensor(a.sensor);
    } catch (const config::ConfigError& e) {
      throw CommandFailed(kExitConfig, e.what());
    }
    d.name = sensor->name;
    const std::atomic<bool> stop{false};
    std::unique_ptr<pipeline::SensorDriver> driver;
    try {
      pipeline::DriverInput input;
      if (a.bag.empty()) input.pcap = fs::path(a.pcap);
      else input.bag = fs::path(a.bag);
      input.topic = a.topic;
      driver = std::make_unique<pipeline::SensorDriver>(*sensor, input, stop, on_scan);
    } catch (const std::exception& e) {
      throw CommandFailed(kExitInput, e.what());
    }
    driver->run();
    d.packets = driver->assemblerStats().packets;
    d.malformed = driver->assemblerStats().malformed;
    d.lost = driver->assemblerStats().lost_packets;
    d.warning = driver->warning();
    return d;
  }
  drivers::DecoderConfig config;
  config.model = a.model;
  config.calibration = a.calibration;
  config.metadata = a.metadata;
  config.time_source = a.time_source == "host" ? TimeSource::kHostReceive : TimeSource::kSensorClock;
  std::unique_ptr<drivers::PacketDecoder> decoder;
  std::unique_ptr<drivers::PacketSource> source;
  try {
    decoder = drivers::makeDecoder(config);
    drivers::PacketFilter filter;
    if (a.port) filter.destination_port = std::uint16_t(a.port);
    if (!a.address.empty()) filter.source_address = drivers::parseIpv4(a.address);
    if (!a.bag.empty()) {
      // A PointCloud2 topic needs no decoder: its clouds are the scans.
      bag::Bag probe(a.bag);
      if (bag::chooseLidarTopic(probe, a.topic).form == bag::LidarTopicForm::kPointCloud2) {
        bag::BagCloudSource clouds(a.bag, a.topic);
        d.name = "lidar";
        while (auto cloud = clouds.next()) on_scan(std::move(cloud->scan));
        d.packets = clouds.stats().packets;
        d.malformed = clouds.stats().malformed;
        d.warning = clouds.warning();
        return d;
      }
      source = std::make_unique<bag::BagPacketSource>(a.bag, a.topic);
    } else {
      source = std::make_unique<drivers::PcapSource>(a.pcap, filter);
    }
  } catch (const std::exception& e) {
    throw CommandFailed(kExitInput, e.what());
  }
  d.name = "lidar";
  drivers::ScanAssembler assembler(a.model, drivers::AssemblerConfig{}, on_scan);
  drivers::pumpScans(*source, *decoder, assembler);
  d.packets = assembler.stats().packets;
  d.malformed = assembler.stats().malformed;
  d.lost = assembler.stats().lost_packets;
  d.warning = source->warning();
  return d;
}

std::string summary(const calib::LidarPoseResult& r) {
  const XyzRpy v = toXyzRpy(r.T_pose_lidar);
  std::ostringstream o;
  o << std::fixed << std::setprecision(4) << "T_pose_lidar: x " << v.x << " m, y " << v.y << " m, z " << v.z
    << " m, roll " << rad2deg(v.roll) << " deg, pitch " << rad2deg(v.pitch) << " deg, yaw " << rad2deg(v.yaw)
    << " deg\n"
    << std::setprecision(6) << "time offset to add to lidar timestamps: " << r.time_offset_s << " s\n";
  std::string held;
  for (std::size_t i = 0; i < calib::kLidarPoseParams; ++i)
    if (r.held[i]) held += cat(held.empty() ? "" : ", ", calib::lidarPoseParamName(calib::LidarPoseParam(i)));
  if (!held.empty()) o << "held at the initial guess (poorly constrained by the motion): " << held << '\n';
  return o.str();
}

void run(CalibratePoseArgs a) {
  if (a.config.empty() == a.model.empty())
    throw CommandFailed(kExitUsage, "calibrate-pose: give either --config with --sensor, or --model");
  if (!a.config.empty() && a.sensor.empty())
    throw CommandFailed(kExitUsage, "calibrate-pose: --config needs --sensor NAME");
  if (a.pcap.empty() == a.bag.empty()) throw CommandFailed(kExitUsage, "calibrate-pose: give either --pcap or --bag");
  if (!a.pcap.empty()) requireInputFile(a.pcap, "capture");
  else if (!fs::exists(a.bag)) throw CommandFailed(kExitInput, a.bag + ": bag not found");
  const int pose_inputs = int(!a.poses.empty()) + int(!a.pose_topic.empty()) + int(!a.pose_tf.empty());
  if (pose_inputs != 1)
    throw CommandFailed(kExitUsage, "calibrate-pose: give one of --poses CSV, --pose-topic TOPIC, --pose-tf PARENT:CHILD");
  if (a.poses.empty() && a.bag.empty() && a.pose_bag.empty())
    throw CommandFailed(kExitUsage, "calibrate-pose: --pose-topic / --pose-tf read a bag: give --bag or --pose-bag");
  if (!a.poses.empty()) requireInputFile(a.poses, "pose file");
  if (!a.config.empty()) requireInputFile(a.config, "rig file");
  if (!a.out.empty()) prepareOutputFolder(a.out);

  calib::LidarPoseSettings& s = a.settings;
  s.selection.seed = a.seed;
  s.hold_poorly_constrained = !a.optimise_all;
  s.initial_time_offset_s = a.initial_time_offset_s;
  if (!a.initial.empty()) {
    if (a.initial.size() != 6)
      throw CommandFailed(kExitUsage, "calibrate-pose: --initial needs 6 values: x y z (m) roll pitch yaw (deg)");
    s.initial_T_pose_lidar = fromXyzRpy({a.initial[0], a.initial[1], a.initial[2], deg2rad(a.initial[3]),
                                         deg2rad(a.initial[4]), deg2rad(a.initial[5])});
  }

  calib::PoseCsv csv;
  std::string pose_source = a.poses;
  try {
    if (!a.poses.empty()) {
      csv = calib::readPoseCsv(a.poses);
    } else {
      const std::string bag = a.pose_bag.empty() ? a.bag : a.pose_bag;
      std::optional<std::pair<std::string, std::string>> frames;
      if (!a.pose_tf.empty()) {
        const auto colon = a.pose_tf.find(':');
        if (colon == std::string::npos || colon == 0 || colon + 1 == a.pose_tf.size())
          throw CommandFailed(kExitUsage, "--pose-tf must be PARENT:CHILD, got '" + a.pose_tf + "'");
        frames.emplace(a.pose_tf.substr(0, colon), a.pose_tf.substr(colon + 1));
      }
      std::size_t malformed = 0;
      const auto poses = bag::readBagPoses(bag, a.pose_topic, frames, &malformed);
      pose_source = bag + " " + (frames ? "/tf " + a.pose_tf : a.pose_topic);
      if (malformed) std::cerr << "warning: " << pose_source << ": " << malformed << " malformed messages skipped\n";
      // The same parser and checks as a CSV (order, speed, re-centring): one path for every pose source.
      std::ostringstream text;
      text << std::setprecision(17);
      for (std::size_t i = 0; i < poses.size(); ++i) {
        const Eigen::Quaterniond q(poses[i].T_world_body.linear());
        const Eigen::Vector3d t = poses[i].T_world_body.translation();
        text << poses[i].stamp_ns << ',' << i << ',' << t.x() << ',' << t.y() << ',' << t.z() << ',' << q.w() << ','
             << q.x() << ',' << q.y() << ',' << q.z() << '\n';
      }
      std::istringstream in(text.str());
      csv = calib::parsePoseCsv(in, pose_source);
    }
  } catch (const CommandFailed&) {
    throw;
  } catch (const std::exception& e) {
    throw CommandFailed(kExitInput, e.what());
  }
  std::unique_ptr<calib::PoseTrajectory> trajectory;
  try {
    trajectory = std::make_unique<calib::PoseTrajectory>(csv);
  } catch (const std::exception& e) {
    throw CommandFailed(kExitInput, cat(pose_source, ": ", e.what()));
  }
  std::cout << "poses: " << csv.poses.size() << " from " << pose_source;
  if (!csv.origin.isZero())
    std::cout << std::fixed << std::setprecision(3) << " (re-centred by [" << csv.origin.x() << ", "
              << csv.origin.y() << ", " << csv.origin.z() << "])";
  std::cout << '\n';

  Decoded d = decode(a, s.selection);
  const auto& c = d.points.counts;
  std::cout << "lidar: " << c.scans << " scans, " << c.input << " returns from " << d.packets << " packets ("
            << d.malformed << " malformed, " << d.lost << " lost); " << c.kept << " selected (keep ratio "
            << s.selection.keep_points_ratio << ")\n";
  if (!d.warning.empty()) std::cerr << "warning: " << d.warning << '\n';
  const std::string lidar_source = a.pcap.empty() ? a.bag : a.pcap;
  if (c.scans == 0) throw CommandFailed(kExitNotEnoughData, cat(lidar_source, ": no lidar scans decoded"));

  calib::LidarPoseResult r;
  try {
    r = calib::calibrateLidarPose(std::move(d.points), *trajectory, s);
  } catch (const std::exception& e) {  // poses not covering the lidar, too few points
    throw CommandFailed(kExitInput, cat(pose_source, " vs ", lidar_source, ": ", e.what()));
  }
  std::cout << r.points.counts.outside_poses << " selected points dropped outside the poses' time range, "
            << r.points.size() << " used\n";
  std::cout << summary(r) << r.observability.text();
  std::cout << std::setprecision(6) << "cost: initial " << r.initial_cost << ", final " << r.final_cost
            << "; evaluations " << r.global_evaluations << " global + " << r.local_evaluations << " local; "
            << std::setprecision(3) << r.total_seconds << " s\n";

  if (!a.out.empty()) {
    const fs::path out(a.out);  // proven writable before the run
    try {
      calib::writeLidarPoseCalibrationText(out / "calibration.txt", r, csv.origin);
      calib::writeLidarPoseYaml(out / "calibration.yaml", r, "pose_sensor", d.name);
      calib::writeLidarPoseCloud(out / "lidar_points.ply", r.points, *trajectory, r.T_pose_lidar,
                                 r.time_offset_s);
    } catch (const std::exception& e) {
      throw CommandFailed(kExitFailure, e.what());
    }
    std::cout << "wrote " << (out / "calibration.txt").string() << ", calibration.yaml, lidar_points.ply\n";
  }
  if (!(r.final_cost <= r.initial_cost))
    throw CommandFailed(kExitFailure, "calibrate-pose: the result does not improve on the initial guess");
}

}  // namespace

void addCalibratePoseCommand(CLI::App& app) {
  auto a = std::make_shared<CalibratePoseArgs>();
  auto* cmd = app.add_subcommand(
      "calibrate-pose", "Calibrate a lidar against a 6-DOF pose sensor (extrinsic + time offset), lidar_align style");
  cmd->add_option("--pcap", a->pcap, "pcap or pcapng capture of the lidar");
  cmd->add_option("--bag", a->bag, "Or a ROS 2 bag holding the lidar's packets or PointCloud2 (and the poses)");
  cmd->add_option("--topic", a->topic, "With --bag: the lidar's topic (default: the bag's only lidar topic)");
  cmd->add_option("--poses", a->poses, "Poses CSV: timestamp_ns, index, px, py, pz, qw, qx, qy, qz");
  cmd->add_option("--pose-topic", a->pose_topic,
                  "Poses from a bag topic: nav_msgs/Odometry, geometry_msgs/PoseStamped or TransformStamped");
  cmd->add_option("--pose-tf", a->pose_tf, "Poses from the bag's /tf between two frames, PARENT:CHILD (e.g. map:base_link)");
  cmd->add_option("--pose-bag", a->pose_bag, "The bag of --pose-topic / --pose-tf when not --bag");
  cmd->add_option("--config", a->config, "Rig file: decode the lidar as configured there (with --sensor)");
  cmd->add_option("--sensor", a->sensor, "The rig file's name of the lidar");
  cmd->add_option("--model", a->model, "Lidar model when no rig file is given, e.g. VLP-16, OS1-64");
  cmd->add_option("--calibration", a->calibration, "With --model: Velodyne YAML/XML or Hesai angle CSV");
  cmd->add_option("--metadata", a->metadata, "With --model: Ouster sensor_info JSON");
  cmd->add_option("--port", a->port, "With --model: only datagrams to this UDP port")->check(CLI::Range(1, 65535));
  cmd->add_option("--address", a->address, "With --model: only datagrams from this IPv4 address");
  cmd->add_option("--time-source", a->time_source, "With --model: sensor (packet clock) or host")
      ->check(CLI::IsMember({"sensor", "host"}));
  cmd->add_option("--out", a->out, "Write calibration.txt, calibration.yaml and lidar_points.ply here");
  cmd->add_option("--seed", a->seed, "Salt of the deterministic point subset");
  auto& s = a->settings;
  cmd->add_option("--keep-ratio", s.selection.keep_points_ratio, "Fraction of the returns used")
      ->check(CLI::Range(1e-6, 1.0))
      ->capture_default_str();
  cmd->add_option("--min-range", s.selection.min_point_distance, "Drop returns closer than this (m)")
      ->capture_default_str();
  cmd->add_option("--max-range", s.selection.max_point_distance, "Drop returns farther than this (m)")
      ->capture_default_str();
  cmd->add_option("--min-intensity", s.selection.min_return_intensity, "Keep returns brighter than this")
      ->capture_default_str();
  cmd->add_option("--initial", a->initial, "Initial T_pose_lidar: x y z (m) roll pitch yaw (deg)")->expected(6);
  cmd->add_option("--initial-time-offset", a->initial_time_offset_s, "Initial time offset (s)");
  cmd->add_flag("--local", s.local, "Skip the global rotation search (start from --initial)");
  cmd->add_option("--max-time-offset", s.max_time_offset, "Time offset search range ± (s)")
      ->check(CLI::Range(0.0, 10.0))
      ->capture_default_str();
  cmd->add_option("--translation-range", s.translation_range, "Translation search range ± (m)")
      ->check(CLI::Range(0.0, 100.0))
      ->capture_default_str();
  cmd->add_option("--angular-range", s.angular_range, "Local rotation search range ± (rad)")
      ->check(CLI::Range(0.0, 3.2))
      ->capture_default_str();
  cmd->add_option("--max-evals", s.max_evals, "Evaluations per optimisation stage")
      ->check(CLI::Range(1, 100000))
      ->capture_default_str();
  cmd->add_flag("--no-time-offset", [a](std::int64_t) { a->settings.time_cal = false; },
                "Keep the time offset at its initial value");
  cmd->add_flag("--optimise-all", a->optimise_all,
                "Also optimise parameters the motion leaves poorly constrained (lidar_align's behaviour)");
  cmd->add_option("--threads", s.threads, "Worker threads")->check(CLI::Range(1, 64))->capture_default_str();
  cmd->footer(kExitCodesHelp);
  cmd->callback([a] { run(*a); });
}

}  // namespace rigcal::app
