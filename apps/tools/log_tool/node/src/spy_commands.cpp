#include "pixyslam/log_tool/spy_commands.h"

#include <algorithm>
#include <cstdlib>
#include <chrono>
#include <condition_variable>
#include <cstdio>
#include <deque>
#include <iostream>
#include <map>
#include <mutex>
#include <sstream>
#include <tuple>
#include <stdexcept>
#include <vector>

#include <fastdds/dds/domain/DomainParticipant.hpp>
#include <fastdds/dds/domain/DomainParticipantFactory.hpp>
#include <fastdds/dds/domain/DomainParticipantListener.hpp>
#include <fastdds/dds/publisher/Publisher.hpp>
#include <fastdds/dds/publisher/qos/DataWriterQos.hpp>
#include <fastdds/dds/subscriber/Subscriber.hpp>
#include <fastdds/dds/subscriber/qos/DataReaderQos.hpp>

#include "pixyslam/app/stop_signal.h"
#include "pixyslam/dds/cdr_payload.h"
#include "pixyslam/dds/endpoints.h"
#include "pixyslam/log_tool/message_format.h"

namespace pixyslam::log_tool {

namespace fdds = eprosima::fastdds::dds;
namespace rtps = eprosima::fastrtps::rtps;

namespace {

using Clock = std::chrono::steady_clock;

// Sleeps until `seconds` passed (0: forever) or a stop signal; `done` may end it earlier.
template <class Done>
void wait(double seconds, Done done) {
  const auto end = Clock::now() + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(seconds));
  while (!done() && (seconds <= 0.0 || Clock::now() < end)) {
    if (app::StopSignal::wait_for(std::chrono::milliseconds(20))) return;
  }
}

std::string text(const std::ostringstream& os) { return os.str(); }

template <class T>
std::string to_text(const T& value) {
  std::ostringstream os;
  os << value;
  return text(os);
}

const char* reliability_name(fdds::ReliabilityQosPolicyKind k) {
  return k == fdds::RELIABLE_RELIABILITY_QOS ? "reliable" : "best_effort";
}

const char* durability_name(fdds::DurabilityQosPolicyKind k) {
  switch (k) {
    case fdds::VOLATILE_DURABILITY_QOS: return "volatile";
    case fdds::TRANSIENT_LOCAL_DURABILITY_QOS: return "transient_local";
    case fdds::TRANSIENT_DURABILITY_QOS: return "transient";
    case fdds::PERSISTENT_DURABILITY_QOS: return "persistent";
  }
  return "?";
}

std::string history_name(const fdds::HistoryQosPolicy& h) {
  return h.kind == fdds::KEEP_ALL_HISTORY_QOS ? "keep_all" : "keep_last " + std::to_string(h.depth);
}

// What discovery told about one remote participant.
struct ParticipantEntry {
  std::string name;
  std::string guid_prefix;
  std::map<std::string, std::string> properties;
  bool alive = true;
};

// One remote writer or reader.
struct EndpointEntry {
  bool writer = true;
  std::string topic;
  std::string type;
  std::string participant_prefix;
  std::string reliability;
  std::string durability;
  bool type_information = false;
  bool alive = true;
};

// Collects discovery events (called on Fast DDS threads) under one lock.
class DiscoveryListener : public fdds::DomainParticipantListener {
 public:
  void on_participant_discovery(fdds::DomainParticipant*, rtps::ParticipantDiscoveryInfo&& info) override {
    const std::string prefix = to_text(info.info.m_guid.guidPrefix);
    std::lock_guard<std::mutex> lock(mutex_);
    ParticipantEntry& e = participants_[prefix];
    e.guid_prefix = prefix;
    switch (info.status) {
      case rtps::ParticipantDiscoveryInfo::DISCOVERED_PARTICIPANT:
      case rtps::ParticipantDiscoveryInfo::CHANGED_QOS_PARTICIPANT:
        e.alive = true;
        e.name = info.info.m_participantName.to_string();
        for (const auto& p : info.info.m_properties) e.properties[p.first()] = p.second();
        break;
      default:
        e.alive = false;
    }
  }

