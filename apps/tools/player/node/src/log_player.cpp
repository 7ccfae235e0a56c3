#include "pixyslam/player/log_player.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <limits>
#include <map>
#include <numeric>
#include <stdexcept>
#include <thread>

#include "pixyslam/app/stop_signal.h"
#include "pixyslam/dds/endpoints.h"
#include "pixyslam/dds/cdr_payload.h"
#include "pixyslam/dds/topic_selection.h"

namespace pixyslam::player {

constexpr std::size_t kNotPlayed = std::numeric_limits<std::size_t>::max();

// One played topic: decodes recorded payloads into its type and writes them.
class LogPlayer::Channel {
 public:
  explicit Channel(std::string topic) : report_{std::move(topic)} {}
  virtual ~Channel() = default;
  // Decodes, restamps by `offset_ns` (when `restamp`) and writes one sample.
  virtual void publish(const std::vector<std::uint8_t>& payload, bool restamp, std::int64_t offset_ns) = 0;
  virtual int matched_readers() const = 0;
  virtual bool wait_for_acknowledgments(std::chrono::milliseconds timeout) = 0;
  TopicReport& report() { return report_; }

 protected:
  TopicReport report_;
};

namespace {

template <class Message>
class TypedChannel final : public LogPlayer::Channel {
 public:
  explicit TypedChannel(dds::Participant& participant)
      : Channel(std::string(dds::MessageTraits<Message>::topic)), writer_(participant) {}

  void publish(const std::vector<std::uint8_t>& payload, bool restamp, std::int64_t offset_ns) override {
    std::string error;
    if (!dds::from_cdr(payload, sample_, error)) {
      ++report_.undecodable;
      return;
    }
    if (restamp) sample_.header().stamp_ns(shift_stamp(sample_.header().stamp_ns(), offset_ns));
    if (writer_.publish_as_is(sample_)) {
      ++report_.published;
    } else {
      ++report_.refused;
    }
  }
  int matched_readers() const override { return writer_.matched_readers(); }
  bool wait_for_acknowledgments(std::chrono::milliseconds timeout) override {
    return writer_.wait_for_acknowledgments(timeout);
  }

