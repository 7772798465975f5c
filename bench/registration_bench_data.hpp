#pragma once
// The registration benchmark's data, shared by its Google Benchmark cases and its callgrind profile mode:
// the VLS-128 reference scan moved by a known transform (the source), the same scan as a scan-to-scan
// target and a ~255k-point map as a scan-to-map target, each also as a PCL cloud for the baseline.
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include <filesystem>
#include <memory>
#include <string>

#include "rigcal/core/pose.hpp"
#include "rigcal/registration/point_cloud.hpp"
#include "rigcal/registration/target.hpp"

namespace rigcal::bench {

using PclCloud = pcl::PointCloud<pcl::PointXYZ>;

struct Scenario {
  std::string name;
  std::unique_ptr<registration::Target> target;  // everything: tree, covariances + graph, NDT grid 1.0
  PclCloud::Ptr pcl_target;
};

struct Data {
  registration::PointCloud raw;
  registration::PointCloud source;      // positions only
  registration::PointCloud source_cov;  // with covariances (for "align only")
  PclCloud::Ptr pcl_source;
  Pose truth;
  Scenario scan, map;
};

/// Loads the scan and a second sensor's scan (the map's far part, content the source does not see).
/// Call once, before data().
void loadRegistrationData(const std::filesystem::path& scan, const std::filesystem::path& other);
[[nodiscard]] const Data& data();

PclCloud::Ptr toPcl(const registration::PointCloud& c);

/// The limits every method runs with, ours and PCL's: 64 iterations, steps of 1e-4 m / rad.
template <class P>
P commonParams(int threads) {
  P p;
  p.num_threads = threads;
  p.max_iterations = 64;
  p.transformation_epsilon = 1e-4;
  p.rotation_epsilon = 1e-4;
  return p;
}

}  // namespace rigcal::bench
