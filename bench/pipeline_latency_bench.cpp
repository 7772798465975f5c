// pipeline_latency_bench: the online pipeline's per-stage latency (scan complete → stage exit) at 1× real
// time, pinned to 2 cores, with 1, 2 and 3 lidars (parking-lot: OS1-64 mapping + two VLP-16), and the
// highest sustainable offline rate (× real time). Baseline in the same run: the mapper alone, serially
// (scan-to-pose compute time with nothing else running) — the floor the pipelined scan-to-pose p99 is
// compared with. Plain main(): the pipeline's threads and the pacing do not fit Google Benchmark's loop.
//
//   taskset -c 0,1 build/bench/pipeline_latency_bench [--seconds 12] [--baseline-only | --view-only]
#include <sched.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <string>
#include <thread>
#include <vector>

#include "rigcal/config/rig_config.hpp"
#include "rigcal/pipeline/latency_histogram.hpp"
#include "rigcal/pipeline/mapper.hpp"
#include "rigcal/pipeline/pipeline.hpp"
#include "rigcal/sim/outputs.hpp"
#include "rigcal/sim/simulation.hpp"
#include "rigcal/view/live_view.hpp"
#include "rigcal/view/view_server.hpp"

#include <boost/asio/ip/tcp.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/websocket.hpp>

using namespace rigcal;
namespace fs = std::filesystem;