  void on_publisher_discovery(fdds::DomainParticipant*, rtps::WriterDiscoveryInfo&& info) override {
    on_endpoint(info.info, true,
                info.status == rtps::WriterDiscoveryInfo::DISCOVERED_WRITER ||
                    info.status == rtps::WriterDiscoveryInfo::CHANGED_QOS_WRITER);
  }

  void on_subscriber_discovery(fdds::DomainParticipant*, rtps::ReaderDiscoveryInfo&& info) override {
    on_endpoint(info.info, false,
                info.status == rtps::ReaderDiscoveryInfo::DISCOVERED_READER ||
                    info.status == rtps::ReaderDiscoveryInfo::CHANGED_QOS_READER);
  }

  // A writer's or reader's announcement (WriterProxyData / ReaderProxyData).
  template <class ProxyData>
  void on_endpoint(const ProxyData& data, bool writer, bool alive) {
    EndpointEntry e;
    e.writer = writer;
    e.topic = data.topicName().to_string();
    e.type = data.typeName().to_string();
    e.participant_prefix = to_text(data.guid().guidPrefix);
    e.reliability = reliability_name(data.m_qos.m_reliability.kind);
    e.durability = durability_name(data.m_qos.m_durability.kind);
    e.type_information = data.has_type_information();
    e.alive = alive;
    store(to_text(data.guid()), std::move(e));
  }

  std::map<std::string, ParticipantEntry> participants() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return participants_;
  }
  std::map<std::string, EndpointEntry> endpoints() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return endpoints_;
  }

 private:
  void store(const std::string& guid, EndpointEntry e) {
    std::lock_guard<std::mutex> lock(mutex_);
    endpoints_[guid] = std::move(e);
  }

  mutable std::mutex mutex_;
  std::map<std::string, ParticipantEntry> participants_;  // by GUID prefix
  std::map<std::string, EndpointEntry> endpoints_;        // by GUID
};

// A bare participant with the discovery listener attached from creation (a
// listener set afterwards would miss the first announcements), from the same
// XML profile as every pixyslam process.
class DiscoveryParticipant {
 public:
  DiscoveryParticipant(const dds::DdsOptions& options, DiscoveryListener& listener) {
    participant_ = dds::create_participant(options, "pixyslam_spy", &listener);
    publisher_ = participant_->create_publisher(fdds::PUBLISHER_QOS_DEFAULT);
    subscriber_ = participant_->create_subscriber(fdds::SUBSCRIBER_QOS_DEFAULT);
  }
  ~DiscoveryParticipant() {
    participant_->set_listener(nullptr);
    participant_->delete_contained_entities();
    fdds::DomainParticipantFactory::get_instance()->delete_participant(participant_);
  }
  DiscoveryParticipant(const DiscoveryParticipant&) = delete;
  DiscoveryParticipant& operator=(const DiscoveryParticipant&) = delete;

  // History of the local XML profile named like the topic ("" if none).
  std::string profile_history(const std::string& topic, bool writer) const {
    if (writer) {
      fdds::DataWriterQos qos;
      if (publisher_ == nullptr || publisher_->get_datawriter_qos_from_profile(topic, qos) != ReturnCode_t::RETCODE_OK) return "";
      return history_name(qos.history());
    }
    fdds::DataReaderQos qos;
    if (subscriber_ == nullptr || subscriber_->get_datareader_qos_from_profile(topic, qos) != ReturnCode_t::RETCODE_OK) return "";
    return history_name(qos.history());
  }

 private:
  fdds::DomainParticipant* participant_ = nullptr;
  fdds::Publisher* publisher_ = nullptr;
  fdds::Subscriber* subscriber_ = nullptr;
};

