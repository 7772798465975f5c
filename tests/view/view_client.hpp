#pragma once
// Test clients of the view server on real loopback sockets: one HTTP request, and a WebSocket client
// (Boost.Beast) that reads messages with a timeout.
#include <boost/asio/connect.hpp>
#include <boost/asio/ip/tcp.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <boost/beast/websocket.hpp>

#include <chrono>
#include <optional>
#include <string>
#include <thread>

#include "rigcal/view/view_server.hpp"

namespace rigcal::view::test {

namespace beast = boost::beast;
namespace http = beast::http;
namespace websocket = beast::websocket;
using tcp = boost::asio::ip::tcp;

struct HttpResult {
  int status = 0;
  std::string content_type;
  std::string body;
};

/// `method target` sent verbatim (the target is not normalised: traversal attempts reach the server as typed).
inline HttpResult httpRequest(std::uint16_t port, const std::string& target, http::verb method = http::verb::get) {
  boost::asio::io_context io;
  beast::tcp_stream stream(io);
  stream.connect(tcp::endpoint(boost::asio::ip::make_address("127.0.0.1"), port));
  stream.expires_after(std::chrono::seconds(10));
  http::request<http::string_body> req(method, target, 11);
  req.set(http::field::host, "127.0.0.1");
  http::write(stream, req);
  beast::flat_buffer buffer;
  http::response_parser<http::string_body> parser;
  parser.body_limit(64u << 20);
  if (method == http::verb::head) parser.skip(true);
  http::read(stream, buffer, parser);
  const auto& res = parser.get();
  beast::error_code ec;
  stream.socket().shutdown(tcp::socket::shutdown_both, ec);
  return {int(res.result_int()), std::string(res[http::field::content_type]), res.body()};
}

struct WsMessage {
  std::string data;
  bool binary = false;
};

class WsClient {
 public:
  explicit WsClient(std::uint16_t port, const std::string& target = "/ws") : ws_(io_) {
    beast::get_lowest_layer(ws_).connect(tcp::endpoint(boost::asio::ip::make_address("127.0.0.1"), port));
    ws_.handshake("127.0.0.1:" + std::to_string(port), target);
  }
  /// The next message, or nullopt after `timeout` (then the stream is cancelled: later reads fail) or on
  /// an error. Asynchronous underneath: Beast's stream timeouts apply to asynchronous operations only.
  std::optional<WsMessage> read(std::chrono::milliseconds timeout = std::chrono::milliseconds(10000)) {
    beast::flat_buffer buffer;
    std::optional<beast::error_code> result;
    ws_.async_read(buffer, [&](beast::error_code ec, std::size_t) { result = ec; });
    io_.restart();
    io_.run_for(timeout);
    if (!result) {
      beast::get_lowest_layer(ws_).cancel();
      io_.restart();
      io_.run();
      return std::nullopt;
    }
    if (*result) return std::nullopt;
    return WsMessage{beast::buffers_to_string(buffer.data()), ws_.got_binary()};
  }
  /// Reads until `pred(message)` holds; false after `timeout` without it.
  template <class Pred>
  bool readUntil(Pred pred, std::chrono::milliseconds timeout = std::chrono::milliseconds(10000)) {
    const auto until = std::chrono::steady_clock::now() + timeout;
    while (std::chrono::steady_clock::now() < until) {
      auto m = read(std::chrono::duration_cast<std::chrono::milliseconds>(until - std::chrono::steady_clock::now()));
      if (!m) return false;
      if (pred(*m)) return true;
    }
    return false;
  }

 private:
  boost::asio::io_context io_;
  websocket::stream<beast::tcp_stream> ws_;
};

/// Waits until the server has registered `n` WebSocket clients (a client's handshake returns before the
/// server has added it: what is published in between reaches it only if kept).
inline bool waitForSessions(const ViewServer& server, std::size_t n) {
  for (int i = 0; i < 1000; ++i) {
    if (server.stats().sessions >= n) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  return false;
}

}  // namespace rigcal::view::test
