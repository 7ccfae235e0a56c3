#pragma once

#include <cstddef>
#include <cstdint>
#include <map>
#include <string>
#include <string_view>
#include <vector>

// The Foxglove WebSocket protocol, subprotocol "foxglove.websocket.v1"
// (github.com/foxglove/ws-protocol, docs/spec.md), server side: the JSON and
// binary messages and one client's subscriptions. Pure: no sockets.
namespace pixyslam::foxglove {

inline constexpr std::string_view kSubprotocol = "foxglove.websocket.v1";

// One advertised channel: a topic with its encoding and schema.
struct Channel {
  std::uint32_t id = 0;
  std::string topic;            // e.g. "pixyslam/odometry"
  std::string encoding;         // message encoding: "cdr"
  std::string schema_name;      // e.g. "pixyslam::msg::Odometry", "foxglove::SceneUpdate"
  std::string schema;           // the schema text (OMG IDL, includes inlined)
  std::string schema_encoding;  // "omgidl"
};

enum class StatusLevel { kInfo = 0, kWarning = 1, kError = 2 };

// Server -> client, text frames.
std::string server_info_json(std::string_view name, const std::map<std::string, std::string>& metadata,
                             std::string_view session_id);
std::string advertise_json(const std::vector<Channel>& channels);
std::string status_json(StatusLevel level, std::string_view message);

// Server -> client, binary "message data" frame: opcode 0x01, subscription id
// (uint32 LE), receive time in ns (uint64 LE), then the payload as sent on the
// channel (for "cdr": the encapsulation header and the CDR bytes).
std::vector<std::uint8_t> message_data_frame(std::uint32_t subscription_id, std::uint64_t time_ns,
                                             const std::uint8_t* payload, std::size_t size);

// A client's text frame, parsed. Only the ops this server takes are decoded;
// everything else is kError with `error` saying what was wrong.
struct ClientRequest {
  enum class Kind { kSubscribe, kUnsubscribe, kError } kind = Kind::kError;
  std::vector<std::pair<std::uint32_t, std::uint32_t>> subscriptions;  // (subscription id, channel id)
  std::vector<std::uint32_t> subscription_ids;                         // unsubscribe
  std::string error;
};

// Parses one text frame. Never throws: malformed JSON, a missing or mistyped
// field, an id outside uint32 or more than `max_items` entries give kError.
ClientRequest parse_client_request(std::string_view text, std::size_t max_items = 1024);

// One client's subscriptions (subscription id -> channel id), with the
// protocol's rules: a subscription id is used once, the channel must be
// advertised, at most `max_subscriptions`.
class ClientSession {
 public:
  ClientSession() = default;
  explicit ClientSession(std::size_t max_subscriptions) : max_subscriptions_(max_subscriptions) {}

  // Applies a subscribe/unsubscribe against the advertised channel ids. Returns
  // one text per refused entry (the rest are applied).
  std::vector<std::string> apply(const ClientRequest& request, const std::vector<std::uint32_t>& channel_ids);

  // The subscription ids on `channel_id` (a client may subscribe twice).
  std::vector<std::uint32_t> subscriptions_of(std::uint32_t channel_id) const;
  const std::map<std::uint32_t, std::uint32_t>& subscriptions() const { return subscriptions_; }

 private:
  std::size_t max_subscriptions_ = 1024;
  std::map<std::uint32_t, std::uint32_t> subscriptions_;
};

}  // namespace pixyslam::foxglove
