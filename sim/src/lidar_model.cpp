#include "rigcal/sim/lidar_model.hpp"

#include <cmath>
#include <stdexcept>

#include "rigcal/core/pose.hpp"

namespace rigcal::sim {

Eigen::Vector3d beamDirection(double azimuth_deg, double elevation_deg) {
  const double a = deg2rad(azimuth_deg), w = deg2rad(elevation_deg);
  return {std::cos(w) * std::cos(a), -std::cos(w) * std::sin(a), std::sin(w)};
}

double LidarModel::beamAzimuthDeg(std::size_t beam, double rotor_azimuth_deg) const {
  const LidarBeam& b = beams.at(beam);
  double a = rotor_azimuth_deg + b.azimuth_offset_deg;
  if (azimuth_follows_firing_time) a += 360.0 * rotation_hz * double(b.time_offset_ns) * 1e-9;
  return a;
}

Eigen::Vector3d LidarModel::direction(std::size_t beam, double rotor_azimuth_deg) const {
  return beamDirection(beamAzimuthDeg(beam, rotor_azimuth_deg), beams.at(beam).elevation_deg);
}

Eigen::Vector3d LidarModel::beamOrigin(double rotor_azimuth_deg) const {
  if (beam_origin_radius_m == 0.0 && beam_origin_z_m == 0.0) return Eigen::Vector3d::Zero();
  const double a = deg2rad(rotor_azimuth_deg);
  return {beam_origin_radius_m * std::cos(a), -beam_origin_radius_m * std::sin(a), beam_origin_z_m};
}

Eigen::Vector3d LidarModel::point(std::size_t beam, double rotor_azimuth_deg, double range_m) const {
  const double travel = range_from_beam_origin ? range_m : range_m - beam_origin_radius_m;
  return beamOrigin(rotor_azimuth_deg + beams.at(beam).origin_azimuth_deg) + travel * direction(beam, rotor_azimuth_deg);
}

namespace {

const std::vector<LidarModel>& registry() {
  static const std::vector<LidarModel> models = [] {
    std::vector<LidarModel> m;
    m.push_back(detail::makeVlp16());
    m.push_back(detail::makeVlp32c());
    m.push_back(detail::makeVls128());
    m.push_back(detail::makeOs1_64());
    m.push_back(detail::makeOs1_128());
    m.push_back(detail::makePandarXt32());
    m.push_back(detail::makePandar64());
    m.push_back(detail::makeHelios16p());
    return m;
  }();
  return models;
}

}  // namespace

const LidarModel& lidarModel(std::string_view name) {
  for (const auto& m : registry())
    if (m.name == name) return m;
  std::string known;
  for (const auto& m : registry()) known += (known.empty() ? "" : ", ") + m.name;
  throw std::invalid_argument("unknown lidar model '" + std::string(name) + "'; known: " + known);
}

std::vector<std::string> lidarModelNames() {
  std::vector<std::string> names;
  for (const auto& m : registry()) names.push_back(m.name);
  return names;
}

}  // namespace rigcal::sim
