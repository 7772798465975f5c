#include "static_capture.hpp"

#include <algorithm>
#include <chrono>
#include <condition_variable>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <stdexcept>
#include <thread>

#include "rigcal/calib/lidar_lidar/stillness_watch.hpp"
#include "rigcal/pipeline/sensor_driver.hpp"
#include "rigcal/shm/scan_ring_reader.hpp"

namespace rigcal::app {
namespace {

// Shared by the sensors' threads: the window opens at the mapping lidar's sweep at which the vehicle had
// been still for settle_s (the StillnessWatch, fed by the mapping lidar's thread only).
class Collector {
 public:
  Collector(std::vector<std::string> sensors, double capture_s, const config::Parameters& params,
            const std::atomic<bool>& outer_stop)
      : sensors_(std::move(sensors)), window_ns_(fromSeconds(capture_s)), outer_stop_(outer_stop), watch_(params),
        scans_(sensors_.size()), seen_(sensors_.size(), 0), done_(sensors_.size(), false) {}

  /// Sensor 0 is the mapping lidar. Called from that sensor's thread.
  void add(std::size_t sensor, Scan&& scan) {
    {
      std::lock_guard lock(mutex_);
      if (++seen_[sensor] == 1) return;  // the first sweep may have started mid-rotation
      if (sensor == 0) mapping_stamp_ = scan.stamp_ns;
    }
    changed_.notify_all();
    // Registering the sweep takes milliseconds: outside the lock, so the other sensors' threads go on.
    const bool open = sensor == 0 && !watch_.settled() && watch_.add(scan);
    std::unique_lock lock(mutex_);
    if (open) start_ = scan.stamp_ns;
    if (!start_ && sensor != 0) {
      // Waiting for the vehicle to settle. A file is read as fast as each driver goes and the watch slows
      // the mapping lidar's: a calibration lidar waits here rather than run ahead of it (and pile up).
      while (!start_ && !mapping_ended_ && !stop.load() && scan.stamp_ns > mapping_stamp_ + kAheadNs)
        changed_.wait_for(lock, std::chrono::milliseconds(20));
    }
    if (!start_) {
      // Only the calibration sweeps that may still belong to the window are kept.
      if (sensor != 0) {
        auto& list = scans_[sensor];
        list.push_back(std::make_shared<const Scan>(std::move(scan)));
        std::erase_if(list, [&](const auto& s) { return s->stamp_ns < mapping_stamp_ - kEarlyNs; });
      }
      return;
    }
    if (done_[sensor]) return;
    if (start_ && scan.stamp_ns >= *start_ + window_ns_) {
      done_[sensor] = true;
      if (std::all_of(done_.begin(), done_.end(), [](bool d) { return d; })) stop.store(true);
      return;
    }
    scans_[sensor].push_back(std::make_shared<const Scan>(std::move(scan)));
  }
  /// The mapping lidar's input ended: nothing more to wait for.
  void mappingEnded() {
    {
      std::lock_guard lock(mutex_);
      mapping_ended_ = true;
    }
    changed_.notify_all();
  }
  void pollOuterStop() {
    if (outer_stop_.load()) stop.store(true);
  }

  StaticCaptureResult result() {
    std::lock_guard lock(mutex_);
    StaticCaptureResult r;
    r.complete = std::all_of(done_.begin(), done_.end(), [](bool d) { return d; });
    r.settled = start_.has_value();
    r.waited_s = watch_.waitedS();
    if (!r.settled && watch_.sweeps() >= 2) r.never_still = watch_.neverStillMessage();
    // Sweeps that came before the window opened (another sensor's thread ran ahead) are left out.
    const auto inWindow = [&](const calib::ScanList& list) {
      calib::ScanList kept;
      for (const auto& s : list)
        if (start_ && s->stamp_ns >= *start_ - kEarlyNs && s->stamp_ns < *start_ + window_ns_) kept.push_back(s);
      return kept;
    };
    r.capture.mapping = inWindow(scans_[0]);
    for (std::size_t k = 1; k < sensors_.size(); ++k) r.capture.calibration.emplace_back(sensors_[k], inWindow(scans_[k]));
    if (r.capture.mapping.size() >= 2)
      r.capture.capture_s = toSeconds(r.capture.mapping.back()->stamp_ns - r.capture.mapping.front()->stamp_ns);
    return r;
  }

  std::atomic<bool> stop{false};

