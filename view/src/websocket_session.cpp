#include "websocket_session.hpp"

namespace rigcal::view {

namespace beast = boost::beast;
namespace websocket = beast::websocket;

WebSocketSession::WebSocketSession(boost::asio::ip::tcp::socket socket, ViewServer::Impl& server)
    : ws_(std::move(socket)), server_(server) {}

void WebSocketSession::start(beast::http::request<beast::http::string_body> request) {
  // Idle clients are pinged; one that answers nothing for the timeout is closed.
  ws_.set_option(websocket::stream_base::timeout::suggested(beast::role_type::server));
  ws_.read_message_max(64 * 1024);  // the page sends nothing; anything big is not ours
  ws_.async_accept(request, [self = shared_from_this()](beast::error_code ec) { self->onAccept(ec); });
}

void WebSocketSession::onAccept(beast::error_code ec) {
  if (ec || server_.stopped.load()) return;
  open_ = true;
  server_.addSession(shared_from_this());
  readNext();
}

void WebSocketSession::readNext() {
  ws_.async_read(incoming_, [self = shared_from_this()](beast::error_code ec, std::size_t) {
    if (ec) {
      self->open_ = false;
      return;
    }
    self->incoming_.consume(self->incoming_.size());
    self->readNext();
  });
}

void WebSocketSession::send(const MessagePtr& m) {
  if (!open_) return;
  // An empty queue takes any message, so one larger than the bound still goes to a client that reads.
  if (pending_bytes_ > 0 && pending_bytes_ + m->data.size() > server_.limits.session_queue_bytes) {
    server_.messages_dropped.fetch_add(1, std::memory_order_relaxed);
    return;
  }
  queue_.push_back(m);
  pending_bytes_ += m->data.size();
  server_.notePending(pending_bytes_);
  if (!writing_) writeNext();
}

void WebSocketSession::writeNext() {
  writing_ = true;
  const MessagePtr& m = queue_.front();
  ws_.binary(m->binary);
  ws_.async_write(boost::asio::buffer(m->data), [self = shared_from_this()](beast::error_code ec, std::size_t) {
    if (ec) {
      self->open_ = false;
      self->queue_.clear();
      self->pending_bytes_ = 0;
      self->writing_ = false;
      return;
    }
    self->server_.messages_sent.fetch_add(1, std::memory_order_relaxed);
    self->pending_bytes_ -= self->queue_.front()->data.size();
    self->queue_.pop_front();
    if (!self->queue_.empty()) self->writeNext();
    else self->writing_ = false;
  });
}

void WebSocketSession::close() {
  open_ = false;
  beast::error_code ec;
  beast::get_lowest_layer(ws_).socket().shutdown(boost::asio::ip::tcp::socket::shutdown_both, ec);
  beast::get_lowest_layer(ws_).socket().close(ec);
}

}  // namespace rigcal::view
