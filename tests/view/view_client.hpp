#pragma once
// Test clients of the view server on real loopback sockets: one HTTP request, and a WebSocket client that
// reads messages with a timeout. Boost.Beast stays in view_client.cpp, compiled once for every view test.
#include <boost/system/system_error.hpp>

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>

#include "rigcal/view/view_server.hpp"

namespace rigcal::view::test {

enum class HttpMethod { kGet, kHead, kPost, kPut, kDelete };

struct HttpResult {
  int status = 0;
  std::string content_type;
  std::string body;
};

/// `method target` sent verbatim (the target is not normalised: traversal attempts reach the server as typed).
HttpResult httpRequest(std::uint16_t port, const std::string& target, HttpMethod method = HttpMethod::kGet);

struct WsMessage {
  std::string data;
  bool binary = false;
};

class WsClient {
 public:
  /// Connects and completes the handshake; throws boost::system::system_error when the server refuses it.
  explicit WsClient(std::uint16_t port, const std::string& target = "/ws");
  ~WsClient();
  WsClient(const WsClient&) = delete;
  WsClient& operator=(const WsClient&) = delete;

  /// The next message, or nullopt after `timeout` (then the stream is cancelled: later reads fail) or on
  /// an error.
  std::optional<WsMessage> read(std::chrono::milliseconds timeout = std::chrono::milliseconds(10000));

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
  struct Connection;
  std::unique_ptr<Connection> connection_;
};

/// Waits until the server has registered `n` WebSocket clients (a client's handshake returns before the
/// server has added it: what is published in between reaches it only if kept).
bool waitForSessions(const ViewServer& server, std::size_t n);

}  // namespace rigcal::view::test
