#include "lidar_lidar_sim_dataset.hpp"

#include <algorithm>
#include <cmath>
#include <memory>
#include <random>
#include <stdexcept>

#include "rigcal/calib/lidar_lidar/calibration_deskew.hpp"
#include "rigcal/pipeline/deskew.hpp"
#include "rigcal/pipeline/frame_selector.hpp"
#include "rigcal/registration/voxel_grid.hpp"
#include "rigcal/sim/scenario.hpp"
#include "rigcal/sim/simulation.hpp"
#include "sanitizers.hpp"

namespace rigcal::test {
namespace {

using pipeline::CalibrationDataset;
using pipeline::FrameKind;
using pipeline::MappingFrame;

Eigen::Vector3d randomUnit(std::mt19937_64& rng) {
  std::normal_distribution<double> n(0.0, 1.0);
  Eigen::Vector3d v(n(rng), n(rng), n(rng));
  return v.normalized();
}

/// Collects the mapping lidar's sweeps (deskewed by the truth, voxelised at once to keep memory small)
/// and the calibration lidars' raw sweeps.
struct Collector : sim::SimulationSink {
  const sim::Simulation* sim = nullptr;
  std::size_t mapping = 0;
  double leaf = 0.1;
  std::vector<std::shared_ptr<const Scan>> mapping_scans;
  std::map<std::size_t, std::vector<std::shared_ptr<const Scan>>> calib_scans;

