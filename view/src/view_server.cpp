#include "rigcal/view/view_server.hpp"

#include <boost/asio/post.hpp>

#include <stdexcept>

#include "http_session.hpp"
#include "websocket_session.hpp"

namespace rigcal::view {

namespace asio = boost::asio;
using tcp = asio::ip::tcp;

std::vector<std::shared_ptr<WebSocketSession>> ViewServer::Impl::liveSessions() {
  std::vector<std::shared_ptr<WebSocketSession>> live;
  std::vector<std::weak_ptr<WebSocketSession>> kept;
  for (auto& w : sessions)
    if (auto s = w.lock(); s && s->isOpen()) {
      live.push_back(s);
      kept.push_back(w);
    }
  sessions = std::move(kept);
  session_count.store(live.size());
  return live;
}

void ViewServer::Impl::addSession(const std::shared_ptr<WebSocketSession>& s) {
  sessions.push_back(s);
  liveSessions();
  if (status) s->send(status);
  for (const auto& m : history) s->send(m);
  if (report_message) s->send(report_message);
}

void ViewServer::Impl::broadcast(const MessagePtr& m) {
  for (const auto& s : liveSessions()) s->send(m);
}

void ViewServer::Impl::accept() {
  acceptor.async_accept([this](boost::system::error_code ec, tcp::socket socket) {
    if (ec == asio::error::operation_aborted || stopped.load()) return;
    if (!ec) std::make_shared<HttpSession>(std::move(socket), *this)->start();
    accept();
  });
}

ViewServer::ViewServer(const ViewEndpoint& endpoint, ServerLimits limits) : impl_(std::make_shared<Impl>(limits)) {
  Impl& m = *impl_;
  boost::system::error_code ec;
  const auto address = asio::ip::make_address(endpoint.address, ec);
  const tcp::endpoint at(address, endpoint.port);
  const auto fail = [&](const char* what) {
    throw std::runtime_error(std::string("view: cannot ") + what + " " + endpoint.address + ":" +
                             std::to_string(endpoint.port) + ": " + ec.message());
  };
  if (ec) fail("parse");
  if (m.acceptor.open(at.protocol(), ec); ec) fail("open");
  if (m.acceptor.set_option(asio::socket_base::reuse_address(true), ec); ec) fail("configure");
  if (m.acceptor.bind(at, ec); ec) fail("bind");
  if (m.acceptor.listen(asio::socket_base::max_listen_connections, ec); ec) fail("listen on");
  m.accept();
  m.thread = std::thread([&m] { m.io.run(); });
}

ViewServer::~ViewServer() { stop(); }

std::uint16_t ViewServer::port() const {
  boost::system::error_code ec;
  return impl_->acceptor.local_endpoint(ec).port();
}

std::string ViewServer::url() const {
  boost::system::error_code ec;
  const auto e = impl_->acceptor.local_endpoint(ec);
  const std::string host = e.address().is_v6() ? "[" + e.address().to_string() + "]" : e.address().to_string();
  return "http://" + host + ":" + std::to_string(e.port()) + "/";
}

void ViewServer::publish(std::string message, bool binary, bool keep) {
  auto m = std::make_shared<const Message>(Message{std::move(message), binary});
  asio::post(impl_->io, [impl = impl_.get(), m, keep] {
    if (keep) {
      if (impl->history_bytes + m->data.size() <= impl->limits.history_bytes) {
        impl->history.push_back(m);
        impl->history_bytes += m->data.size();
        impl->history_size.store(impl->history_bytes);
      } else {
        impl->history_dropped.fetch_add(1, std::memory_order_relaxed);
      }
    }
    impl->broadcast(m);
  });
}

void ViewServer::publishStatus(std::string json) {
  auto m = std::make_shared<const Message>(Message{std::move(json), false});
  asio::post(impl_->io, [impl = impl_.get(), m] {
    impl->status = m;
    impl->broadcast(m);
  });
}

void ViewServer::publishReport(std::string report_json) {
  {
    std::lock_guard lock(impl_->report_mutex);
    impl_->report_json = report_json;
  }
  auto m = std::make_shared<const Message>(Message{"{\"type\":\"report\",\"report\":" + report_json + "}", false});
  asio::post(impl_->io, [impl = impl_.get(), m] {
    impl->report_message = m;
    impl->broadcast(m);
  });
}

ServerStats ViewServer::stats() const {
  const Impl& m = *impl_;
  ServerStats s;
  s.sessions = m.session_count.load();
  s.messages_sent = m.messages_sent.load();
  s.messages_dropped = m.messages_dropped.load();
  s.max_pending_bytes = m.max_pending_bytes.load();
  s.history_bytes = m.history_size.load();
  s.history_dropped = m.history_dropped.load();
  s.http_requests = m.http_requests.load();
  return s;
}

void ViewServer::stop() {
  Impl& m = *impl_;
  if (m.stopped.exchange(true)) return;
  asio::post(m.io, [&m] {
    boost::system::error_code ec;
    m.acceptor.close(ec);
    for (const auto& s : m.liveSessions()) s->close();
  });
  // Give the closes a moment to run, then stop whatever is still pending (a client mid-request).
  if (m.thread.joinable()) {
    asio::post(m.io, [&m] { m.io.stop(); });
    m.thread.join();
  }
}

}  // namespace rigcal::view
