#pragma once
// One browser's WebSocket: a bounded queue of messages written one at a time. Messages that do not fit
// (a client that stopped reading) are dropped and counted, so the server's memory per client is bounded.
// Incoming messages are read and ignored (the view is read-only); a close or error ends the session.
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <boost/beast/websocket.hpp>

#include <deque>
#include <memory>

#include "server_impl.hpp"

namespace rigcal::view {

class WebSocketSession : public std::enable_shared_from_this<WebSocketSession> {
 public:
  WebSocketSession(boost::asio::ip::tcp::socket socket, ViewServer::Impl& server);
  /// Completes the upgrade `request` asked for, then registers with the server.
  void start(boost::beast::http::request<boost::beast::http::string_body> request);
  /// Queues `m` (Asio thread), or drops it when the queue would exceed the server's per-client bound.
  void send(const MessagePtr& m);
  void close();
  [[nodiscard]] bool isOpen() const { return open_; }

 private:
  void onAccept(boost::beast::error_code ec);
  void readNext();
  void writeNext();

  boost::beast::websocket::stream<boost::beast::tcp_stream> ws_;
  ViewServer::Impl& server_;
  boost::beast::flat_buffer incoming_;
  std::deque<MessagePtr> queue_;
  std::size_t pending_bytes_ = 0;
  bool writing_ = false;
  bool open_ = false;
};

}  // namespace rigcal::view
