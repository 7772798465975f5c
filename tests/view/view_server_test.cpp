// The view server on real loopback sockets: HTTP routes, refused traversal attempts, the WebSocket
// protocol round trip, late clients, many clients, and a client that stops reading.
#include <gtest/gtest.h>

#include <thread>

#include "rigcal/view/update_encoding.hpp"
#include "rigcal/view/view_server.hpp"
#include "sanitizers.hpp"
#include "view_client.hpp"

namespace rigcal::view {
namespace {

using test::httpRequest;
using test::WsClient;
using test::WsMessage;
using test::waitForSessions;

ViewEndpoint anyPort() { return ViewEndpoint{"127.0.0.1", 0}; }

bool isUpdate(const WsMessage& m, UpdateKind kind) {
  const auto d = decodeUpdate(m.data);
  return m.binary && d && d->kind == kind;
}

TEST(ViewServer, ServesItsPageAndAssets) {
  ViewServer server(anyPort());
  ASSERT_NE(server.port(), 0);
  const auto index = httpRequest(server.port(), "/");
  EXPECT_EQ(index.status, 200);
  EXPECT_NE(index.content_type.find("text/html"), std::string::npos);
  EXPECT_NE(index.body.find("/view.js"), std::string::npos);
  EXPECT_NE(index.body.find("/three.min.js"), std::string::npos);
  const auto js = httpRequest(server.port(), "/view.js?v=1");
  EXPECT_EQ(js.status, 200);
  EXPECT_NE(js.body.find("WebSocket"), std::string::npos);
  EXPECT_EQ(httpRequest(server.port(), "/view.css").status, 200);
  // Debian's three.js, served from its installed files.
  const auto three = httpRequest(server.port(), "/three.min.js");
  EXPECT_EQ(three.status, 200) << "libjs-three installed? (scripts/install-deps)";
  EXPECT_GT(three.body.size(), 100'000u);
  EXPECT_EQ(httpRequest(server.port(), "/OrbitControls.js").status, 200);
  // HEAD: the page's status and type without its body; an unknown path is still 404.
  const auto head = httpRequest(server.port(), "/", test::HttpMethod::kHead);
  EXPECT_EQ(head.status, 200);
  EXPECT_NE(head.content_type.find("text/html"), std::string::npos);
  EXPECT_TRUE(head.body.empty());
  EXPECT_EQ(httpRequest(server.port(), "/etc/passwd", test::HttpMethod::kHead).status, 404);
  EXPECT_GE(server.stats().http_requests, 7u);
}

TEST(ViewServer, ReportIsServedOnceTheRunHasOne) {
  ViewServer server(anyPort());
  EXPECT_EQ(httpRequest(server.port(), "/report.json").status, 404);
  server.publishReport(R"({"status":"ok","lidars":[]})");
  const auto r = httpRequest(server.port(), "/report.json");
  EXPECT_EQ(r.status, 200);
  EXPECT_EQ(r.body, R"({"status":"ok","lidars":[]})");
  EXPECT_EQ(r.content_type, "application/json");
}

TEST(ViewServer, RefusesPathsOutsideItsOwnRoutesAndWrites) {
  ViewServer server(anyPort());
  for (const char* target : {"/../../../../etc/passwd", "/%2e%2e/%2e%2e/etc/passwd", "/three.min.js/../../../etc/passwd",
                             "//etc/passwd", "/etc/passwd", "/view.js%00.png", "/..%2f..%2fetc%2fpasswd",
                             "/examples/js/controls/OrbitControls.js", "/usr/share/javascript/three/three.min.js",
                             "/report.json/../../etc/passwd", "/ws/../etc/passwd"}) {
    const auto r = httpRequest(server.port(), target);
    EXPECT_EQ(r.status, 404) << target;
    EXPECT_EQ(r.body.find("root:"), std::string::npos) << target;
  }
  EXPECT_EQ(httpRequest(server.port(), "/", test::HttpMethod::kPost).status, 405);
  EXPECT_EQ(httpRequest(server.port(), "/report.json", test::HttpMethod::kPut).status, 405);
  EXPECT_EQ(httpRequest(server.port(), "/", test::HttpMethod::kDelete).status, 405);
}

TEST(ViewServer, WebSocketRoundTripAndHistoryForLateClients) {
  ViewServer server(anyPort());
  WsClient early(server.port());
  ASSERT_TRUE(waitForSessions(server, 1));
  const std::vector<float> points = {1.5f, -2.0f, 0.25f, 10.0f, 20.0f, -1.0f};
  server.publishStatus(R"({"type":"counters","mapping_scans":3})");
  server.publish(encodeUpdate(UpdateKind::kMapPoints, kNoLane, points), true, true);
  server.publish(encodeUpdate(UpdateKind::kCandidate, 1, {1, 2, 3, 1}), true, false);  // not kept
  for (auto* c : {&early}) {
    auto status = c->read();
    ASSERT_TRUE(status);
    EXPECT_FALSE(status->binary);
    EXPECT_NE(status->data.find("mapping_scans"), std::string::npos);
    auto map = c->read();
    ASSERT_TRUE(map);
    const auto d = decodeUpdate(map->data);
    ASSERT_TRUE(d);
    EXPECT_EQ(d->kind, UpdateKind::kMapPoints);
    EXPECT_EQ(d->values, points);
    auto cand = c->read();
    ASSERT_TRUE(cand && isUpdate(*cand, UpdateKind::kCandidate));
    EXPECT_EQ(decodeUpdate(cand->data)->lane, 1);
  }
  // A client that connects later gets the latest status and the kept messages, not the others.
  WsClient late(server.port());
  ASSERT_TRUE(waitForSessions(server, 2));
  auto s = late.read();
  ASSERT_TRUE(s);
  EXPECT_FALSE(s->binary);
  auto m = late.read();
  ASSERT_TRUE(m && isUpdate(*m, UpdateKind::kMapPoints));
  server.publishReport(R"({"status":"ok"})");
  auto r = late.read();  // next: the report, not the candidate that was not kept
  ASSERT_TRUE(r);
  EXPECT_EQ(r->data, R"({"type":"report","report":{"status":"ok"}})");
}

TEST(ViewServer, ManyClientsEachGetEveryUpdate) {
  ViewServer server(anyPort());
  const int n = rigcal::test::kSanitized ? 8 : 32;
  std::vector<std::unique_ptr<WsClient>> clients;
  for (int i = 0; i < n; ++i) clients.push_back(std::make_unique<WsClient>(server.port()));
  ASSERT_TRUE(waitForSessions(server, std::size_t(n)));
  server.publish(encodeUpdate(UpdateKind::kSelected, 0, {}), true, false);
  for (auto& c : clients) ASSERT_TRUE(c->readUntil([](const WsMessage& m) { return isUpdate(m, UpdateKind::kSelected); }));
  EXPECT_EQ(server.stats().sessions, std::size_t(n));
  const int updates = 20;
  for (int k = 0; k < updates; ++k)
    server.publish(encodeUpdate(UpdateKind::kTrajectory, kNoLane, {float(k), 0, 0, 1}), true, true);
  for (auto& c : clients) {
    for (int k = 0; k < updates; ++k) {
      auto m = c->read();
      ASSERT_TRUE(m);
      const auto d = decodeUpdate(m->data);
      ASSERT_TRUE(d);
      EXPECT_EQ(d->values[0], float(k));  // in order
    }
  }
  EXPECT_EQ(server.stats().messages_dropped, 0u);
  clients.clear();
  // The server notices the closed clients at its next broadcast.
  for (int i = 0; i < 50 && server.stats().sessions > 0; ++i) {
    server.publish("{}", false, false);
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  EXPECT_EQ(server.stats().sessions, 0u);
}

TEST(ViewServer, AClientThatStopsReadingCostsBoundedMemoryAndDelaysNobody) {
  ServerLimits limits;
  limits.session_queue_bytes = 2u << 20;
  limits.history_bytes = 1u << 20;
  ViewServer server(anyPort(), limits);
  WsClient stalled(server.port());  // handshakes, then never reads
  ASSERT_TRUE(waitForSessions(server, 1));
  const std::vector<float> chunk(3 * 20'000, 1.0f);  // 240 kB
  const int messages = rigcal::test::kSanitized ? 100 : 400;  // 24 / 96 MB in all
  const auto t0 = std::chrono::steady_clock::now();
  for (int i = 0; i < messages; ++i) server.publish(encodeUpdate(UpdateKind::kMapPoints, kNoLane, chunk), true, true);
  const double publish_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  // publish() only hands the message to the server thread.
  if (rigcal::test::kWallClockAsserted) {
    EXPECT_LT(publish_s, 1.0);
  }
  // A reading client still gets new updates while the stalled one holds its full queue.
  WsClient reader(server.port());
  ASSERT_TRUE(waitForSessions(server, 2));
  server.publish(encodeUpdate(UpdateKind::kSelected, 3, {7, 8, 9}), true, false);
  EXPECT_TRUE(reader.readUntil([](const WsMessage& m) {
    const auto d = decodeUpdate(m.data);
    return d && d->kind == UpdateKind::kSelected && d->lane == 3;
  }));
  const ServerStats s = server.stats();
  EXPECT_LE(s.max_pending_bytes, limits.session_queue_bytes);
  EXPECT_GT(s.messages_dropped, 0u);
  EXPECT_LE(s.history_bytes, limits.history_bytes);
  EXPECT_GT(s.history_dropped, 0u);
  EXPECT_EQ(httpRequest(server.port(), "/").status, 200);
}

TEST(ViewServer, RefusesAWebSocketElsewhereThanWs) {
  ViewServer server(anyPort());
  EXPECT_THROW(WsClient(server.port(), "/other"), boost::system::system_error);
}

TEST(ViewServer, BindFailureNamesTheAddress) {
  ViewServer first(anyPort());
  try {
    ViewServer second(ViewEndpoint{"127.0.0.1", first.port()});
    // SO_REUSEADDR does not allow two listeners on Linux; reaching here is a failure.
    ADD_FAILURE() << "bound a port already listened on";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("127.0.0.1:" + std::to_string(first.port())), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace rigcal::view
