#include "rigcal/view/live_view.hpp"

#include <chrono>
#include <cmath>
#include <nlohmann/json.hpp>

#include "rigcal/view/update_encoding.hpp"

namespace rigcal::view {

namespace {

FrameCode codeOf(const pipeline::MappingFrame& f) {
  if (f.lost) return FrameCode::kLost;
  if (f.kind == pipeline::FrameKind::kStopped || f.kind == pipeline::FrameKind::kStoppedKeyframe) return FrameCode::kStopped;
  if (f.isKeyframe()) return FrameCode::kKeyframe;
  return FrameCode::kFrame;
}

/// 21 bits per axis of a voxel index: ±100 km at 0.1 m.
std::uint64_t cellKey(const Eigen::Vector3d& p, double voxel) {
  const auto axis = [&](double v) { return std::uint64_t(std::int64_t(std::floor(v / voxel)) & 0x1FFFFF); };
  return axis(p.x()) | (axis(p.y()) << 21) | (axis(p.z()) << 42);
}

}  // namespace

std::string countersJson(const pipeline::PipelineProgress& p, const std::string& mode, bool finished,
                         std::uint64_t view_dropped) {
  nlohmann::json j;
  j["type"] = "counters";
  j["mode"] = mode;
  j["finished"] = finished;
  j["mapping_scans"] = p.mapping_scans;
  j["registered"] = p.registered;
  j["keyframes"] = p.keyframes;
  j["stopped_frames"] = p.stopped_frames;
  j["lost_frames"] = p.lost_frames;
  j["budget_fill"] = p.budgetFill();
  j["view_dropped"] = view_dropped;
  j["line"] = p.line();
  auto lidars = nlohmann::json::array();
  for (const auto& l : p.lidars)
    lidars.push_back({{"sensor", l.sensor}, {"scans", l.scans}, {"candidates", l.candidates}, {"accepted", l.accepted},
                      {"selected", l.selected}, {"budget", l.budget}, {"handed_over", l.handed_over}});
  j["lidars"] = lidars;
  return j.dump();
}

LiveView::LiveView(ViewServer& server, std::string mode, std::vector<std::string> lidars, LiveViewOptions options)
    : server_(server), mode_(std::move(mode)), lidars_(std::move(lidars)), options_(options), queue_(options.queue_capacity) {
  server_.publish(nlohmann::json{{"type", "lidars"}, {"names", lidars_}}.dump(), false, true);
  thread_ = std::thread([this] { loop(); });
}

LiveView::~LiveView() {
  // No final counters here: the pipeline they come from may be gone already (finish() sends them).
  stop_.store(true);
  queue_.close();
  if (thread_.joinable()) thread_.join();
}

void LiveView::onFrame(const pipeline::MappingFrame& frame, const std::shared_ptr<const Scan>& cloud) {
  // Only keyframes' points go to the map; the other frames need just their pose.
  queue_.tryPush(FrameEvent{frame, frame.isKeyframe() ? cloud : nullptr});
}

void LiveView::onCandidate(pipeline::CandidateEvent event) { queue_.tryPush(std::move(event)); }

void LiveView::setProgressSource(std::function<pipeline::PipelineProgress()> source) {
  std::lock_guard lock(source_mutex_);
  progress_source_ = std::move(source);
}

void LiveView::finish() {
  if (stop_.exchange(true)) return;
  queue_.close();
  if (thread_.joinable()) thread_.join();
  publishCounters(true);
  std::lock_guard lock(source_mutex_);
  progress_source_ = nullptr;
}

void LiveView::loop() {
  auto next_counters = std::chrono::steady_clock::now();
  const auto period = std::chrono::milliseconds(options_.counters_period_ms);
  while (true) {
    auto event = queue_.pop(period);
    if (event) std::visit([this](const auto& e) { handle(e); }, *event);
    else if (stop_.load()) return;  // closed and drained
    if (std::chrono::steady_clock::now() >= next_counters) {
      publishCounters(false);
      next_counters = std::chrono::steady_clock::now() + period;
    }
  }
}

void LiveView::handle(const FrameEvent& e) {
  const Eigen::Vector3d t = e.frame.T_map_lidar.translation();
  server_.publish(encodeUpdate(UpdateKind::kTrajectory, kNoLane,
                               {float(t.x()), float(t.y()), float(t.z()), float(static_cast<int>(codeOf(e.frame)))}),
                  true, true);
  published_.fetch_add(1);
  if (!e.cloud) return;
  std::vector<float> points;
  const Scan& s = *e.cloud;
  for (std::size_t i = 0; i < s.size(); ++i) {
    const Eigen::Vector3d p = e.frame.T_map_lidar * Eigen::Vector3d(s.x[i], s.y[i], s.z[i]);
    if (!p.allFinite() || !sent_cells_.insert(cellKey(p, options_.map_voxel_m)).second) continue;
    points.insert(points.end(), {float(p.x()), float(p.y()), float(p.z())});
  }
  if (points.empty()) return;
  server_.publish(encodeUpdate(UpdateKind::kMapPoints, kNoLane, points), true, true);
  published_.fetch_add(1);
}

void LiveView::handle(const pipeline::CandidateEvent& e) {
  const auto lane = static_cast<std::uint8_t>(e.lane);
  server_.publish(encodeUpdate(UpdateKind::kCandidate, lane,
                               {e.position.x(), e.position.y(), e.position.z(), e.accepted ? 1.0f : 0.0f}),
                  true, true);
  std::vector<float> selected;
  for (const auto& p : e.selected) selected.insert(selected.end(), {p.x(), p.y(), p.z()});
  // The latest selection replaces the earlier ones: keep it for late clients too (small).
  server_.publish(encodeUpdate(UpdateKind::kSelected, lane, selected), true, true);
  published_.fetch_add(2);
}

void LiveView::publishCounters(bool finished) {
  std::lock_guard lock(source_mutex_);
  if (!progress_source_) return;
  server_.publishStatus(countersJson(progress_source_(), mode_, finished, queue_.dropped()));
}

}  // namespace rigcal::view
