#include "http_session.hpp"

#include <boost/beast/websocket.hpp>

#include <chrono>

#include "rigcal/view/http_routes.hpp"
#include "websocket_session.hpp"

namespace rigcal::view {

namespace beast = boost::beast;
namespace http = beast::http;

HttpSession::HttpSession(boost::asio::ip::tcp::socket socket, ViewServer::Impl& server)
    : stream_(std::move(socket)), server_(server) {}

void HttpSession::readNext() {
  parser_.emplace();
  parser_->header_limit(8 * 1024);
  parser_->body_limit(8 * 1024);  // the page only GETs
  stream_.expires_after(std::chrono::seconds(30));
  http::async_read(stream_, buffer_, *parser_, [self = shared_from_this()](beast::error_code ec, std::size_t) { self->onRead(ec); });
}

void HttpSession::onRead(beast::error_code ec) {
  if (ec) {
    stream_.socket().shutdown(boost::asio::ip::tcp::socket::shutdown_send, ec);
    return;
  }
  server_.http_requests.fetch_add(1, std::memory_order_relaxed);
  const auto& req = parser_->get();
  if (beast::websocket::is_upgrade(req)) {
    const std::string_view target(req.target().data(), req.target().size());
    if (target.substr(0, target.find('?')) != "/ws") return reply(404, "text/plain", "not found\n", false);
    if (server_.session_count.load() >= server_.limits.max_sessions)
      return reply(503, "text/plain", "too many view clients\n", false);
    stream_.expires_never();
    std::make_shared<WebSocketSession>(stream_.release_socket(), server_)->start(parser_->release());
    return;
  }
  const std::string_view method(req.method_string().data(), req.method_string().size());
  const std::string_view target(req.target().data(), req.target().size());
  HttpReply r = routeRequest(method, target, server_.report());
  reply(r.status, r.content_type, std::move(r.body), req.method() == http::verb::head);
}

void HttpSession::reply(int status, const std::string& type, std::string body, bool head) {
  const auto& req = parser_->get();
  response_ = std::make_shared<http::response<http::string_body>>(static_cast<http::status>(status), req.version());
  auto& res = *response_;
  res.set(http::field::server, "rigcal-view");
  res.set(http::field::content_type, type);
  res.set(http::field::cache_control, "no-store");
  res.set("X-Content-Type-Options", "nosniff");
  res.set("Content-Security-Policy", "default-src 'self'; connect-src 'self'; img-src 'self' data:");
  res.keep_alive(req.keep_alive());
  const std::size_t length = body.size();
  if (!head) res.body() = std::move(body);
  res.content_length(length);
  http::async_write(stream_, res, [self = shared_from_this()](beast::error_code ec, std::size_t) {
    if (ec) return;
    if (!self->response_->keep_alive()) {
      self->stream_.socket().shutdown(boost::asio::ip::tcp::socket::shutdown_send, ec);
      return;
    }
    self->readNext();
  });
}

}  // namespace rigcal::view
