#pragma once
// The pipeline's side of the live view: a PipelineObserver whose callbacks (on the mapper and selector
// threads) only try to queue the event (UpdateQueue: full means dropped and counted, never a wait). The
// view's own thread turns events into messages (keyframe points transformed into the map frame and
// decimated on a voxel grid, so each map cell is sent once), publishes them, and every 250 ms publishes
// the counters of the progress line.
#include <atomic>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <unordered_set>
#include <variant>
#include <vector>

#include "rigcal/pipeline/pipeline.hpp"
#include "rigcal/pipeline/pipeline_observer.hpp"
#include "rigcal/view/update_queue.hpp"
#include "rigcal/view/view_server.hpp"

namespace rigcal::view {

struct LiveViewOptions {
  double map_voxel_m = 0.25;        // one map point per cell of this size is sent
  std::size_t queue_capacity = 256; // events waiting for the view thread; more are dropped
  int counters_period_ms = 250;
};

class LiveView : public pipeline::PipelineObserver {
 public:
  /// `lidars`: the rig's calibration lidars, in the pipeline's lane order. `server` must outlive this.
  LiveView(ViewServer& server, std::string mode, std::vector<std::string> lidars, LiveViewOptions options = {});
  ~LiveView() override;  // stops the view thread (without the final counters: call finish())
  LiveView(const LiveView&) = delete;
  LiveView& operator=(const LiveView&) = delete;

  void onFrame(const pipeline::MappingFrame& frame, const std::shared_ptr<const Scan>& cloud) override;
  void onCandidate(pipeline::CandidateEvent event) override;

  /// Where the counters come from (Pipeline::progress); set once the pipeline exists.
  void setProgressSource(std::function<pipeline::PipelineProgress()> source);
  /// Publishes what is queued and the final counters (`"finished": true`), then stops the view thread.
  void finish();

  [[nodiscard]] std::uint64_t droppedUpdates() const { return queue_.dropped(); }
  [[nodiscard]] std::uint64_t publishedUpdates() const { return published_.load(); }

 private:
  struct FrameEvent {
    pipeline::MappingFrame frame;
    std::shared_ptr<const Scan> cloud;
  };
  using Event = std::variant<FrameEvent, pipeline::CandidateEvent>;

  void loop();
  void handle(const FrameEvent& e);
  void handle(const pipeline::CandidateEvent& e);
  void publishCounters(bool finished);

  ViewServer& server_;
  const std::string mode_;
  const std::vector<std::string> lidars_;
  const LiveViewOptions options_;
  UpdateQueue<Event> queue_;
  std::mutex source_mutex_;
  std::function<pipeline::PipelineProgress()> progress_source_;
  std::unordered_set<std::uint64_t> sent_cells_;  // view thread only
  std::atomic<std::uint64_t> published_{0};
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

/// The counters of the progress line as the page shows them (JSON text message {"type":"counters",...}).
std::string countersJson(const pipeline::PipelineProgress& p, const std::string& mode, bool finished,
                         std::uint64_t view_dropped);

}  // namespace rigcal::view
