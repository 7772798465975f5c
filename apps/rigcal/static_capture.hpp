#pragma once
// The input side of `rigcal calibrate --static`: every lidar of the rig read straight from its driver
// (pcap or live UDP, the SensorDriver of `rigcal driver`) or its shared-memory ring, no mapping pipeline,
// until each has covered `capture_s` from the moment the vehicle has been still for 0.5 s (StillnessWatch
// on the mapping lidar's sweeps), or the input ends, or `stop` is set. Each sensor's first sweep is
// dropped: it may have started mid-rotation.
#include <atomic>
#include <string>
#include <vector>

#include "rigcal/calib/lidar_lidar/static_calibration.hpp"
#include "rigcal/config/rig_config.hpp"
#include "rigcal/pipeline/pipeline.hpp"

namespace rigcal::app {

struct StaticCaptureResult {
  calib::StaticCapture capture;
  std::vector<pipeline::SensorInput> inputs;  // per sensor (pcap / live), as the pipeline reports them
  bool complete = false;                      // every sensor covered the window (else the input ended first)
  bool settled = false;     // the vehicle was still for 0.5 s and the window opened (else: never_still)
  double waited_s = 0.0;    // from the first mapping sweep to the window's start (or the input's end)
  std::string never_still;  // one line when !settled
};

/// Throws std::runtime_error (one line naming the sensor) when a sensor's input cannot be opened.
StaticCaptureResult captureStatic(const config::RigConfig& rig, const pipeline::PipelineOptions& options,
                                  double capture_s, const std::atomic<bool>& stop);

}  // namespace rigcal::app