namespace {

struct Recorded : sim::SimulationSink {
  std::vector<Scan> scans;  // in the simulation's order (time order per sensor, chunks interleaved)
  void onScan(sim::SimulatedScan&& s) override { scans.push_back(std::move(s.scan)); }
};

std::string loadavg() {
  std::ifstream f("/proc/loadavg");
  std::string a, b, c;
  f >> a >> b >> c;
  return a + " " + b + " " + c;
}

double ms(std::int64_t ns) { return double(ns) * 1e-6; }

std::int64_t processCpuNs() {
  timespec t{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return std::int64_t(t.tv_sec) * 1'000'000'000 + t.tv_nsec;
}

void printStage(const char* label, const pipeline::LatencyHistogram& h) {
  std::printf("  %-26s n=%5llu  p50 %8.2f ms  p99 %8.2f ms  max %8.2f ms\n", label,
              static_cast<unsigned long long>(h.count()), ms(h.quantile(0.5)), ms(h.quantile(0.99)), ms(h.max()));
}

std::vector<Scan> only(const std::vector<Scan>& all, const std::vector<std::string>& sensors) {
  std::vector<Scan> out;
  for (const auto& s : all)
    if (std::find(sensors.begin(), sensors.end(), s.sensor_id) != sensors.end()) out.push_back(s);
  return out;
}

/// Feeds the scans at 1× their stamps (a scan is pushed when its last point would have arrived).
pipeline::PipelineStats realtime(const config::RigConfig& rig, const std::vector<Scan>& scans, std::uint64_t* registered,
                                 std::shared_ptr<pipeline::PipelineObserver> observer = nullptr) {
  pipeline::PipelineOptions o;
  o.observer = std::move(observer);
  o.mode = pipeline::PipelineMode::kRealtime;
  o.cores = {0, 1};
  pipeline::Pipeline p(rig, o);
  TimeNs first = INT64_MAX;
  for (const auto& s : scans) first = std::min(first, s.stamp_ns);
  const auto start = std::chrono::steady_clock::now();
  for (const auto& s : scans) {
    const auto due = start + std::chrono::nanoseconds(s.endTime() - first);
    std::this_thread::sleep_until(due);
    p.push(s);
  }
  p.finish();
  *registered = p.progress().registered;
  return p.stats();
}

/// A browser stand-in: one WebSocket client reading everything the view sends, on its own thread.
class ViewClient {
 public:
  explicit ViewClient(std::uint16_t port) : ws_(io_) {
    boost::beast::get_lowest_layer(ws_).connect({boost::asio::ip::make_address("127.0.0.1"), port});
    ws_.handshake("127.0.0.1", "/ws");
    readNext();
    thread_ = std::thread([this] { io_.run(); });
  }
  ~ViewClient() { stopAndJoin(); }
  /// Stops reading; returns the bytes received.
  std::size_t stopAndJoin() {
    io_.stop();
    if (thread_.joinable()) thread_.join();
    return bytes_;
  }

 private:
  void readNext() {
    ws_.async_read(buffer_, [this](boost::beast::error_code ec, std::size_t n) {
      if (ec) return;
      bytes_ += n;
      buffer_.consume(buffer_.size());
      readNext();
    });
  }
  boost::asio::io_context io_;
  boost::beast::websocket::stream<boost::beast::tcp_stream> ws_;
  boost::beast::flat_buffer buffer_;
  std::size_t bytes_ = 0;  // the client thread's until joined
  std::thread thread_;
};

double scanToPoseP99Ms(const pipeline::PipelineStats& stats) {
  for (const auto& st : stats.stages)
    if (st.name == "mapper") return ms(st.latency.quantile(0.99));
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  std::setvbuf(stdout, nullptr, _IOLBF, 0);  // progress lines as they come, also into a file
  double seconds = 12.0;
  bool baseline_only = false;
  bool view_only = false;
  for (int i = 1; i < argc; ++i) {
    if (std::strcmp(argv[i], "--seconds") == 0 && i + 1 < argc) seconds = std::stod(argv[i + 1]);
    if (std::strcmp(argv[i], "--baseline-only") == 0) baseline_only = true;
    if (std::strcmp(argv[i], "--view-only") == 0) view_only = true;  // only the with/without live view rounds
  }

  sim::Simulation simulation(sim::loadScenario("parking-lot"));
  const fs::path dir = fs::temp_directory_path() / ("pipeline_latency_bench_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  sim::writeRigFiles(simulation, dir);
  config::RigConfig rig = config::loadRigConfig(dir / "rig.yaml");
  fs::remove_all(dir);
  Recorded rec;
  sim::SimulationOptions so;
  so.max_duration_ns = fromSeconds(seconds);
  simulation.run(rec, so);
  std::printf("pipeline_latency_bench: parking-lot, first %.1f s (%zu scans), loadavg before: %s\n", seconds,
              rec.scans.size(), loadavg().c_str());

  // Baseline: the mapper alone, serially, on one thread (no queues, no other stage).
  {
    pipeline::Mapper mapper(rig.parameters);
    pipeline::LatencyHistogram h;
    std::vector<std::pair<std::int64_t, std::uint64_t>> slowest;  // (ns, scan sequence): where the tail is
    const auto cpu0 = std::clock();
    for (const auto& s : rec.scans) {
      if (s.sensor_id != rig.roles.mapping_lidar) continue;
      const auto t0 = std::chrono::steady_clock::now();
      const std::int64_t c0 = processCpuNs();
      mapper.process(s);
      const auto ns = std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now() - t0).count();
      h.record(ns);
      // CPU, not wall: on a loaded machine the wall tail is other processes' time slices.
      slowest.emplace_back(processCpuNs() - c0, s.sequence);
    }
    std::sort(slowest.rbegin(), slowest.rend());
    std::printf("most CPU-hungry mapper scans, all threads (sequence: CPU ms):");
    for (std::size_t i = 0; i < std::min<std::size_t>(6, slowest.size()); ++i)
      std::printf(" %llu: %.1f", static_cast<unsigned long long>(slowest[i].second), ms(slowest[i].first));
    std::printf("\n");
    std::printf("baseline (mapper alone, serial, compute only): %.1f ms CPU per scan\n",
                1e3 * double(std::clock() - cpu0) / CLOCKS_PER_SEC / double(std::max<std::uint64_t>(1, h.count())));
    printStage("mapper process()", h);
  }

  // The same serially, as the pipeline runs it: the pose is out when process() returns; the stored
  // frame's dense cloud and the keyframe's local-map feed follow (finishFrame, not timed).
  {
    pipeline::Mapper mapper(rig.parameters);
    mapper.deferPostPoseWork(true);
    pipeline::LatencyHistogram h;
    for (const auto& s : rec.scans) {
      if (s.sensor_id != rig.roles.mapping_lidar) continue;
      const auto t0 = std::chrono::steady_clock::now();
      pipeline::MapperOutput out = mapper.process(s);
      h.record(std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now() - t0).count());
      mapper.finishFrame(out);
    }
    printStage("mapper scan-to-pose only", h);
  }

  if (baseline_only) return 0;
  const std::vector<std::vector<std::string>> setups = {
      {"top"}, {"top", "front_left"}, {"top", "front_left", "front_right"}};
  for (const auto& sensors : setups) {
    if (view_only) break;
    config::RigConfig r = rig;
    r.roles.calibration_lidars.assign(sensors.begin() + 1, sensors.end());
    const auto scans = only(rec.scans, sensors);
    std::uint64_t registered = 0;
    const auto stats = realtime(r, scans, &registered);
    std::printf("1x real time, %zu lidar(s), pinned to cores 0,1 (loadavg %s):\n", sensors.size(), loadavg().c_str());
    for (const auto& st : stats.stages) {
      if (st.latency.count() == 0) continue;
      const std::string label = st.name == "mapper" ? "mapper (scan-to-pose)" : st.name;
      printStage(label.c_str(), st.latency);
    }
    std::uint64_t dropped = 0;
    for (const auto& q : stats.queues) dropped += q.dropped;
    double cpu = 0;
    for (const auto& st : stats.stages) cpu += st.cpu_seconds;
    std::printf("  dropped %llu, registered %llu of the mapping scans, CPU %.2f s over %.2f s wall\n",
                static_cast<unsigned long long>(dropped), static_cast<unsigned long long>(registered), cpu,
                stats.wall_seconds);
  }

  // The live view (--view) must not slow the pipeline: 3 lidars at 1x, alternately without and with a
  // view whose one client reads everything, twice each, in this same run.
  for (int round = 0; round < 2; ++round) {
    for (const bool with_view : {false, true}) {
      std::uint64_t registered = 0;
      pipeline::PipelineStats stats;
      std::size_t client_bytes = 0;
      std::uint64_t view_dropped = 0;
      if (with_view) {
        view::ViewServer server(view::ViewEndpoint{"127.0.0.1", 0});
        auto live = std::make_shared<view::LiveView>(server, "bench", rig.roles.calibration_lidars);
        {
          ViewClient client(server.port());
          std::this_thread::sleep_for(std::chrono::milliseconds(100));  // connected before the first scan
          stats = realtime(rig, rec.scans, &registered, live);
          live->finish();
          std::this_thread::sleep_for(std::chrono::milliseconds(300));
          client_bytes = client.stopAndJoin();
        }
        view_dropped = live->droppedUpdates();
      } else {
        stats = realtime(rig, rec.scans, &registered);
      }
      std::printf("1x real time, 3 lidars, %s: scan-to-pose p99 %.2f ms, registered %llu", with_view ? "live view + 1 client" : "no view           ",
                  scanToPoseP99Ms(stats), static_cast<unsigned long long>(registered));
      if (with_view) std::printf(", client got %.1f MB, view dropped %llu updates", double(client_bytes) / 1e6,
                                 static_cast<unsigned long long>(view_dropped));
      std::printf(" (loadavg %s)\n", loadavg().c_str());
    }
  }

  // Offline: as fast as possible, lossless; the rate is recorded time / wall time.
  if (!view_only) {
    pipeline::PipelineOptions o;
    o.cores = {0, 1};
    const auto t0 = std::chrono::steady_clock::now();
    pipeline::Pipeline p(rig, o);
    for (const auto& s : rec.scans) p.push(s);
    p.finish();
    const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    std::printf("offline, 3 lidars, pinned to cores 0,1: %.2f s of recording in %.2f s wall = %.2fx real time "
                "(loadavg %s)\n", seconds, wall, seconds / wall, loadavg().c_str());
  }
  return 0;
}