 private:
  // A calibration lidar's sweep that started up to one sweep (0.1 s) before the mapping lidar's is in.
  static constexpr TimeNs kEarlyNs = 100'000'000;
  // How far (stamps) a calibration lidar may read ahead of the mapping lidar while the watch decides.
  static constexpr TimeNs kAheadNs = 500'000'000;
  std::vector<std::string> sensors_;
  TimeNs window_ns_;
  const std::atomic<bool>& outer_stop_;
  std::mutex mutex_;
  calib::StillnessWatch watch_;
  std::optional<TimeNs> start_;
  TimeNs mapping_stamp_ = 0;
  bool mapping_ended_ = false;
  std::condition_variable changed_;
  std::vector<calib::ScanList> scans_;
  std::vector<std::uint64_t> seen_;
  std::vector<bool> done_;
};

}  // namespace

StaticCaptureResult captureStatic(const config::RigConfig& rig, const pipeline::PipelineOptions& options,
                                  double capture_s, const std::atomic<bool>& outer_stop) {
  std::vector<std::string> sensors{rig.roles.mapping_lidar};
  for (const auto& c : rig.roles.calibration_lidars) sensors.push_back(c);
  Collector collect(sensors, capture_s, rig.parameters, outer_stop);
  std::vector<std::thread> threads;
  std::vector<std::unique_ptr<pipeline::SensorDriver>> drivers;

  if (options.input == pipeline::InputKind::kShm) {
    std::vector<std::unique_ptr<shm::ScanRingReader>> readers;
    for (const auto& name : sensors) {
      shm::ReaderOptions ro;
      ro.sensor = name;
      ro.name_prefix = options.shm_prefix;
      ro.start_at = shm::ReaderOptions::StartAt::kNext;  // the vehicle stands still from now on
      readers.push_back(std::make_unique<shm::ScanRingReader>(ro));
    }
    for (std::size_t k = 0; k < readers.size(); ++k)
      threads.emplace_back([&, k] {
        Scan scan;
        while (!collect.stop.load()) {
          collect.pollOuterStop();
          try {
            if (readers[k]->read(scan, std::chrono::milliseconds(100)) == shm::ReadStatus::kScan) collect.add(k, Scan(scan));
          } catch (const std::exception&) {  // a ring truncated under us: this sensor's input ends
            break;
          }
        }
        if (k == 0) collect.mappingEnded();
      });
    for (auto& t : threads) t.join();
  } else {
    pipeline::DriverInput in;
    if (options.input == pipeline::InputKind::kPcap) in.pcap = options.pcap;
    if (options.input == pipeline::InputKind::kBag) in.bag = options.bag;
    if (pipeline::isRecording(options.input)) in.rate = options.rate;
    for (const auto& [name, topic] : options.bag_topics)
      if (name.empty() ? sensors.size() != 1 : std::find(sensors.begin(), sensors.end(), name) == sensors.end())
        throw std::runtime_error(name.empty() ? "a bag topic without a sensor name (" + topic +
                                                    ") needs a one-sensor rig: give SENSOR=TOPIC"
                                              : "a bag topic for '" + name + "', which is not a lidar of the rig");
    for (std::size_t k = 0; k < sensors.size(); ++k) {
      // --topic SENSOR=TOPIC, else the sensor's source.topic, else the bag's only lidar topic.
      if (const auto t = options.bag_topics.find(sensors[k]); t != options.bag_topics.end()) in.topic = t->second;
      else if (const auto any = options.bag_topics.find(""); any != options.bag_topics.end()) in.topic = any->second;
      else in.topic.clear();
      drivers.push_back(std::make_unique<pipeline::SensorDriver>(
          rig.sensor(sensors[k]), in, collect.stop, [&collect, k](Scan&& scan) {
            collect.pollOuterStop();
            collect.add(k, std::move(scan));
          }));
    }
    for (std::size_t k = 0; k < drivers.size(); ++k)
      threads.emplace_back([&, k] {
        drivers[k]->run([&collect] { collect.pollOuterStop(); });
        if (k == 0) collect.mappingEnded();
      });
    for (auto& t : threads) t.join();
  }

  StaticCaptureResult r = collect.result();
  for (std::size_t k = 0; k < drivers.size(); ++k) {
    const auto& a = drivers[k]->assemblerStats();
    const auto& src = drivers[k]->sourceStats();
    pipeline::SensorInput in;
    in.sensor = sensors[k];
    in.packets = a.packets;
    in.lost_packets = a.lost_packets;
    in.malformed = a.malformed + src.malformed;
    in.late_dropped = a.late_dropped;
    in.fragments_dropped = src.fragments_dropped;
    in.last_error = a.last_error;
    in.warning = drivers[k]->warning();
    in.clock_lag_ms = drivers[k]->clockLagMs();
    r.inputs.push_back(std::move(in));
  }
  return r;
}

}  // namespace rigcal::app
