#pragma once
// The online pipeline: ingest → deskew → mapper (mapping lidar) → pairing (calibration lidars) →
// selector, as stage threads joined by BoundedQueues. It hands one CalibrationDataset per calibration
// lidar to a callback as soon as that lidar's frame budget is full, and at end of input for every lidar
// with at least lidar_calibration_min_frames (the others are reported in shortfalls()).
//
// Input, one of:
//  (a) in process: push() decoded scans (tests, the simulator), then finish();
//  (b) driver threads: pcap or live UDP through SensorDriver (the code path of `rigcal driver`);
//  (c) shared memory: the ScanRings written by `rigcal driver` processes.
// Offline mode is lossless, in order and deterministic (two runs give the same frames); real-time mode
// never blocks a driver: its queues drop the oldest work and count it.
#include <atomic>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "rigcal/config/rig_config.hpp"
#include "rigcal/core/scan.hpp"
#include "rigcal/pipeline/calibration_dataset.hpp"
#include "rigcal/pipeline/latency_histogram.hpp"
#include "rigcal/pipeline/mapping_frame.hpp"
#include "rigcal/pipeline/pipeline_observer.hpp"

namespace rigcal::pipeline {

enum class PipelineMode : std::uint8_t {
  kOffline,   // lossless: a full queue makes its producer wait
  kRealtime,  // never blocks the input: a full queue drops its oldest item (counted)
};

enum class InputKind : std::uint8_t {
  kInProcess,  // push() / finish()
  kPcap,       // driver threads read `pcap` (rate 0: as fast as possible, 1: recorded timing)
  kLive,       // driver threads on the sensors' UDP ports
  kShm,        // ScanRings written by `rigcal driver` processes
  kBag,        // driver threads read `bag` (a ROS 2 bag: packet or PointCloud2 topics), paced as a pcap
};

/// A recording (pcap or bag): offline by default, replayed at `rate`.
inline bool isRecording(InputKind k) { return k == InputKind::kPcap || k == InputKind::kBag; }

struct PipelineOptions {
  PipelineMode mode = PipelineMode::kOffline;
  InputKind input = InputKind::kInProcess;
  std::filesystem::path pcap;              // kPcap
  double rate = 0.0;                       // kPcap, kBag: replay speed (0 = as fast as possible)
  std::filesystem::path bag;               // kBag
  /// kBag: sensor name → topic; the key "" names the topic of a one-sensor rig. A sensor not named here
  /// reads its rig source.topic, else the bag's only lidar topic.
  std::map<std::string, std::string> bag_topics;
  std::optional<std::string> shm_prefix;   // kShm: default $RIGCAL_SHM_PREFIX, else "rigcal."
  bool wait_for_writers = false;           // kShm: keep waiting when every ring writer is gone
  std::vector<int> cores;                  // pin every pipeline thread to these cores (empty: no pinning)
  std::size_t queue_capacity = 32;         // per queue, in scans
  std::shared_ptr<PipelineObserver> observer;  // the live view (optional): called on the stage threads
};

/// Per calibration lidar.
struct LidarProgress {
  std::string sensor;
  std::uint64_t scans = 0;       // scans received
  std::uint64_t candidates = 0;  // pairings considered
  std::uint64_t accepted = 0;    // pairings passing the interpolation criteria and size filters
  std::uint64_t selected = 0;    // frames the selector holds now
  int budget = 0;                // lidar_calibration_max_frames
  bool handed_over = false;      // its dataset went to the callback
  std::uint64_t lost_packets = 0;  // the packets its scans say were lost (any input: pcap, live, rings)
  /// Packets its driver dropped as malformed so far (pcap, bag, live; for a shared-memory ring, as its
  /// driver process had counted them when it published the newest scan read).
  std::uint64_t malformed_packets = 0;
};

struct PipelineProgress {
  std::uint64_t mapping_scans = 0;  // mapping-lidar scans received
  std::uint64_t registered = 0;     // scans through the mapper
  std::uint64_t skipped = 0;        // scans the mapper skipped: too few points, an incomplete seed sweep, map full
  std::uint64_t stored_frames = 0;
  std::uint64_t keyframes = 0;
  std::uint64_t stopped_frames = 0;
  std::uint64_t lost_frames = 0;
  bool mapping_done = false;  // mapping_max_frames reached: the mapper stopped by itself
  std::string mapping_sensor;
  std::uint64_t mapping_lost_packets = 0;  // as LidarProgress::lost_packets, for the mapping lidar
  std::uint64_t mapping_malformed_packets = 0;  // as LidarProgress::malformed_packets
  std::vector<LidarProgress> lidars;
  /// Mean budget fill over the calibration lidars, 0..1.
  [[nodiscard]] double budgetFill() const;
  /// One line for a terminal: "scans 812 | kf 41 lost 0 | left 6/10 (cand 30) | right 10/10 ✓".
  [[nodiscard]] std::string line() const;
};

/// What the mapper built.
struct MappingResult {
  std::string mapping_sensor;
  Pose T_base_mapping = Pose::Identity();    // initial, from the rig config
  std::vector<MappingFrame> trajectory;       // every registered frame (stored, stopped, dropped, lost), in order
  /// The whole map in the map frame (= the first mapping-lidar frame), voxelised at leaf_size_local_map.
  std::shared_ptr<const Scan> map_cloud;
  /// Only when asked for (Pipeline::mapping(true): it costs seconds on a long run): the clouds of the last
  /// dense_pointcloud_num_keyframes keyframes (only keyframes have one), in the map frame, voxelised at
  /// leaf_size_dense_map. Empty while no keyframe exists; nullptr when not asked for.
  std::shared_ptr<const Scan> dense_cloud;
  int last_keyframe_frame = -1;  // index into `trajectory` of the keyframe `dense_cloud` is centred on
};

struct StageStats {
  std::string name;            // "ingest", "deskew", "mapper", "pairing", "selector", "driver:<sensor>"
  LatencyHistogram latency;    // scan end (last point, or packet arrival / publish) → this stage's exit
  std::uint64_t processed = 0;
  double cpu_seconds = 0.0;
};

struct QueueStats {
  std::string name;  // "<from>→<to>"
  std::size_t capacity = 0;
  std::size_t depth = 0;
  std::size_t max_depth = 0;
  std::uint64_t dropped = 0;
};

struct PipelineStats {
  double wall_seconds = 0.0;
  std::vector<StageStats> stages;
  std::vector<QueueStats> queues;
  std::uint64_t input_dropped_scans = 0;  // lost before the pipeline (ring overruns, assembler losses)
  [[nodiscard]] std::string table() const;
  [[nodiscard]] std::string json() const;
};

/// A calibration lidar that did not get enough frames by the end of input.
struct Shortfall {
  std::string sensor;
  int selected = 0;
  int required = 0;     // lidar_calibration_min_frames
  std::string message;  // "1 of 2 frames for left: drive further or lower lidar_calibration_min_frames"
};

/// One sensor's input as its driver saw it (pcap, live or ring input; complete after finish()): what a damaged
/// capture or a lossy network cost, and the sensor's clock against the capture / receive time.
struct SensorInput {
  std::string sensor;
  std::uint64_t packets = 0;            // data packets decoded
  std::uint64_t lost_packets = 0;       // gaps in the sensor's packet sequence
  std::uint64_t malformed = 0;          // packets and frames dropped as malformed (decoder and source)
  std::uint64_t late_dropped = 0;       // packets older than one already assembled
  std::uint64_t reordered = 0;          // packets that came after a later one (put back in order unless late)
  std::uint64_t foreign_packets = 0;    // packets of another model on its port, ignored
  std::string foreign;                  // ForeignPackets::describe(), when foreign_packets > 0
  std::uint64_t fragments_dropped = 0;  // IPv4 fragments never completed (of every sensor in the capture)
  std::string last_error;               // the latest malformed packet's reason
  std::string warning;                  // the capture ended abnormally (e.g. truncated mid-record)
  std::optional<double> clock_lag_ms;   // SensorDriver::clockLagMs()
  double clock_lag_sigma_ms = 0.0;      // the standard error of clock_lag_ms (ClockLag::sigma_ms)
  std::size_t clock_lag_sweeps = 0;
  [[nodiscard]] bool damaged() const {
    return lost_packets + malformed + late_dropped + foreign_packets > 0 || !warning.empty();
  }
};

class Pipeline {
 public:
  /// Called on the selector thread, once per calibration lidar. Return quickly (hand the dataset to
  /// another thread): the selector waits for it. The pointer is the pipeline's only reference (it keeps
  /// none): a receiver that drops it frees the dataset's clouds the pipeline does not store any more.
  using DatasetCallback = std::function<void(std::shared_ptr<const CalibrationDataset>)>;