// Rows of cells printed as columns two spaces apart (the last one unpadded).
void print_table(const std::vector<std::vector<std::string>>& rows, const std::string& indent, std::ostream& out) {
  std::vector<std::size_t> widths;
  for (const auto& row : rows) {
    widths.resize(std::max(widths.size(), row.size()), 0);
    for (std::size_t i = 0; i < row.size(); ++i) widths[i] = std::max(widths[i], row[i].size());
  }
  for (const auto& row : rows) {
    std::string line = indent;
    for (std::size_t i = 0; i < row.size(); ++i) {
      line += row[i];
      if (i + 1 < row.size()) line.append(widths[i] - row[i].size() + 2, ' ');
    }
    while (!line.empty() && line.back() == ' ') line.pop_back();
    out << line << "\n";
  }
}

std::string property(const ParticipantEntry& p, const std::string& key) {
  const auto it = p.properties.find(key);
  return it == p.properties.end() || it->second.empty() ? "-" : it->second;
}

std::string participant_label(const std::map<std::string, ParticipantEntry>& participants, const std::string& prefix) {
  const auto it = participants.find(prefix);
  if (it == participants.end()) return "(unknown participant " + prefix + ")";
  std::string label = it->second.name.empty() ? "(unnamed)" : it->second.name;
  const std::string pid = property(it->second, "pixyslam.pid");
  if (pid != "-") label += " (pid " + pid + ")";
  return label;
}

// Dispatches on the topic name to the project's message type.
template <class Function>
int with_topic_type(const std::string& topic, Function f) {
  int status = 2;
  if (dds::visit_topic_type(topic, [&](auto tag) { status = f(typename decltype(tag)::type{}); })) return status;
  std::string known;
  for (const dds::TopicInfo& t : dds::known_topics()) known += (known.empty() ? "" : ", ") + t.topic;
  std::fprintf(stderr, "pixyslam_spy: unknown topic '%s'; known: %s\n", topic.c_str(), known.c_str());
  return 2;
}

// mean/min/max/std of a gap statistic in milliseconds.
Value gap_value(const GapStats& g) {
  return Value::structure()
      .add("mean", Value::number(g.mean_s * 1e3))
      .add("min", Value::number(g.min_s * 1e3))
      .add("max", Value::number(g.max_s * 1e3))
      .add("std", Value::number(g.std_s * 1e3));
}

}  // namespace

int run_participants(const dds::DdsOptions& dds, double seconds, bool json, std::ostream& out) {
  DiscoveryListener listener;
  DiscoveryParticipant participant(dds, listener);
  wait(seconds, [] { return false; });
  const auto participants = listener.participants();
  if (json) {
    for (const auto& [prefix, p] : participants) {
      if (!p.alive) continue;
      out << to_json_line(Value::structure()
                              .add("name", Value::string(p.name))
                              .add("guid_prefix", Value::string(prefix))
                              .add("host", Value::string(property(p, "pixyslam.host")))
                              .add("pid", Value::string(property(p, "pixyslam.pid")))
                              .add("process", Value::string(property(p, "pixyslam.process"))))
          << "\n";
    }
    return 0;
  }
  std::size_t alive = 0;
  for (const auto& [prefix, p] : participants) alive += p.alive ? 1 : 0;
  out << "participants on domain " << dds.domain_id << ": " << alive << " (discovery for " << seconds << " s)\n";
  std::vector<std::vector<std::string>> rows{{"name", "guid prefix", "host", "pid", "process"}};
  for (const auto& [prefix, p] : participants) {
    if (!p.alive) continue;
    rows.push_back({p.name.empty() ? "(unnamed)" : p.name, prefix, property(p, "pixyslam.host"),
                    property(p, "pixyslam.pid"), property(p, "pixyslam.process")});
  }
  print_table(rows, "", out);
  return 0;
}