 private:
  dds::Writer<Message> writer_;
  Message sample_;
};

std::unique_ptr<LogPlayer::Channel> make_channel(const std::string& topic, dds::Participant& participant) {
  std::unique_ptr<LogPlayer::Channel> channel;
  dds::visit_topic_type(topic, [&](auto tag) {
    channel = std::make_unique<TypedChannel<typename decltype(tag)::type>>(participant);
  });
  if (!channel) throw std::logic_error("no channel type for " + topic);
  return channel;
}

// Sleeps until `until`, waking every 100 ms for a stop; false if stopped.
bool sleep_until(std::chrono::steady_clock::time_point until) {
  while (std::chrono::steady_clock::now() < until) {
    if (app::StopSignal::requested()) return false;
    const auto left = until - std::chrono::steady_clock::now();
    std::this_thread::sleep_for(std::min<std::chrono::steady_clock::duration>(left, std::chrono::milliseconds(100)));
  }
  return !app::StopSignal::requested();
}

}  // namespace

LogPlayer::LogPlayer(const PlayerOptions& options, std::ostream& log) : options_(options), log_(log) {
  validate(options_.playback);
  if (options_.files.empty()) throw std::invalid_argument("no log file given");

  // Topics of the logs that the project knows (with a CDR channel).
  std::vector<std::string> in_logs;
  for (const std::string& file : options_.files) {
    readers_.push_back(std::make_unique<mcap::McapReader>(file));
    const mcap::McapReader& reader = *readers_.back();
    if (!reader.clean()) {
      log_ << "pixyslam_play: " << file << " is incomplete (" << reader.recovery().messages_recovered
           << " messages recovered); playing what was recovered\n";
    }
    for (const mcap::McapChannel& channel : reader.channels()) {
      if (dds::find_topic(channel.topic) == nullptr || channel.message_encoding != "cdr") {
        log_ << "pixyslam_play: " << file << ": skipping channel '" << channel.topic << "' ("
             << channel.message_encoding << "): not a topic of this project\n";
        continue;
      }
      if (std::find(in_logs.begin(), in_logs.end(), channel.topic) == in_logs.end()) in_logs.push_back(channel.topic);
    }
  }
  if (in_logs.empty()) throw std::runtime_error("no topic of this project in " + options_.files.front());
  std::vector<std::string> played = in_logs;
  if (!options_.topics.empty()) {
    const dds::TopicSelection selection = dds::select_topics(options_.topics, in_logs);
    if (!selection.error.empty()) {
      throw std::invalid_argument("--topics '" + options_.topics[selection.bad_pattern] + "': " + selection.error);
    }
    played = selection.topics;
  }

  participant_ = std::make_unique<dds::Participant>(options_.dds, "pixyslam_play");
  std::map<std::string, std::size_t> channel_of_topic;
  for (const std::string& topic : played) {
    channel_of_topic[topic] = channels_.size();
    channels_.push_back(make_channel(topic, *participant_));
  }

  for (std::size_t f = 0; f < readers_.size(); ++f) {
    const mcap::McapReader& reader = *readers_[f];
    for (std::size_t m = 0; m < reader.messages().size(); ++m) {
      const mcap::McapChannel* channel = reader.find_channel(reader.messages()[m].channel_id);
      std::size_t index = kNotPlayed;
      if (channel != nullptr && channel->message_encoding == "cdr") {
        const auto it = channel_of_topic.find(channel->topic);
        if (it != channel_of_topic.end()) index = it->second;
      }
      entries_.push_back({f, m, index});
    }
  }
  const auto log_time = [&](const Entry& e) { return readers_[e.file]->messages()[e.message].log_time_ns; };
  std::stable_sort(entries_.begin(), entries_.end(),
                   [&](const Entry& a, const Entry& b) { return log_time(a) < log_time(b); });
  for (const Entry& e : entries_) log_times_ns_.push_back(log_time(e));
  if (entries_.empty()) throw std::runtime_error("no messages in " + options_.files.front());
}

LogPlayer::~LogPlayer() {
  channels_.clear();  // writers before their participant
  participant_.reset();
}

void LogPlayer::wait_for_readers() {
  if (options_.wait_readers <= 0) return;
  const auto until = std::chrono::steady_clock::now() +
                     std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                         std::chrono::duration<double>(options_.wait_timeout_s));
  bool said = false;
  for (const auto& channel : channels_) {
    if (!said && channel->matched_readers() < options_.wait_readers) {
      log_ << "pixyslam_play: waiting up to " << options_.wait_timeout_s << " s for " << options_.wait_readers
           << " reader(s) per topic (--wait-readers 0: do not wait)\n";
      log_.flush();
      said = true;
    }
    while (channel->matched_readers() < options_.wait_readers) {
      if (app::StopSignal::requested()) {  // play() then plays nothing
        log_ << "pixyslam_play: stopped while waiting for readers\n";
        return;
      }
      if (std::chrono::steady_clock::now() >= until) {
        log_ << "pixyslam_play: warning: " << channel->report().topic << " has " << channel->matched_readers()
             << " of " << options_.wait_readers << " readers after " << options_.wait_timeout_s
             << " s; playing anyway\n";
        break;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
  }
}

std::vector<TopicReport> LogPlayer::play() {
  std::vector<bool> selected(entries_.size());
  for (std::size_t i = 0; i < entries_.size(); ++i) selected[i] = entries_[i].channel != kNotPlayed;
  const PlaybackPass pass = plan_pass(log_times_ns_, selected, log_times_ns_.front(), options_.playback);
  const double span_s = static_cast<double>(pass.span_ns) * 1e-9;
  log_ << "pixyslam_play: " << pass.messages.size() << " messages on " << channels_.size() << " topics, "
       << span_s << " s at rate " << options_.playback.rate << (options_.playback.loop ? ", looping" : "")
       << (options_.restamp ? ", restamped" : "") << "\n";
  log_.flush();
  wait_for_readers();

  using Clock = std::chrono::steady_clock;
  const auto progress_period = std::chrono::duration_cast<Clock::duration>(
      std::chrono::duration<double>(options_.progress_period_s));
  bool stopped = false;
  for (std::uint64_t pass_number = 0; !stopped; ++pass_number) {
    const Clock::time_point start = Clock::now();
    const std::int64_t offset_ns = restamp_offset_ns(pass.origin_log_ns, dds::now_ns());
    auto next_progress = start + progress_period;
    std::size_t done = 0;
    for (const ScheduledMessage& s : pass.messages) {
      if (!sleep_until(start + std::chrono::nanoseconds(s.due_ns))) {
        stopped = true;
        break;
      }
      const Entry& e = entries_[s.index];
      channels_[e.channel]->publish(readers_[e.file]->messages()[e.message].data, options_.restamp, offset_ns);
      ++done;
      if (options_.progress_period_s > 0 && Clock::now() >= next_progress) {
        next_progress += progress_period;
        char line[128];
        std::snprintf(line, sizeof(line), "pixyslam_play: pass %llu, %.1f / %.1f s, %zu messages\n",
                      static_cast<unsigned long long>(pass_number + 1),
                      std::chrono::duration<double>(Clock::now() - start).count(), span_s, done);
        log_ << line;
        log_.flush();
      }
    }
    if (stopped || !options_.playback.loop) break;
    // A window of one instant (a single message) repeats once a second, not in a busy loop.
    const std::int64_t loop_period_ns = pass.span_ns > 0 ? pass.span_ns : 1000000000;
    stopped = !sleep_until(start + std::chrono::nanoseconds(loop_period_ns));
  }

  for (const auto& channel : channels_) {
    if (!channel->wait_for_acknowledgments(std::chrono::seconds(5))) {
      log_ << "pixyslam_play: warning: " << channel->report().topic
           << ": not every sample acknowledged within 5 s\n";
    }
  }
  std::vector<TopicReport> reports;
  for (const auto& channel : channels_) reports.push_back(channel->report());
  log_summary(reports);
  return reports;
}

void LogPlayer::log_summary(const std::vector<TopicReport>& reports) const {
  for (const TopicReport& r : reports) {
    log_ << "pixyslam_play: " << r.topic << " published " << r.published;
    if (r.undecodable > 0) log_ << ", undecodable " << r.undecodable << " (skipped)";
    if (r.refused > 0) log_ << ", refused by DDS " << r.refused;
    log_ << "\n";
  }
  log_.flush();
}

}  // namespace pixyslam::player
