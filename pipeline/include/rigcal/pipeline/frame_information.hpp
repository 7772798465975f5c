#pragma once
// What a calibration frame can constrain, before any registration: the point-to-plane information of the
// calibration lidar's cloud, in its own frame, against its own local planes (rotation about the lidar).
// A registration of that cloud against the map can only be as well conditioned as the planes it sees, so
// a frame whose planes all share one normal direction (a side-mounted lidar looking at one wall and the
// ground) leaves a translation free, however much PCA spread its points have.
#include "rigcal/core/scan.hpp"
#include "rigcal/registration/point_to_plane_information.hpp"

namespace rigcal::pipeline {

struct FrameInformationOptions {
  double leaf_size = 0.25;        // m: voxel thinning first (a dense near field would outvote the far planes)
  int num_neighbors = 12;         // k of the local plane fit
  double max_neighbor_distance = 1.5;  // m: farther neighbours belong to another surface
  double max_flatness = 0.1;      // smallest / middle eigenvalue of the neighbourhood: a plane, not a volume
  double min_planarity = 0.05;    // middle / largest: a plane, not one scan ring (a line, whose normal is arbitrary)
};

/// Only points whose neighbourhood is a plane contribute (normal from it, arm from the origin).
registration::PointToPlaneInformation frameInformation(const Scan& cloud, const FrameInformationOptions& options = {});

}  // namespace rigcal::pipeline