int run_topics(const dds::DdsOptions& dds, double seconds, bool json, std::ostream& out) {
  DiscoveryListener listener;
  DiscoveryParticipant participant(dds, listener);
  wait(seconds, [] { return false; });
  const auto participants = listener.participants();
  // topic -> type -> endpoints (sorted writers first, then by participant)
  std::map<std::string, std::map<std::string, std::vector<EndpointEntry>>> topics;
  for (const auto& [guid, e] : listener.endpoints()) {
    if (e.alive) topics[e.topic][e.type].push_back(e);
  }
  if (!json) {
    out << "topics on domain " << dds.domain_id << ": " << topics.size() << " (discovery for " << seconds << " s)\n";
  }
  for (auto& [topic, types] : topics) {
    for (auto& [type, endpoints] : types) {
      std::stable_sort(endpoints.begin(), endpoints.end(), [&](const EndpointEntry& a, const EndpointEntry& b) {
        if (a.writer != b.writer) return a.writer;
        return participant_label(participants, a.participant_prefix) <
               participant_label(participants, b.participant_prefix);
      });
      std::size_t writers = 0;
      for (const EndpointEntry& e : endpoints) writers += e.writer ? 1 : 0;
      if (json) {
        Value list = Value::list();
        for (const EndpointEntry& e : endpoints) {
          list.push(Value::structure()
                        .add("kind", Value::string(e.writer ? "writer" : "reader"))
                        .add("participant", Value::string(participant_label(participants, e.participant_prefix)))
                        .add("reliability", Value::string(e.reliability))
                        .add("durability", Value::string(e.durability))
                        .add("history", Value::string(participant.profile_history(topic, e.writer)))
                        .add("type_information", Value::boolean(e.type_information)));
        }
        out << to_json_line(Value::structure()
                                .add("topic", Value::string(topic))
                                .add("type", Value::string(type))
                                .add("writers", Value::unsigned_integer(writers))
                                .add("readers", Value::unsigned_integer(endpoints.size() - writers))
                                .add("endpoints", std::move(list)))
            << "\n";
        continue;
      }
      out << topic << "  [" << type << "]  " << writers << " writer(s), " << endpoints.size() - writers
          << " reader(s)\n";
      std::vector<std::vector<std::string>> rows;
      for (const EndpointEntry& e : endpoints) {
        const std::string history = participant.profile_history(topic, e.writer);
        rows.push_back({e.writer ? "writer" : "reader", participant_label(participants, e.participant_prefix),
                        e.reliability, e.durability,
                        "history " + (history.empty() ? std::string("? (not announced)") : history + " (local profile)"),
                        e.type_information ? "type_information" : ""});
      }
      print_table(rows, "  ", out);
    }
  }
  return 0;
}

namespace {

// Which writer a sample comes from, as far as echo tells them apart: the
// robot and frame, and for diagnostics the process.
template <class Message>
std::string writer_key(const Message& m) {
  return m.header().robot_id() + "/" + m.header().frame_id();
}
std::string writer_key(const msg::Diagnostics& m) {
  return m.header().robot_id() + "/" + m.process() + "/" + std::to_string(m.pid());
}

// A reader that joins late gets each transient-local writer's kept history at
// once, oldest first: of what arrives within this time of the first sample,
// echo prints only the newest per writer (the current map, not one seconds old).
constexpr auto kHistoryWindow = std::chrono::milliseconds(300);

struct PendingSample {
  std::string text;
  std::string writer;
};

// The newest sample per writer, in arrival order.
void keep_newest_per_writer(std::deque<PendingSample>& pending) {
  std::map<std::string, std::size_t> newest;
  for (std::size_t i = 0; i < pending.size(); ++i) newest[pending[i].writer] = i;
  std::deque<PendingSample> kept;
  for (std::size_t i = 0; i < pending.size(); ++i) {
    if (newest[pending[i].writer] == i) kept.push_back(std::move(pending[i]));
  }
  pending.swap(kept);
}

}  // namespace

// Samples waiting for the output at most (echo) and reporters kept at most
// (diagnostics): a flood, or output slower than the input (a paused pager),
// must not grow the spy's memory without end.
constexpr std::size_t kMaxPendingSamples = 10000;
constexpr std::size_t kMaxReporters = 4096;

