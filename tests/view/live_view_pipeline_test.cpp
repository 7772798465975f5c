// The pipeline with a live view attached: a simulated parking-lot segment in process, one browser-like
// client reading and one that stopped reading. The pipeline's results equal a run without a view
// (offline mode is deterministic), the reading client gets the map, the trajectory, the candidates and
// the final counters, and the stalled client's queue stays within its bound.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <thread>

#include "rigcal/view/live_view.hpp"
#include "rigcal/view/update_encoding.hpp"
#include "rigcal/view/view_server.hpp"
#include "sanitizers.hpp"
#include "sim_pipeline_util.hpp"
#include "view_client.hpp"

namespace rigcal::view {
namespace {

struct Recorded : sim::SimulationSink {
  std::vector<Scan> scans;
  void onScan(sim::SimulatedScan&& s) override { scans.push_back(std::move(s.scan)); }
};

TEST(LiveViewPipeline, FeedsClientsWithoutChangingThePipeline) {
  rigcal::test::TempDir dir;
  const sim::Simulation sim(sim::loadScenario("parking-lot"));
  const config::RigConfig rig = pipeline::test::rigFor(sim, dir.path());
  Recorded recorded;
  sim::SimulationOptions so;
  so.max_duration_ns = fromSeconds(rigcal::test::kSanitized ? 3.0 : 6.0);
  sim.run(recorded, so);
  ASSERT_FALSE(recorded.scans.empty());
  const auto feed = [&](pipeline::Pipeline& p) {
    for (const auto& s : recorded.scans) p.push(s);
  };

  const pipeline::test::RunResult plain = pipeline::test::runPipeline(rig, {}, feed);

  ServerLimits limits;
  limits.session_queue_bytes = 4u << 20;
  ViewServer server(ViewEndpoint{"127.0.0.1", 0}, limits);
  auto live = std::make_shared<LiveView>(server, "map", rig.roles.calibration_lidars);
  test::WsClient stalled(server.port());  // never reads
  test::WsClient reader(server.port());
  std::size_t map_points = 0, poses = 0, candidates = 0;
  nlohmann::json last_counters = nlohmann::json::object();
  ASSERT_TRUE(test::waitForSessions(server, 2));
  std::thread client([&] {
    // Until the final counters (a minute without any message is a failure: they never came).
    while (!last_counters.value("finished", false)) {
      auto m = reader.read(std::chrono::milliseconds(60'000));
      if (!m) return;
      if (!m->binary) {
        auto j = nlohmann::json::parse(m->data);
        if (j["type"] == "counters") last_counters = j;
        continue;
      }
      const auto d = decodeUpdate(m->data);
      if (!d) continue;
      const std::size_t n = d->values.size() / strideOf(d->kind);
      if (d->kind == UpdateKind::kMapPoints) map_points += n;
      if (d->kind == UpdateKind::kTrajectory) poses += n;
      if (d->kind == UpdateKind::kCandidate) candidates += n;
    }
  });

  pipeline::PipelineOptions options;
  options.observer = live;
  pipeline::test::RunResult viewed;
  {
    std::mutex m;
    pipeline::Pipeline p(rig, options, [&](std::shared_ptr<const pipeline::CalibrationDataset> d) {
      std::lock_guard lock(m);
      viewed.datasets.push_back(std::move(d));
    });
    live->setProgressSource([&p] { return p.progress(); });
    feed(p);
    p.finish();
    live->finish();
    viewed.progress = p.progress();
  }
  client.join();

  EXPECT_EQ(viewed.progress.registered, plain.progress.registered);
  EXPECT_EQ(viewed.progress.keyframes, plain.progress.keyframes);
  EXPECT_EQ(viewed.datasets.size(), plain.datasets.size());
  for (std::size_t i = 0; i < viewed.progress.lidars.size(); ++i)
    EXPECT_EQ(viewed.progress.lidars[i].selected, plain.progress.lidars[i].selected);

  ASSERT_TRUE(last_counters.is_object());
  EXPECT_TRUE(last_counters["finished"].get<bool>());
  EXPECT_EQ(last_counters["registered"].get<std::uint64_t>(), viewed.progress.registered);
  EXPECT_EQ(last_counters["keyframes"].get<std::uint64_t>(), viewed.progress.keyframes);
  EXPECT_GT(map_points, 1000u);
  // Every registered frame's pose reached the reader unless the view dropped it (counted).
  EXPECT_EQ(poses + live->droppedUpdates() >= viewed.progress.registered, true)
      << poses << " poses, " << live->droppedUpdates() << " dropped, " << viewed.progress.registered << " registered";
  if (viewed.progress.lidars[0].candidates > 0) {
    EXPECT_GT(candidates, 0u);
  }
  const ServerStats s = server.stats();
  // The stalled client holds at most its bound (kernel socket buffers take the first megabytes; the flood
  // that makes it drop is ViewServer.AClientThatStopsReadingCostsBoundedMemoryAndDelaysNobody).
  EXPECT_LE(s.max_pending_bytes, limits.session_queue_bytes);
}

}  // namespace
}  // namespace rigcal::view
