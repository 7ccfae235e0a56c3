#include "pixyslam/foxglove_node/ws_server.h"

#include <algorithm>
#include <cstdio>
#include <mutex>
#include <random>
#include <set>
#include <stdexcept>
#include <thread>

#include <websocketpp/config/asio_no_tls.hpp>
#include <websocketpp/server.hpp>

namespace pixyslam::foxglove_node {

namespace fox = pixyslam::foxglove;
using Server = websocketpp::server<websocketpp::config::asio>;
using Handle = websocketpp::connection_hdl;

class WsServer::Impl {
 public:
  Impl(const WsServerOptions& options, const std::vector<fox::Channel>& channels)
      : options_(options), channels_(channels), subscriber_counts_(channels.size()) {
    for (const fox::Channel& c : channels_) channel_ids_.push_back(c.id);
    server_.clear_access_channels(websocketpp::log::alevel::all);
    server_.clear_error_channels(websocketpp::log::elevel::all);
    server_.set_error_channels(websocketpp::log::elevel::fatal);
    server_.init_asio();
    server_.set_reuse_addr(true);
    server_.set_max_message_size(options_.max_request_bytes);
    server_.set_validate_handler([this](Handle h) { return on_validate(h); });
    server_.set_open_handler([this](Handle h) { on_open(h); });
    server_.set_close_handler([this](Handle h) { on_close(h); });
    server_.set_fail_handler([](Handle) {});
    server_.set_message_handler([this](Handle h, Server::message_ptr m) { on_message(h, m); });
    std::error_code ec;
    const auto address = websocketpp::lib::asio::ip::make_address(options_.address, ec);
    if (ec) throw std::runtime_error("foxglove_bridge: address '" + options_.address + "' is not an IP address");
    server_.listen(websocketpp::lib::asio::ip::tcp::endpoint(address, options_.port), ec);
    if (ec) {
      throw std::runtime_error("foxglove_bridge: cannot listen on " + options_.address + ":" +
                               std::to_string(options_.port) + ": " + ec.message());
    }
    port_ = server_.get_local_endpoint(ec).port();
    server_.start_accept(ec);
    if (ec) throw std::runtime_error("foxglove_bridge: cannot accept connections: " + ec.message());
    std::random_device seed;
    session_id_ = std::to_string(seed());
    thread_ = std::thread([this] { server_.run(); });
  }

  ~Impl() { stop(); }

  void stop() {
    std::call_once(stopped_, [this] {
      websocketpp::lib::asio::post(server_.get_io_service(), [this] {
        std::error_code ec;
        server_.stop_listening(ec);
        for (const auto& [h, session] : sessions_) server_.close(h, websocketpp::close::status::going_away, "", ec);
        sessions_.clear();
        closed_listening_ = true;
      });
      // Closing handshakes get a moment; then the loop is stopped either way.
      for (int i = 0; i < 50 && !server_.stopped(); ++i) {
        if (clients_now_.load() == 0 && closed_listening_.load()) break;
        std::this_thread::sleep_for(std::chrono::milliseconds(20));
      }
      server_.stop();
      if (thread_.joinable()) thread_.join();
    });
  }

  std::uint16_t port() const { return port_; }

  bool has_subscribers(std::uint32_t channel_id) const {
    const std::size_t i = index_of(channel_id);
    return i < subscriber_counts_.size() && subscriber_counts_[i].load() > 0;
  }

  void publish(std::uint32_t channel_id, std::uint64_t time_ns, std::vector<std::uint8_t> payload) {
    const std::size_t bytes = payload.size();
    if (backlog_bytes_.fetch_add(bytes) + bytes > options_.backlog_max_bytes) {
      backlog_bytes_.fetch_sub(bytes);
      ++dropped_backlog_;
      return;
    }
    websocketpp::lib::asio::post(server_.get_io_service(),
                                 [this, channel_id, time_ns, bytes, p = std::move(payload)] {
                                   backlog_bytes_.fetch_sub(bytes);
                                   send_to_subscribers(channel_id, time_ns, p);
                                 });
  }

  WsServerCounters counters() const {
    WsServerCounters c;
    c.clients_now = clients_now_.load();
    c.clients_accepted = clients_accepted_.load();
    c.clients_refused = clients_refused_.load();
    c.bad_requests = bad_requests_.load();
    c.messages_sent = messages_sent_.load();
    c.dropped_slow_client = dropped_slow_client_.load();
    c.dropped_backlog = dropped_backlog_.load();
    return c;
  }

 private:
  struct Session {
    fox::ClientSession subscriptions;
  };

  std::size_t index_of(std::uint32_t channel_id) const {
    return static_cast<std::size_t>(std::find(channel_ids_.begin(), channel_ids_.end(), channel_id) -
                                    channel_ids_.begin());
  }