int run_echo(const dds::DdsOptions& options, const EchoRequest& request, std::ostream& out) {
  return with_topic_type(request.topic, [&](auto tag) {
    using Message = decltype(tag);
    std::mutex mutex;
    std::condition_variable cv;
    std::deque<PendingSample> pending;
    std::uint64_t overrun = 0;  // oldest pending samples dropped at kMaxPendingSamples
    Clock::time_point first_arrival{};
    dds::Participant participant(options, "pixyslam_spy");
    dds::Reader<Message> reader(participant, [&](const Message& m) {
      const Value value = to_value(m);
      std::string text = request.json ? to_json_line(value) + "\n" : to_yaml_document(value);
      std::lock_guard<std::mutex> lock(mutex);
      if (first_arrival == Clock::time_point{}) first_arrival = Clock::now();
      if (pending.size() >= kMaxPendingSamples) {
        pending.pop_front();
        ++overrun;
      }
      pending.push_back({std::move(text), writer_key(m)});
      cv.notify_all();
    }, request.robot);
    std::size_t printed = 0;
    bool history_done = false;
    const auto end = Clock::now() + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(request.seconds));
    while (!app::StopSignal::requested() && (request.count == 0 || printed < request.count) &&
           (request.seconds <= 0.0 || Clock::now() < end)) {
      std::unique_lock<std::mutex> lock(mutex);
      cv.wait_for(lock, std::chrono::milliseconds(50), [&] { return !pending.empty(); });
      if (!history_done) {
        if (pending.empty() || Clock::now() < first_arrival + kHistoryWindow) continue;
        keep_newest_per_writer(pending);
        history_done = true;
      }
      // Written without the lock: a slow reader of the output (a paused pager)
      // must not block the DDS thread, which then drops the oldest instead.
      std::deque<PendingSample> batch;
      while (!pending.empty() && (request.count == 0 || printed + batch.size() < request.count)) {
        batch.push_back(std::move(pending.front()));
        pending.pop_front();
      }
      lock.unlock();
      for (const PendingSample& p : batch) out << p.text;
      printed += batch.size();
      out.flush();
    }
    const std::uint64_t malformed = reader.malformed() + reader.callback_errors();
    if (malformed > 0) {
      std::fprintf(stderr, "pixyslam_spy: echo %s: %llu malformed samples dropped\n", request.topic.c_str(),
                   static_cast<unsigned long long>(malformed));
    }
    std::lock_guard<std::mutex> lock(mutex);
    if (overrun > 0) {
      std::fprintf(stderr, "pixyslam_spy: echo %s: %llu samples dropped: the output was slower than the input\n",
                   request.topic.c_str(), static_cast<unsigned long long>(overrun));
    }
    if (request.count > 0 && printed < request.count) {
      std::fprintf(stderr, "pixyslam_spy: echo %s: %zu of %zu samples received\n", request.topic.c_str(), printed,
                   request.count);
      return 1;
    }
    return 0;
  });
}

int run_diagnostics(const dds::DdsOptions& options, double seconds, bool json, std::ostream& out) {
  std::mutex mutex;
  std::map<std::tuple<std::string, std::string, std::uint32_t>, msg::Diagnostics> latest;
  dds::Participant participant(options, "pixyslam_spy");
  dds::Reader<msg::Diagnostics> reader(participant, [&](const msg::Diagnostics& m) {
    std::lock_guard<std::mutex> lock(mutex);
    std::tuple<std::string, std::string, std::uint32_t> key{m.header().robot_id(), m.process(), m.pid()};
    if (latest.size() >= kMaxReporters && latest.count(key) == 0) return;  // a flood of invented reporters
    latest[std::move(key)] = m;
  });
  wait(seconds, [] { return false; });
  std::lock_guard<std::mutex> lock(mutex);
  if (latest.empty()) {
    (json ? std::cerr : out) << "no diagnostics received in " << format_double(seconds) << " s\n";  // JSON: stdout stays JSON
    return 1;
  }
  std::vector<msg::Diagnostics> reports;
  for (const auto& [key, report] : latest) reports.push_back(report);
  if (json) {
    for (const msg::Diagnostics& report : reports) out << to_json_line(to_value(report)) << "\n";
    return 0;
  }
  out << diagnostics_table(reports);
  return 0;
}