  void onScan(sim::SimulatedScan&& s) override {
    if (s.scan.empty()) return;
    const TimeNs offset = sim->scenario().sensors[s.sensor].clock_offset_ns;
    if (s.sensor != mapping) {
      calib_scans[s.sensor].push_back(std::make_shared<const Scan>(std::move(s.scan)));
      return;
    }
    Scan scan = std::move(s.scan);
    const std::size_t sensor = s.sensor;
    const Pose T_ref_world = sim->T_world_sensor(sensor, scan.stamp_ns - offset).inverse();
    pipeline::deskew(scan, [&](TimeNs t) { return Pose(T_ref_world * sim->T_world_sensor(sensor, t - offset)); });
    const auto voxels = registration::voxelDownsample(registration::fromScan(scan), leaf);
    auto out = std::make_shared<Scan>();
    out->sensor_id = scan.sensor_id;
    out->sequence = scan.sequence;
    out->stamp_ns = scan.stamp_ns;
    out->reserve(voxels.size());
    for (const auto& p : voxels.points) {
      Point q;
      q.x = float(p.x());
      q.y = float(p.y());
      q.z = float(p.z());
      q.time_ns = scan.stamp_ns;
      out->push_back(q);
    }
    mapping_scans.push_back(std::move(out));
  }
};

}  // namespace

Pose perturb(const Pose& T, double metres, double degrees, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  const Eigen::Vector3d dt = randomUnit(rng) * metres;
  const Eigen::Vector3d axis = randomUnit(rng);
  Pose D = Pose::Identity();
  D.linear() = Eigen::AngleAxisd(deg2rad(degrees), axis).toRotationMatrix();
  D.translation() = dt;
  return Pose(T * D);
}

SimDatasets buildSimDatasets(const SimDatasetOptions& options) {
  sim::Scenario scenario = sim::loadScenario(options.scenario);
  auto& segments = scenario.trajectory.segments;
  // Start moving at once: the preset's opening stop adds nothing to a lidar-lidar dataset.
  if (!segments.empty() && segments.front().kind == sim::TrajectorySegment::Kind::kStop) segments.erase(segments.begin());
  if (options.bump_amplitude_m >= 0) scenario.scene.bump_amplitude_m = options.bump_amplitude_m;
  const sim::Simulation sim(scenario);
  const std::size_t mapping = scenario.sensorIndex(scenario.mapping_lidar);

  Collector c;
  c.sim = &sim;
  c.mapping = mapping;
  c.leaf = options.mapping_leaf;
  sim::SimulationOptions so;
  so.threads = 2;
  so.max_duration_ns = fromSeconds(options.seconds);
  sim.run(c, so);
  if (c.mapping_scans.size() < 10) throw std::runtime_error("simulation gave too few mapping sweeps");

  SimDatasets out;
  config::Parameters& p = out.params;
  p.dense_pointcloud_num_keyframes = 3;
  p.lidar_calibration_max_frames = options.frames;
  p.lidar_calibration_min_frames = 2;
  const TimeNs mapping_offset = scenario.sensors[mapping].clock_offset_ns;

  // The mapper's trajectory from the truth (map frame = the first sweep's), keyframes every metre.
  std::mt19937_64 noise_rng(options.seed);
  std::normal_distribution<double> n01(0.0, 1.0);
  const auto& first = *c.mapping_scans.front();
  const Pose T_map_world = sim.T_world_sensor(mapping, first.stamp_ns - mapping_offset).inverse();
  std::vector<MappingFrame> trajectory;
  std::vector<pipeline::MappingCloud> clouds;
  double path = 0.0, last_keyframe_path = -1e9;
  int keyframes = 0;
  std::vector<std::size_t> keyframe_frames;
  for (std::size_t i = 0; i < c.mapping_scans.size(); ++i) {
    const auto& s = c.mapping_scans[i];
    MappingFrame f;
    f.sequence = s->sequence;
    f.stamp_ns = s->stamp_ns;
    f.T_map_lidar = T_map_world * sim.T_world_sensor(mapping, s->stamp_ns - mapping_offset);
    if (options.pose_noise_m > 0 || options.pose_noise_deg > 0) {
      Vector6d xi;
      for (int k = 0; k < 3; ++k) xi[k] = options.pose_noise_m * n01(noise_rng);
      for (int k = 3; k < 6; ++k) xi[k] = deg2rad(options.pose_noise_deg) * n01(noise_rng);
      f.T_map_lidar = f.T_map_lidar * expSE3(xi);
    }
    if (!trajectory.empty()) {
      f.delta = (trajectory.back().T_map_lidar.translation() - f.T_map_lidar.translation()).norm();
      path += f.delta;
    }
    f.path_length = path;
    f.kind = FrameKind::kFrame;
    if (path >= last_keyframe_path + 1.0) {
      f.kind = FrameKind::kKeyframe;
      f.keyframe_index = keyframes++;
      last_keyframe_path = path;
      keyframe_frames.push_back(i);
    }
    trajectory.push_back(f);
    clouds.push_back({f, s});
  }
  if (keyframes < options.frames + 2) throw std::runtime_error("simulated stretch too short for the frames asked");

  // Ground cloud for the base-lidar check: the dense window of the middle keyframe, in its frame.
  {
    const std::size_t kf = keyframe_frames[keyframe_frames.size() / 2];
    const Pose T_kf_map = trajectory[kf].T_map_lidar.inverse();
    for (std::size_t i = (kf >= 20 ? kf - 20 : 0); i < std::min(clouds.size(), kf + 20); ++i) {
      const Pose T = T_kf_map * clouds[i].frame.T_map_lidar;
      const Scan& s = *clouds[i].cloud;
      for (std::size_t j = 0; j < s.size(); ++j) out.ground_cloud_mapping.push_back(T * Eigen::Vector3d(s.x[j], s.y[j], s.z[j]));
    }
  }

  out.truth_T_base_mapping = scenario.sensors[mapping].T_base_sensor;
  std::uint64_t seed = options.seed;
  for (const auto& name : scenario.calibration_lidars) {
    const std::size_t ci = scenario.sensorIndex(name);
    const Pose truth = scenario.sensors[mapping].T_base_sensor.inverse() * scenario.sensors[ci].T_base_sensor;
    out.truth_T_mapping_calib[name] = truth;
    CalibrationDataset d;
    d.mapping_sensor = scenario.mapping_lidar;
    d.calibration_sensor = name;
    d.T_base_mapping = out.truth_T_base_mapping;
    d.T_mapping_calib_guess = perturb(truth, options.perturb_m, options.perturb_deg, ++seed);
    d.trajectory = trajectory;
    d.mapping_clouds = clouds;
    d.budget_full = true;
    // Calibration sweeps on the mapping clock (what the pipeline's time sources give it).
    const TimeNs shift = mapping_offset - scenario.sensors[ci].clock_offset_ns;
    const auto& scans = c.calib_scans[ci];
    // Keyframes spread along the path, away from both ends (the pose must be interpolable).
    for (int k = 0; k < options.frames; ++k) {
      const std::size_t kf = keyframe_frames[1 + std::size_t(k) * (keyframe_frames.size() - 3) / std::size_t(std::max(options.frames - 1, 1))];
      const TimeNs t_kf = trajectory[kf].stamp_ns;
      std::shared_ptr<const Scan> best;
      for (std::size_t i = 1; i + 1 < scans.size(); ++i)  // complete sweeps only
        if (best == nullptr || std::llabs(scans[i]->stamp_ns + shift - t_kf) < std::llabs(best->stamp_ns + shift - t_kf))
          best = scans[i];
      if (best == nullptr) throw std::runtime_error("no calibration sweep for " + name);
      auto raw = std::make_shared<Scan>(*best);
      raw->stamp_ns += shift;
      pipeline::CalibrationFrame f;
      f.pairing.keyframe_frame = kf;
      f.pairing.scan_sequence = raw->sequence;
      f.pairing.scan_stamp_ns = raw->stamp_ns;
      f.pairing.T_map_mapping_at_scan = calib::mappingPoseAt(trajectory, raw->stamp_ns);
      f.pairing.accepted = true;
      f.raw = raw;
      f.deskewed = std::make_shared<const Scan>(calib::deskewThroughMapping(*raw, trajectory, d.T_mapping_calib_guess));
      f.information = pipeline::pcaInformation(*f.deskewed);
      d.frames.push_back(std::move(f));
      d.candidates.push_back(d.frames.back().pairing);
    }
    out.datasets.push_back(std::move(d));
  }
  return out;
}

namespace {
std::unique_ptr<SimDatasets> g_flat_parking_lot;
}  // namespace

const SimDatasets& flatParkingLot() {
  if (!g_flat_parking_lot) {
    SimDatasetOptions o;
    o.bump_amplitude_m = 0.0;  // the lot keeps its slope; see SimDatasetOptions for why no bumps
    if (RIGCAL_SANITIZED) {    // instrumented code runs 10-50x slower: a shorter stretch, fewer frames
      o.seconds = 6.0;
      o.frames = 2;
    }
    g_flat_parking_lot = std::make_unique<SimDatasets>(buildSimDatasets(o));
  }
  return *g_flat_parking_lot;
}

void releaseFlatParkingLot() { g_flat_parking_lot.reset(); }

}  // namespace rigcal::test