  bool on_validate(Handle h) {
    Server::connection_ptr con = server_.get_con_from_hdl(h);
    const std::vector<std::string>& offered = con->get_requested_subprotocols();
    if (std::find(offered.begin(), offered.end(), std::string(fox::kSubprotocol)) == offered.end()) {
      ++clients_refused_;
      con->set_status(websocketpp::http::status_code::bad_request);
      con->set_body("this server speaks the foxglove.websocket.v1 subprotocol only\n");
      return false;
    }
    if (clients_now_.load() >= options_.max_clients) {
      ++clients_refused_;
      con->set_status(websocketpp::http::status_code::service_unavailable);
      con->set_body("too many clients (foxglove_bridge.max_clients)\n");
      return false;
    }
    con->select_subprotocol(std::string(fox::kSubprotocol));
    return true;
  }

  void on_open(Handle h) {
    sessions_.emplace(h, Session{});
    ++clients_now_;
    ++clients_accepted_;
    send_text(h, fox::server_info_json(options_.name, options_.metadata, session_id_));
    send_text(h, fox::advertise_json(channels_));
  }

  void on_close(Handle h) {
    const auto it = sessions_.find(h);
    if (it == sessions_.end()) return;
    for (const auto& [id, channel] : it->second.subscriptions.subscriptions()) --subscriber_counts_[index_of(channel)];
    sessions_.erase(it);
    --clients_now_;
  }

  void on_message(Handle h, Server::message_ptr message) {
    const auto it = sessions_.find(h);
    if (it == sessions_.end()) return;
    if (message->get_opcode() != websocketpp::frame::opcode::text) {
      ++bad_requests_;
      send_status(h, fox::StatusLevel::kError, "binary client messages (client publish, services) are not supported");
      return;
    }
    const fox::ClientRequest request = fox::parse_client_request(message->get_payload());
    if (request.kind == fox::ClientRequest::Kind::kError) {
      ++bad_requests_;
      send_status(h, fox::StatusLevel::kError, request.error);
      return;
    }
    fox::ClientSession& session = it->second.subscriptions;
    const std::map<std::uint32_t, std::uint32_t> before = session.subscriptions();
    const std::vector<std::string> refused = session.apply(request, channel_ids_);
    for (const auto& [id, channel] : before) --subscriber_counts_[index_of(channel)];
    for (const auto& [id, channel] : session.subscriptions()) ++subscriber_counts_[index_of(channel)];
    if (!refused.empty()) {
      ++bad_requests_;
      std::string text = refused.front();
      if (refused.size() > 1) text += " (and " + std::to_string(refused.size() - 1) + " more)";
      send_status(h, fox::StatusLevel::kWarning, text);
    }
  }

  void send_to_subscribers(std::uint32_t channel_id, std::uint64_t time_ns, const std::vector<std::uint8_t>& payload) {
    for (auto& [h, session] : sessions_) {
      for (std::uint32_t subscription : session.subscriptions.subscriptions_of(channel_id)) {
        std::error_code ec;
        Server::connection_ptr con = server_.get_con_from_hdl(h, ec);
        if (ec) continue;
        if (con->get_buffered_amount() + payload.size() > options_.client_queue_max_bytes) {
          ++dropped_slow_client_;
          continue;
        }
        const std::vector<std::uint8_t> frame =
            fox::message_data_frame(subscription, time_ns, payload.data(), payload.size());
        con->send(frame.data(), frame.size(), websocketpp::frame::opcode::binary);
        ++messages_sent_;
      }
    }
  }

  void send_text(Handle h, const std::string& text) {
    std::error_code ec;
    server_.send(h, text, websocketpp::frame::opcode::text, ec);
  }
  void send_status(Handle h, fox::StatusLevel level, const std::string& text) {
    send_text(h, fox::status_json(level, text));
  }

  WsServerOptions options_;
  std::vector<fox::Channel> channels_;
  std::vector<std::uint32_t> channel_ids_;
  std::vector<std::atomic<int>> subscriber_counts_;  // per channel index
  Server server_;
  std::uint16_t port_ = 0;
  std::string session_id_;
  std::map<Handle, Session, std::owner_less<Handle>> sessions_;  // server thread only
  std::atomic<std::size_t> backlog_bytes_{0};
  std::atomic<std::uint64_t> clients_now_{0}, clients_accepted_{0}, clients_refused_{0}, bad_requests_{0},
      messages_sent_{0}, dropped_slow_client_{0}, dropped_backlog_{0};
  std::atomic<bool> closed_listening_{false};
  std::once_flag stopped_;
  std::thread thread_;
};

WsServer::WsServer(const WsServerOptions& options, std::vector<foxglove::Channel> channels)
    : channels_(std::move(channels)), impl_(std::make_unique<Impl>(options, channels_)) {
  port_ = impl_->port();
}

WsServer::~WsServer() = default;

bool WsServer::has_subscribers(std::uint32_t channel_id) const { return impl_->has_subscribers(channel_id); }

void WsServer::publish(std::uint32_t channel_id, std::uint64_t time_ns, std::vector<std::uint8_t> payload) {
  impl_->publish(channel_id, time_ns, std::move(payload));
}

WsServerCounters WsServer::counters() const { return impl_->counters(); }

void WsServer::stop() { impl_->stop(); }

}  // namespace pixyslam::foxglove_node
