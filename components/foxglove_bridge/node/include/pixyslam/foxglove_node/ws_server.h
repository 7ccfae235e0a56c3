#pragma once

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "pixyslam/foxglove/ws_protocol.h"

namespace pixyslam::foxglove_node {

struct WsServerOptions {
  std::string address = "127.0.0.1";  // interface to listen on ("0.0.0.0": every interface)
  std::uint16_t port = 8765;           // 0: any free port (port() tells which)
  std::size_t max_clients = 8;         // more connections are refused (HTTP 503)
  std::size_t client_queue_max_bytes = std::size_t{16} << 20;  // per client: beyond, messages are dropped
  std::size_t backlog_max_bytes = std::size_t{64} << 20;       // published, not yet sent: beyond, dropped
  std::size_t max_request_bytes = 65536;                       // a bigger client frame closes that connection
  std::string name = "pixyslam foxglove_bridge";               // serverInfo name
  std::map<std::string, std::string> metadata;                 // serverInfo metadata
};

// Counters since construction. Every client input that is refused is counted
// here and answered with a "status" message; none stops the server.
struct WsServerCounters {
  std::uint64_t clients_now = 0;
  std::uint64_t clients_accepted = 0;
  std::uint64_t clients_refused = 0;        // no foxglove.websocket.v1 subprotocol, or too many clients
  std::uint64_t bad_requests = 0;           // client frames not understood or refused (status sent)
  std::uint64_t messages_sent = 0;          // message data frames queued to clients
  std::uint64_t dropped_slow_client = 0;    // a client's queue was full
  std::uint64_t dropped_backlog = 0;        // publish() faster than the server thread
};

// A Foxglove WebSocket server (websocketpp, one thread of its own): advertises
// `channels` to each client on connect, takes subscribe/unsubscribe, and sends
// each published message to the clients subscribed to its channel. publish()
// is thread-safe and never blocks: a message that cannot be queued is dropped
// and counted. Throws std::runtime_error naming address:port if it cannot listen.
class WsServer {
 public:
  WsServer(const WsServerOptions& options, std::vector<foxglove::Channel> channels);
  ~WsServer();
  WsServer(const WsServer&) = delete;
  WsServer& operator=(const WsServer&) = delete;

  std::uint16_t port() const { return port_; }
  const std::vector<foxglove::Channel>& channels() const { return channels_; }
  // True while at least one client is subscribed to `channel_id` (a hint: work
  // for nobody can be skipped).
  bool has_subscribers(std::uint32_t channel_id) const;
  void publish(std::uint32_t channel_id, std::uint64_t time_ns, std::vector<std::uint8_t> payload);
  WsServerCounters counters() const;
  // Stops listening, closes every connection, joins the thread. Idempotent.
  void stop();

 private:
  class Impl;
  std::vector<foxglove::Channel> channels_;
  std::uint16_t port_ = 0;
  std::unique_ptr<Impl> impl_;
};

}  // namespace pixyslam::foxglove_node
