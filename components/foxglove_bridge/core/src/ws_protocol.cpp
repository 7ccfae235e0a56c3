#include "pixyslam/foxglove/ws_protocol.h"

#include <algorithm>

#include <nlohmann/json.hpp>

namespace pixyslam::foxglove {

using nlohmann::json;

std::string server_info_json(std::string_view name, const std::map<std::string, std::string>& metadata,
                             std::string_view session_id) {
  json j = {{"op", "serverInfo"},
            {"name", std::string(name)},
            {"capabilities", json::array()},
            {"supportedEncodings", json::array()},
            {"metadata", metadata},
            {"sessionId", std::string(session_id)}};
  return j.dump();
}

std::string advertise_json(const std::vector<Channel>& channels) {
  json list = json::array();
  for (const Channel& c : channels) {
    list.push_back({{"id", c.id},
                    {"topic", c.topic},
                    {"encoding", c.encoding},
                    {"schemaName", c.schema_name},
                    {"schema", c.schema},
                    {"schemaEncoding", c.schema_encoding}});
  }
  return json{{"op", "advertise"}, {"channels", list}}.dump();
}

std::string status_json(StatusLevel level, std::string_view message) {
  // Replace invalid UTF-8 (a client's bytes may be quoted back) rather than throw.
  return json{{"op", "status"}, {"level", static_cast<int>(level)}, {"message", std::string(message)}}.dump(
      -1, ' ', false, json::error_handler_t::replace);
}

std::vector<std::uint8_t> message_data_frame(std::uint32_t subscription_id, std::uint64_t time_ns,
                                             const std::uint8_t* payload, std::size_t size) {
  std::vector<std::uint8_t> frame(1 + 4 + 8 + size);
  frame[0] = 0x01;
  for (int i = 0; i < 4; ++i) frame[1 + i] = static_cast<std::uint8_t>(subscription_id >> (8 * i));
  for (int i = 0; i < 8; ++i) frame[5 + i] = static_cast<std::uint8_t>(time_ns >> (8 * i));
  std::copy(payload, payload + size, frame.begin() + 13);
  return frame;
}

namespace {

// `value[key]` as a uint32, or an error text.
bool read_id(const json& value, const char* key, std::uint32_t& out, std::string& error) {
  const auto it = value.find(key);
  if (it == value.end()) {
    error = std::string("missing \"") + key + "\"";
    return false;
  }
  if (!it->is_number_unsigned() || it->get<std::uint64_t>() > 0xffffffffULL) {
    error = std::string("\"") + key + "\" is not an integer in [0, 4294967295]";
    return false;
  }
  out = static_cast<std::uint32_t>(it->get<std::uint64_t>());
  return true;
}

ClientRequest fail(std::string error) {
  ClientRequest r;
  r.error = std::move(error);
  return r;
}

}  // namespace

ClientRequest parse_client_request(std::string_view text, std::size_t max_items) {
  const json j = json::parse(text.begin(), text.end(), nullptr, /*allow_exceptions=*/false);
  if (j.is_discarded()) return fail("not valid JSON");
  if (!j.is_object()) return fail("not a JSON object");
  const auto op = j.find("op");
  if (op == j.end() || !op->is_string()) return fail("missing \"op\"");
  const std::string name = op->get<std::string>();
  ClientRequest r;
  if (name == "subscribe") {
    const auto list = j.find("subscriptions");
    if (list == j.end() || !list->is_array()) return fail("subscribe: \"subscriptions\" is not an array");
    if (list->size() > max_items) return fail("subscribe: more than " + std::to_string(max_items) + " subscriptions");
    for (const json& s : *list) {
      if (!s.is_object()) return fail("subscribe: an entry is not an object");
      std::uint32_t id = 0, channel = 0;
      std::string error;
      if (!read_id(s, "id", id, error) || !read_id(s, "channelId", channel, error)) return fail("subscribe: " + error);
      r.subscriptions.emplace_back(id, channel);
    }
    r.kind = ClientRequest::Kind::kSubscribe;
    return r;
  }
  if (name == "unsubscribe") {
    const auto list = j.find("subscriptionIds");
    if (list == j.end() || !list->is_array()) return fail("unsubscribe: \"subscriptionIds\" is not an array");
    if (list->size() > max_items) return fail("unsubscribe: more than " + std::to_string(max_items) + " ids");
    for (const json& v : *list) {
      if (!v.is_number_unsigned() || v.get<std::uint64_t>() > 0xffffffffULL) {
        return fail("unsubscribe: an id is not an integer in [0, 4294967295]");
      }
      r.subscription_ids.push_back(static_cast<std::uint32_t>(v.get<std::uint64_t>()));
    }
    r.kind = ClientRequest::Kind::kUnsubscribe;
    return r;
  }
  return fail("op \"" + name.substr(0, 64) + "\" is not supported by this server");
}

std::vector<std::string> ClientSession::apply(const ClientRequest& request,
                                              const std::vector<std::uint32_t>& channel_ids) {
  std::vector<std::string> refused;
  if (request.kind == ClientRequest::Kind::kSubscribe) {
    for (const auto& [id, channel] : request.subscriptions) {
      if (subscriptions_.count(id) != 0) {
        refused.push_back("subscription id " + std::to_string(id) + " is already in use");
      } else if (std::find(channel_ids.begin(), channel_ids.end(), channel) == channel_ids.end()) {
        refused.push_back("channel " + std::to_string(channel) + " is not advertised");
      } else if (subscriptions_.size() >= max_subscriptions_) {
        refused.push_back("more than " + std::to_string(max_subscriptions_) + " subscriptions");
      } else {
        subscriptions_[id] = channel;
      }
    }
  } else if (request.kind == ClientRequest::Kind::kUnsubscribe) {
    for (std::uint32_t id : request.subscription_ids) {
      if (subscriptions_.erase(id) == 0) refused.push_back("subscription id " + std::to_string(id) + " is not in use");
    }
  }
  return refused;
}

std::vector<std::uint32_t> ClientSession::subscriptions_of(std::uint32_t channel_id) const {
  std::vector<std::uint32_t> out;
  for (const auto& [id, channel] : subscriptions_) {
    if (channel == channel_id) out.push_back(id);
  }
  return out;
}

}  // namespace pixyslam::foxglove
