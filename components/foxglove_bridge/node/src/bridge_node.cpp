#include "pixyslam/foxglove_node/bridge_node.h"

#include <stdexcept>

#include "pixyslam/dds/cdr_payload.h"
#include "pixyslam/dds/endpoints.h"

namespace pixyslam::foxglove_node {

namespace {

constexpr std::uint32_t kFirstVisualChannel = 101;

std::uint32_t raw_channel_id(const std::string& topic) {
  const std::vector<dds::TopicInfo>& known = dds::known_topics();
  for (std::size_t i = 0; i < known.size(); ++i) {
    if (known[i].topic == topic) return static_cast<std::uint32_t>(i + 1);
  }
  throw std::invalid_argument("foxglove_bridge: unknown topic '" + topic + "'");
}

std::uint32_t visual_channel_id(foxglove::VisualChannel c) {
  return kFirstVisualChannel + static_cast<std::uint32_t>(c);
}

std::vector<foxglove::Channel> make_channels(const BridgeOptions& options) {
  std::vector<foxglove::Channel> channels;
  for (const std::string& topic : options.topics) {
    const dds::TopicInfo* info = dds::find_topic(topic);
    channels.push_back({raw_channel_id(topic), topic, "cdr", info->type_name,
                        std::string(msg::idl_text(info->idl_stem)), "omgidl"});
  }
  if (options.visuals) {
    const std::vector<foxglove::VisualChannelInfo>& visuals = foxglove::visual_channels();
    for (std::size_t i = 0; i < visuals.size(); ++i) {
      channels.push_back({kFirstVisualChannel + static_cast<std::uint32_t>(i), visuals[i].topic, "cdr",
                          visuals[i].schema_name, std::string(msg::idl_text(visuals[i].idl_stem)), "omgidl"});
    }
  }
  return channels;
}

}  // namespace

namespace detail {

class BridgeSubscription {
 public:
  virtual ~BridgeSubscription() = default;
  virtual std::uint64_t received() const = 0;
  virtual std::uint64_t malformed() const = 0;
  virtual std::uint64_t lost() const = 0;
};

template <class Message>
class TypedBridgeSubscription final : public BridgeSubscription {
 public:
  TypedBridgeSubscription(dds::Participant& participant, BridgeNode& node, std::uint32_t channel_id)
      : reader_(participant, [&node, channel_id](const Message& m) { node.on_sample(channel_id, m); }) {}
  std::uint64_t received() const override { return reader_.received(); }
  std::uint64_t malformed() const override { return reader_.malformed() + reader_.callback_errors(); }
  std::uint64_t lost() const override { return reader_.lost(); }

 private:
  dds::Reader<Message> reader_;
};

}  // namespace detail

BridgeNode::BridgeNode(const BridgeOptions& options) : options_(options), visualiser_(options.visual) {
  if (options_.topics.empty()) {
    options_.topics = dds::known_topic_names();
  }
  WsServerOptions server = options_.server;
  server.metadata["robot_id"] = options_.dds.robot_id;
  server.metadata["dds_domain_id"] = std::to_string(options_.dds.domain_id);
  server_ = std::make_unique<WsServer>(server, make_channels(options_));

  participant_ = std::make_unique<dds::Participant>(options_.dds, "foxglove_bridge");
  for (const std::string& topic : options_.topics) {
    const std::uint32_t id = raw_channel_id(topic);
    if (!dds::visit_topic_type(topic, [&](auto tag) { subscribe<typename decltype(tag)::type>(id); })) {
      throw std::logic_error("foxglove_bridge: no reader for topic '" + topic + "'");
    }
  }
  diagnostics_ = std::make_unique<diagnostics::DiagnosticsPublisher>(
      *participant_, "foxglove_bridge", options_.dds.diagnostics_period_s, [this] { return diagnostics_snapshot(); });
}

BridgeNode::~BridgeNode() { stop(); }

template <class Message>
void BridgeNode::subscribe(std::uint32_t channel_id) {
  subscriptions_.push_back(
      std::make_unique<detail::TypedBridgeSubscription<Message>>(*participant_, *this, channel_id));
}

template <class Message>
void BridgeNode::on_sample(std::uint32_t channel_id, const Message& message) {
  if (server_->has_subscribers(channel_id)) forward(channel_id, dds::to_cdr(message));
  if (!options_.visuals) return;
  // Only the scene messages a client subscribed to are built (the paths grow regardless).
  const auto subscribed = [this](foxglove::VisualChannel c) { return server_->has_subscribers(visual_channel_id(c)); };
  if constexpr (std::is_same_v<Message, msg::MapState>) {
    std::lock_guard<std::mutex> lock(visual_mutex_);
    visualise(visualiser_.on_map_state(message, subscribed));
  } else if constexpr (std::is_same_v<Message, msg::GroundTruth>) {
    std::lock_guard<std::mutex> lock(visual_mutex_);
    visualise(visualiser_.on_ground_truth(message, subscribed));
  }
}

void BridgeNode::forward(std::uint32_t channel_id, std::vector<std::uint8_t> payload) {
  server_->publish(channel_id, dds::now_ns(), std::move(payload));
}

void BridgeNode::visualise(const std::vector<foxglove::VisualMessage>& messages) {
  for (const foxglove::VisualMessage& m : messages) {
    ++visual_messages_;
    const std::uint32_t id = visual_channel_id(m.channel);
    if (server_->has_subscribers(id)) forward(id, m.cdr);
  }
}

BridgeCounters BridgeNode::counters() const {
  std::lock_guard<std::mutex> lock(counters_mutex_);
  BridgeCounters c = readers_at_stop_;
  c.server = server_->counters();
  for (const auto& s : subscriptions_) {
    c.samples_received += s->received();
    c.samples_malformed += s->malformed();
    c.seq_gaps += s->lost();
  }
  c.visual_messages = visual_messages_.load();
  std::lock_guard<std::mutex> visual_lock(visual_mutex_);
  c.visual_other_robot = visualiser_.other_robot();
  return c;
}

diagnostics::Snapshot BridgeNode::diagnostics_snapshot() const {
  const BridgeCounters c = counters();
  diagnostics::Snapshot s;
  s.counters.push_back({"clients_now", c.server.clients_now, false});
  s.counters.push_back({"clients_accepted", c.server.clients_accepted, false});
  s.counters.push_back({"clients_refused", c.server.clients_refused, true});
  s.counters.push_back({"bad_requests", c.server.bad_requests, true});
  s.counters.push_back({"messages_sent", c.server.messages_sent, false});
  s.counters.push_back({"dropped_slow_client", c.server.dropped_slow_client, true});
  s.counters.push_back({"dropped_backlog", c.server.dropped_backlog, true});
  s.counters.push_back({"samples_received", c.samples_received, false});
  s.counters.push_back({"samples_malformed", c.samples_malformed, true});
  s.counters.push_back({"seq_gaps", c.seq_gaps, true});
  s.counters.push_back({"visual_other_robot", c.visual_other_robot, false});
  return s;
}

void BridgeNode::stop() {
  std::call_once(stopped_, [this] {
    diagnostics_.reset();
    std::lock_guard<std::mutex> lock(counters_mutex_);
    for (const auto& s : subscriptions_) {
      readers_at_stop_.samples_received += s->received();
      readers_at_stop_.samples_malformed += s->malformed();
      readers_at_stop_.seq_gaps += s->lost();
    }
    subscriptions_.clear();
    server_->stop();
  });
}

}  // namespace pixyslam::foxglove_node
