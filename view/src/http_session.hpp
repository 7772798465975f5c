#pragma once
// One HTTP connection: reads small GET requests (keep-alive), answers them from http_routes, and hands
// an upgrade to /ws over to a WebSocketSession.
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>

#include <memory>
#include <optional>

#include "server_impl.hpp"

namespace rigcal::view {

class HttpSession : public std::enable_shared_from_this<HttpSession> {
 public:
  HttpSession(boost::asio::ip::tcp::socket socket, ViewServer::Impl& server);
  void start() { readNext(); }

 private:
  void readNext();
  void onRead(boost::beast::error_code ec);
  void reply(int status, const std::string& type, std::string body, bool head);

  boost::beast::tcp_stream stream_;
  ViewServer::Impl& server_;
  boost::beast::flat_buffer buffer_;
  std::optional<boost::beast::http::request_parser<boost::beast::http::string_body>> parser_;
  std::shared_ptr<boost::beast::http::response<boost::beast::http::string_body>> response_;
};

}  // namespace rigcal::view