  /// Starts the stage threads. Throws std::runtime_error (one line) when a sensor of the rig cannot be
  /// set up for the chosen input.
  Pipeline(const config::RigConfig& rig, const PipelineOptions& options, DatasetCallback on_dataset = {});
  ~Pipeline();  // stops and joins everything
  Pipeline(const Pipeline&) = delete;
  Pipeline& operator=(const Pipeline&) = delete;

  /// (a) Feeds one decoded scan; scan.sensor_id names a rig sensor (others are counted and ignored).
  /// One thread per sensor may call it. Offline: waits for room; real time: never waits.
  void push(Scan scan);

  /// (b)/(c) Runs the driver threads or ring readers until the input ends (pcap end; every ring's writer
  /// gone after it wrote) or `stop` is set, then finishes. Not for kInProcess.
  void run(const std::atomic<bool>& stop);

  /// End of input: drains every stage, hands over the datasets of lidars with enough frames, joins the
  /// threads. Idempotent; run() calls it.
  void finish();

  [[nodiscard]] PipelineProgress progress() const;  // any thread, any time
  [[nodiscard]] PipelineStats stats() const;        // any thread; exact after finish()
  /// A snapshot; complete after finish(). `with_dense_cloud` also merges the dense cloud (seconds).
  [[nodiscard]] MappingResult mapping(bool with_dense_cloud = false) const;
  [[nodiscard]] std::vector<Shortfall> shortfalls() const;  // after finish()
  /// After finish(); empty for kInProcess. For kShm, one per ring as its driver process counted (the tally
  /// in the newest scan read, from the first scan read if the driver was already running, summed over
  /// restarted writers; no clock lag, last error or capture warning).
  [[nodiscard]] std::vector<SensorInput> inputs() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace rigcal::pipeline
