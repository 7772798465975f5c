#include "view_client.hpp"

#include <boost/asio/connect.hpp>
#include <boost/asio/ip/tcp.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <boost/beast/websocket.hpp>

#include <thread>

namespace rigcal::view::test {

namespace beast = boost::beast;
namespace http = beast::http;
namespace websocket = beast::websocket;
using tcp = boost::asio::ip::tcp;

namespace {

http::verb verbOf(HttpMethod method) {
  switch (method) {
    case HttpMethod::kGet: return http::verb::get;
    case HttpMethod::kHead: return http::verb::head;
    case HttpMethod::kPost: return http::verb::post;
    case HttpMethod::kPut: return http::verb::put;
    case HttpMethod::kDelete: return http::verb::delete_;
  }
  return http::verb::get;
}

tcp::endpoint loopback(std::uint16_t port) { return {boost::asio::ip::make_address("127.0.0.1"), port}; }

}  // namespace

HttpResult httpRequest(std::uint16_t port, const std::string& target, HttpMethod method) {
  boost::asio::io_context io;
  beast::tcp_stream stream(io);
  stream.connect(loopback(port));
  stream.expires_after(std::chrono::seconds(10));
  http::request<http::string_body> req(verbOf(method), target, 11);
  req.set(http::field::host, "127.0.0.1");
  http::write(stream, req);
  beast::flat_buffer buffer;
  http::response_parser<http::string_body> parser;
  parser.body_limit(64u << 20);
  if (method == HttpMethod::kHead) parser.skip(true);
  http::read(stream, buffer, parser);
  const auto& res = parser.get();
  beast::error_code ec;
  stream.socket().shutdown(tcp::socket::shutdown_both, ec);
  return {int(res.result_int()), std::string(res[http::field::content_type]), res.body()};
}

struct WsClient::Connection {
  boost::asio::io_context io;
  websocket::stream<beast::tcp_stream> ws{io};
};

WsClient::WsClient(std::uint16_t port, const std::string& target) : connection_(std::make_unique<Connection>()) {
  beast::get_lowest_layer(connection_->ws).connect(loopback(port));
  connection_->ws.handshake("127.0.0.1:" + std::to_string(port), target);
}

WsClient::~WsClient() = default;

// Asynchronous underneath: Beast's stream timeouts apply to asynchronous operations only.
std::optional<WsMessage> WsClient::read(std::chrono::milliseconds timeout) {
  auto& [io, ws] = *connection_;
  beast::flat_buffer buffer;
  std::optional<beast::error_code> result;
  ws.async_read(buffer, [&](beast::error_code ec, std::size_t) { result = ec; });
  io.restart();
  io.run_for(timeout);
  if (!result) {
    beast::get_lowest_layer(ws).cancel();
    io.restart();
    io.run();
    return std::nullopt;
  }
  if (*result) return std::nullopt;
  return WsMessage{beast::buffers_to_string(buffer.data()), ws.got_binary()};
}

bool waitForSessions(const ViewServer& server, std::size_t n) {
  for (int i = 0; i < 1000; ++i) {
    if (server.stats().sessions >= n) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  return false;
}

}  // namespace rigcal::view::test
