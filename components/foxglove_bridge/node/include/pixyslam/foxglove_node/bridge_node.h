#pragma once

#include <atomic>
#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "pixyslam/dds/participant.h"
#include "pixyslam/diagnostics/diagnostics_publisher.h"
#include "pixyslam/foxglove/visualiser.h"
#include "pixyslam/foxglove_node/bridge_options.h"
#include "pixyslam/foxglove_node/ws_server.h"

namespace pixyslam::foxglove_node {

namespace detail {
class BridgeSubscription;
template <class Message>
class TypedBridgeSubscription;
}  // namespace detail

struct BridgeCounters {
  WsServerCounters server;
  std::uint64_t samples_received = 0;   // DDS samples of every bridged topic
  std::uint64_t samples_malformed = 0;  // did not decode (dropped by the readers)
  std::uint64_t seq_gaps = 0;           // header seq numbers skipped, per writer
  std::uint64_t visual_messages = 0;    // pixyslam/viz/* messages made (for subscribed channels only)
  std::uint64_t visual_other_robot = 0; // MapState/GroundTruth of robots other than the one drawn
};

// The foxglove_bridge process: every selected DDS topic as a Foxglove channel
// ("cdr" with its OMG IDL schema, the payload exactly as the DDS writer sent
// it), plus the Visualiser's pixyslam/viz/* channels made from MapState and
// GroundTruth. Channel ids: 1 + the topic's index in known_topics(); 101 + the
// VisualChannel index. Serializes only for channels a client subscribed to.
class BridgeNode {
 public:
  explicit BridgeNode(const BridgeOptions& options);
  ~BridgeNode();
  BridgeNode(const BridgeNode&) = delete;
  BridgeNode& operator=(const BridgeNode&) = delete;

  std::uint16_t port() const { return server_->port(); }
  const std::vector<foxglove::Channel>& channels() const { return server_->channels(); }
  BridgeCounters counters() const;
  // Unsubscribes from DDS, closes every client. Idempotent; the destructor calls it.
  void stop();

 private:
  template <class Message>
  friend class detail::TypedBridgeSubscription;
  template <class Message>
  void subscribe(std::uint32_t channel_id);
  // From DDS callbacks.
  void forward(std::uint32_t channel_id, std::vector<std::uint8_t> payload);
  void visualise(const std::vector<foxglove::VisualMessage>& messages);
  template <class Message>
  void on_sample(std::uint32_t channel_id, const Message& message);
  diagnostics::Snapshot diagnostics_snapshot() const;

  BridgeOptions options_;
  std::unique_ptr<WsServer> server_;
  mutable std::mutex visual_mutex_;
  foxglove::Visualiser visualiser_;
  std::atomic<std::uint64_t> visual_messages_{0};
  mutable std::mutex counters_mutex_;
  BridgeCounters readers_at_stop_;  // the readers' counts, kept when stop() deletes them
  // Declared last so they go first: no callback may outlive the server.
  std::unique_ptr<dds::Participant> participant_;
  std::unique_ptr<diagnostics::DiagnosticsPublisher> diagnostics_;
  std::vector<std::unique_ptr<detail::BridgeSubscription>> subscriptions_;
  std::once_flag stopped_;
};

}  // namespace pixyslam::foxglove_node
