// The WebSocket server against a raw TCP client (pixyslam/foxglove_node/ws_server.h):
// handshake, advertise, subscribe, and a client that stops reading.
#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <chrono>
#include <string>
#include <thread>

#include <gtest/gtest.h>

#include "pixyslam/foxglove_node/bridge_options.h"
#include "pixyslam/foxglove_node/ws_server.h"
#include "pixyslam/parameters/parameters.h"

namespace pixyslam::foxglove_node {
namespace {

// A blocking TCP connection to 127.0.0.1:port; closed by the destructor.
class RawClient {
 public:
  explicit RawClient(std::uint16_t port, int receive_buffer = 0) {
    fd_ = ::socket(AF_INET, SOCK_STREAM, 0);
    if (receive_buffer > 0) ::setsockopt(fd_, SOL_SOCKET, SO_RCVBUF, &receive_buffer, sizeof(receive_buffer));
    timeval timeout{2, 0};
    ::setsockopt(fd_, SOL_SOCKET, SO_RCVTIMEO, &timeout, sizeof(timeout));
    sockaddr_in address{};
    address.sin_family = AF_INET;
    address.sin_port = htons(port);
    address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    connected_ = ::connect(fd_, reinterpret_cast<sockaddr*>(&address), sizeof(address)) == 0;
  }
  ~RawClient() { ::close(fd_); }
  bool connected() const { return connected_; }

  void send_text(const std::string& text) { ::send(fd_, text.data(), text.size(), MSG_NOSIGNAL); }
  // One masked client text frame (RFC 6455 5.2), payload < 65536 bytes.
  void send_frame(const std::string& payload) {
    std::string frame = {'\x81'};
    if (payload.size() < 126) {
      frame += static_cast<char>(0x80 | payload.size());
    } else {
      frame += static_cast<char>(0x80 | 126);
      frame += static_cast<char>(payload.size() >> 8);
      frame += static_cast<char>(payload.size() & 0xff);
    }
    const char mask[4] = {0x12, 0x34, 0x56, 0x78};
    frame.append(mask, 4);
    for (std::size_t i = 0; i < payload.size(); ++i) frame += static_cast<char>(payload[i] ^ mask[i % 4]);
    send_text(frame);
  }
  // Reads until `needle` has arrived (or 2 s without data); returns all read.
  std::string read_until(const std::string& needle) {
    while (received_.find(needle) == std::string::npos) {
      char buffer[4096];
      const ssize_t n = ::recv(fd_, buffer, sizeof(buffer), 0);
      if (n <= 0) break;
      received_.append(buffer, static_cast<std::size_t>(n));
    }
    return received_;
  }

