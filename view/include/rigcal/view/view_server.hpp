#pragma once
// The live view's server: HTTP (http_routes) and a WebSocket at /ws on one Asio thread of its own.
// publish() may be called from any thread; it never waits for a client. Each WebSocket client has its own
// bounded send queue: a client that stops reading loses updates (counted) instead of growing memory.
// Messages marked `keep` are also kept (bounded) for clients that connect later, so a browser opened
// mid-run sees the map so far.
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>

#include "rigcal/view/view_endpoint.hpp"

namespace rigcal::view {

struct ServerLimits {
  std::size_t session_queue_bytes = 48u << 20;  // per client: a message that would queue more is dropped
  std::size_t history_bytes = 32u << 20;        // kept for late clients; later keep messages are not kept
  std::size_t max_sessions = 64;                // further WebSocket clients are refused
};

struct ServerStats {
  std::size_t sessions = 0;                 // open WebSocket clients
  std::uint64_t messages_sent = 0;          // WebSocket messages written, all clients
  std::uint64_t messages_dropped = 0;       // not queued for a client whose queue was full
  std::size_t max_pending_bytes = 0;        // the largest send queue any client had
  std::size_t history_bytes = 0;
  std::uint64_t history_dropped = 0;        // keep messages beyond history_bytes
  std::uint64_t http_requests = 0;
};

class ViewServer {
 public:
  /// Binds and starts serving. Throws std::runtime_error (one line naming the address) when it cannot.
  explicit ViewServer(const ViewEndpoint& endpoint, ServerLimits limits = {});
  ~ViewServer();  // stop()
  ViewServer(const ViewServer&) = delete;
  ViewServer& operator=(const ViewServer&) = delete;

  [[nodiscard]] std::uint16_t port() const;  // the bound port (useful with port 0)
  [[nodiscard]] std::string url() const;     // http://ADDR:PORT/

  /// Sends `message` to every WebSocket client (binary or text); `keep`: also to clients that connect later.
  void publish(std::string message, bool binary, bool keep);
  /// The latest status (counters JSON): sent to every client now and to each new client first.
  void publishStatus(std::string json);
  /// The finished run's report.json: served at /report.json and sent as {"type":"report",...} text.
  void publishReport(std::string report_json);

  [[nodiscard]] ServerStats stats() const;
  /// Closes every connection and joins the server thread. Idempotent.
  void stop();

  struct Impl;

 private:
  std::shared_ptr<Impl> impl_;
};

}  // namespace rigcal::view
