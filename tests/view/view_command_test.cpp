// `rigcal view OUT_DIR` as a real process: its usage and input errors, and a finished run's folder served
// over HTTP and the WebSocket.
#include <gtest/gtest.h>

#include <csignal>
#include <fstream>
#include <thread>

#include "rigcal/view/update_encoding.hpp"
#include "rigcal/view/view_server.hpp"
#include "run_command.hpp"
#include "view_client.hpp"

namespace rigcal::view {
namespace {

namespace fs = std::filesystem;

void writeText(const fs::path& file, const std::string& text) { std::ofstream(file) << text; }

/// An ASCII PCD of `n` points on a line.
void writeCloud(const fs::path& file, int n, float offset) {
  std::string text = "VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nWIDTH " + std::to_string(n) +
                     "\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS " + std::to_string(n) + "\nDATA ascii\n";
  for (int i = 0; i < n; ++i) text += std::to_string(float(i) + offset) + " 1 0\n";
  writeText(file, text);
}

std::uint16_t freePort() {
  ViewServer probe(ViewEndpoint{"127.0.0.1", 0});
  return probe.port();
}

TEST(ViewCommand, RefusesAMissingFolderABadAddressAndAFolderWithoutReport) {
  rigcal::test::TempDir dir;
  auto r = rigcal::test::runRigcal({"view", (dir / "missing").string()});
  EXPECT_EQ(r.exit_code, 4) << r.err;
  EXPECT_NE(r.err.find("missing"), std::string::npos) << r.err;
  r = rigcal::test::runRigcal({"view", dir.path().string(), "--view", "host:80"});
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_NE(r.err.find("--view"), std::string::npos) << r.err;
  r = rigcal::test::runRigcal({"view", dir.path().string(), "--view", "127.0.0.1:0"});
  EXPECT_EQ(r.exit_code, 4) << r.err;
  EXPECT_NE(r.err.find("report.json"), std::string::npos) << r.err;
}

TEST(ViewCommand, WarnsWhenServingBeyondLoopback) {
  rigcal::test::TempDir dir;
  writeText(dir / "report.json", R"({"status":"ok","lidars":[]})");
  const auto r = rigcal::test::runRigcal({"view", dir.path().string(), "--view", "0.0.0.0:0", "--seconds", "0.2"});
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.err.find("warning: the view listens on 0.0.0.0"), std::string::npos) << r.err;
}

TEST(ViewCommand, ServesAFinishedRun) {
  rigcal::test::TempDir dir;
  const std::string report = R"({"status":"ok","lidars":[{"sensor":"left","verdict":"ok"}],"input":{"mapping_scans":"5"}})";
  writeText(dir / "report.json", report);
  writeCloud(dir / "map.pcd", 40, 0.0f);
  writeCloud(dir / "left_before.pcd", 7, 0.1f);
  writeCloud(dir / "left_after.pcd", 9, 0.2f);
  const std::uint16_t port = freePort();
  rigcal::test::RigcalProcess p({"view", dir.path().string(), "--view", "127.0.0.1:" + std::to_string(port)});
  test::HttpResult r;
  for (int i = 0; i < 200 && r.status != 200; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
    try {
      r = test::httpRequest(port, "/report.json");
    } catch (const std::exception&) {
      // not listening yet
    }
  }
  ASSERT_EQ(r.status, 200);
  EXPECT_EQ(r.body, report);
  test::WsClient ws(port);
  std::size_t map = 0, before = 0, after = 0;
  ASSERT_TRUE(ws.readUntil([&](const test::WsMessage& m) {
    if (const auto d = decodeUpdate(m.data); m.binary && d) {
      const std::size_t n = d->values.size() / 3;
      if (d->kind == UpdateKind::kMapPoints) map += n;
      if (d->kind == UpdateKind::kCloudBefore && d->lane == 0) before += n;
      if (d->kind == UpdateKind::kCloudAfter && d->lane == 0) after += n;
    }
    return !m.binary && m.data.find("\"type\":\"report\"") != std::string::npos;
  }));
  EXPECT_EQ(map, 40u);  // 1 m apart: one per 0.25 m cell
  EXPECT_EQ(before, 7u);
  EXPECT_EQ(after, 9u);
  p.kill(SIGINT);
  const auto done = p.wait();
  EXPECT_EQ(done.exit_code, 0) << done.err;
  EXPECT_NE(done.out.find("40 map points, 1 lidars"), std::string::npos) << done.out;
}

}  // namespace
}  // namespace rigcal::view