 private:
  int fd_ = -1;
  bool connected_ = false;
  std::string received_;
};

std::string upgrade_request(const std::string& protocol) {
  return "GET / HTTP/1.1\r\nHost: 127.0.0.1\r\nUpgrade: websocket\r\nConnection: Upgrade\r\n"
         "Sec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\nSec-WebSocket-Version: 13\r\n" +
         (protocol.empty() ? std::string() : "Sec-WebSocket-Protocol: " + protocol + "\r\n") + "\r\n";
}

std::vector<foxglove::Channel> one_channel() {
  return {{7, "pixyslam/odometry", "cdr", "pixyslam::msg::Odometry", "struct Odometry { long x; };", "omgidl"}};
}

template <class Predicate>
bool eventually(Predicate p) {
  for (int i = 0; i < 200 && !p(); ++i) std::this_thread::sleep_for(std::chrono::milliseconds(10));
  return p();
}

// foxglove_bridge.address is checked with the options (a config error, exit 2),
// not when the server binds it (exit 1, no key named).
TEST(BridgeOptions, TheAddressMustBeANumericIpAddress) {
  using foxglove_node::BridgeOptions;
  for (const char* good : {"127.0.0.1", "0.0.0.0", "::1", "::"}) {
    BridgeOptions o;
    EXPECT_NO_THROW(parameters::apply_override(o, foxglove_node::bridge_parameters(), "foxglove_bridge",
                                               std::string("foxglove_bridge.address=") + good))
        << good;
    EXPECT_EQ(o.server.address, good);
  }
  for (const char* bad : {"nope", "999.1.1.1", "localhost", "127.0.0.1:8765"}) {
    BridgeOptions o;
    EXPECT_THROW(parameters::apply_override(o, foxglove_node::bridge_parameters(), "foxglove_bridge",
                                            std::string("foxglove_bridge.address=") + bad),
                 std::invalid_argument)
        << bad;
  }
}

TEST(WsServer, AdvertisesToAFoxgloveClientAndRefusesOthers) {
  WsServerOptions options;
  options.port = 0;
  options.max_clients = 1;
  WsServer server(options, one_channel());
  ASSERT_NE(server.port(), 0);

  RawClient client(server.port());
  ASSERT_TRUE(client.connected());
  client.send_text(upgrade_request("foxglove.websocket.v1"));
  const std::string reply = client.read_until("\"op\":\"advertise\"");
  EXPECT_NE(reply.find("101 Switching Protocols"), std::string::npos);
  EXPECT_NE(reply.find("Sec-WebSocket-Protocol: foxglove.websocket.v1"), std::string::npos);
  EXPECT_NE(reply.find("\"op\":\"serverInfo\""), std::string::npos);
  EXPECT_NE(reply.find("\"topic\":\"pixyslam/odometry\""), std::string::npos);

  RawClient plain(server.port());  // no subprotocol
  plain.send_text(upgrade_request(""));
  EXPECT_NE(plain.read_until("\r\n\r\n").find("400"), std::string::npos);
  RawClient second(server.port());  // one client too many
  second.send_text(upgrade_request("foxglove.websocket.v1"));
  EXPECT_NE(second.read_until("\r\n\r\n").find("503"), std::string::npos);
  EXPECT_TRUE(eventually([&] { return server.counters().clients_refused == 2; }));

  // Subscribed: a published message arrives as opcode 1, subscription id, time, payload.
  client.send_frame(R"({"op":"subscribe","subscriptions":[{"id":42,"channelId":7}]})");
  ASSERT_TRUE(eventually([&] { return server.has_subscribers(7); }));
  server.publish(7, 5, {'P', 'A', 'Y'});
  const std::string data = client.read_until("PAY");
  const std::string frame = {'\x01', 42, 0, 0, 0, 5, 0, 0, 0, 0, 0, 0, 0, 'P', 'A', 'Y'};
  EXPECT_NE(data.find(frame), std::string::npos);
  client.send_frame("{not json");
  EXPECT_NE(client.read_until("not valid JSON").find("\"op\":\"status\""), std::string::npos);
  EXPECT_EQ(server.counters().bad_requests, 1u);
  server.stop();
}

TEST(WsServer, AClientThatStopsReadingLosesItsMessagesNotTheServer) {
  WsServerOptions options;
  options.port = 0;
  options.client_queue_max_bytes = 1 << 16;
  WsServer server(options, one_channel());
  RawClient slow(server.port(), 4096);
  slow.send_text(upgrade_request("foxglove.websocket.v1"));
  slow.read_until("\"op\":\"advertise\"");
  slow.send_frame(R"({"op":"subscribe","subscriptions":[{"id":1,"channelId":7}]})");
  ASSERT_TRUE(eventually([&] { return server.has_subscribers(7); }));
  // 64 MB for a client that reads nothing: the kernel's buffers fill, then the queue.
  for (int i = 0; i < 640; ++i) server.publish(7, i, std::vector<std::uint8_t>(100000, 0x55));
  ASSERT_TRUE(eventually([&] { return server.counters().dropped_slow_client > 0; }));
  // Every message is sent or dropped and counted, once the server thread has taken them all.
  EXPECT_TRUE(eventually([&] {
    const WsServerCounters c = server.counters();
    return c.messages_sent + c.dropped_slow_client + c.dropped_backlog == 640u;
  }));
  EXPECT_LT(server.counters().messages_sent, 640u);
  server.stop();  // returns although the client never reads
}

}  // namespace
}  // namespace pixyslam::foxglove_node