int run_hz(const dds::DdsOptions& options, const std::string& topic, double seconds, bool json, std::ostream& out,
           const std::string& robot) {
  return with_topic_type(topic, [&](auto tag) {
    using Message = decltype(tag);
    std::mutex mutex;
    GapAccumulator arrivals, stamps;  // constant memory however long it listens
    const auto start = Clock::now();
    dds::Participant participant(options, "pixyslam_spy");
    dds::Reader<Message> reader(participant, [&](const Message& m) {
      const double t = std::chrono::duration<double>(Clock::now() - start).count();
      std::lock_guard<std::mutex> lock(mutex);
      arrivals.add(t);
      stamps.add(static_cast<double>(m.header().stamp_ns()) * 1e-9);
    }, robot);
    // A line every second while listening (as ros2 topic hz): the rate over the
    // last second and over everything so far.
    std::size_t reported = 0;
    for (double next_report_s = 1.0;; next_report_s += 1.0) {
      const double remaining_s = seconds > 0.0 ? seconds - std::chrono::duration<double>(Clock::now() - start).count()
                                               : next_report_s;
      if (remaining_s <= 0.0) break;
      const double now_s = std::chrono::duration<double>(Clock::now() - start).count();
      wait(std::max(1e-3, std::min(remaining_s, next_report_s - now_s)), [] { return false; });  // 0 would wait for ever
      if (app::StopSignal::requested() ||
          (seconds > 0.0 && std::chrono::duration<double>(Clock::now() - start).count() >= seconds)) {
        break;
      }
      std::lock_guard<std::mutex> lock(mutex);
      const GapStats so_far = arrivals.stats();
      const std::size_t last_second = so_far.messages - reported;
      reported = so_far.messages;
      const double rate_hz = so_far.messages >= 2 ? so_far.rate_hz : 0.0;
      if (json) {
        out << to_json_line(Value::structure()
                                .add("t_s", Value::number(next_report_s))
                                .add("last_second", Value::unsigned_integer(last_second))
                                .add("rate_hz", Value::number(rate_hz)))
            << "\n" << std::flush;
        continue;
      }
      char line[160];
      std::snprintf(line, sizeof(line), "  %4.0f s: %zu messages in the last second, %.3f Hz since the start\n",
                    next_report_s, last_second, rate_hz);
      out << line << std::flush;
    }
    const double listened_s = std::chrono::duration<double>(Clock::now() - start).count();
    std::lock_guard<std::mutex> lock(mutex);
    const GapStats arrival = arrivals.stats();
    const GapStats stamp = stamps.stats();  // not sorted: a reordering shows as a negative min
    if (json) {
      Value summary = Value::structure()
                          .add("topic", Value::string(topic))
                          .add("messages", Value::unsigned_integer(arrival.messages))
                          .add("listened_s", Value::number(std::round(listened_s * 100) / 100));
      if (arrival.messages >= 2) {
        summary.add("rate_hz", Value::number(arrival.rate_hz))
            .add("arrival_gap_ms", gap_value(arrival))
            .add("stamp_gap_ms", gap_value(stamp));
      }
      out << to_json_line(summary) << "\n";
      return 0;
    }
    char line[256];
    out << topic << ": " << arrival.messages << " messages in " << format_double(std::round(listened_s * 100) / 100)
        << " s\n";
    if (arrival.messages < 2) {
      out << "  fewer than two messages: no rate\n";
      return 0;
    }
    std::snprintf(line, sizeof(line), "  rate %.3f Hz\n", arrival.rate_hz);
    out << line;
    std::snprintf(line, sizeof(line), "  arrival gap  mean %.3f ms  min %.3f ms  max %.3f ms  std %.3f ms\n",
                  arrival.mean_s * 1e3, arrival.min_s * 1e3, arrival.max_s * 1e3, arrival.std_s * 1e3);
    out << line;
    std::snprintf(line, sizeof(line), "  stamp gap    mean %.3f ms  min %.3f ms  max %.3f ms  std %.3f ms\n",
                  stamp.mean_s * 1e3, stamp.min_s * 1e3, stamp.max_s * 1e3, stamp.std_s * 1e3);
    out << line;
    return 0;
  });
}

}  // namespace pixyslam::log_tool
