#pragma once
// ViewServer::Impl, shared by the server's sessions (http_session.cpp, websocket_session.cpp) and
// view_server.cpp. Everything not atomic or under report_mutex belongs to the server's Asio thread.
#include <boost/asio/io_context.hpp>
#include <boost/asio/ip/tcp.hpp>

#include <atomic>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "rigcal/view/view_server.hpp"

namespace rigcal::view {

struct Message {
  std::string data;
  bool binary = false;
};
using MessagePtr = std::shared_ptr<const Message>;

class WebSocketSession;

struct ViewServer::Impl {
  explicit Impl(ServerLimits l) : limits(l) {}
  const ServerLimits limits;

  // Any thread.
  mutable std::mutex report_mutex;
  std::string report_json;
  std::atomic<std::uint64_t> messages_sent{0}, messages_dropped{0}, history_dropped{0}, http_requests{0};
  std::atomic<std::size_t> max_pending_bytes{0}, history_size{0}, session_count{0};
  std::atomic<bool> stopped{false};

  // The Asio thread only.
  std::vector<std::weak_ptr<WebSocketSession>> sessions;
  std::vector<MessagePtr> history;
  std::size_t history_bytes = 0;
  MessagePtr status, report_message;

  std::string report() const {
    std::lock_guard lock(report_mutex);
    return report_json;
  }
  void notePending(std::size_t bytes) {
    std::size_t seen = max_pending_bytes.load();
    while (bytes > seen && !max_pending_bytes.compare_exchange_weak(seen, bytes)) {}
  }
  /// Drops expired sessions; returns the live ones.
  std::vector<std::shared_ptr<WebSocketSession>> liveSessions();
  void addSession(const std::shared_ptr<WebSocketSession>& s);  // sends status, report and history first
  void broadcast(const MessagePtr& m);
  void accept();

  // Declared last so they go first: pending handlers (sessions) are destroyed while the rest still lives.
  std::thread thread;
  boost::asio::io_context io{1};
  boost::asio::ip::tcp::acceptor acceptor{io};
};

}  // namespace rigcal::view
