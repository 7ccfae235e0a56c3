#pragma once

#include <cstdint>
#include <memory>
#include <ostream>
#include <string>
#include <vector>

#include "pixyslam/dds/participant.h"
#include "pixyslam/mcap/mcap_reader.h"
#include "pixyslam/player/playback_plan.h"

namespace pixyslam::player {

struct PlayerOptions {
  std::vector<std::string> files;    // MCAP logs, played as one (merged by log time)
  std::vector<std::string> topics;   // names, globs, "!" exclusions; empty: every topic in the log
  PlaybackOptions playback;
  bool restamp = false;              // move header stamps onto the current clock
  int wait_readers = 1;              // per topic, before the first message
  double wait_timeout_s = 10.0;      // then play anyway, with a warning
  double progress_period_s = 10.0;  // a progress line this often (0: never)
  dds::DdsOptions dds;
};

struct TopicReport {
  std::string topic;
  std::uint64_t published = 0;
  std::uint64_t undecodable = 0;  // payloads that are not a valid sample of the topic's type
  std::uint64_t refused = 0;      // samples DDS did not accept
};

// Replays MCAP logs written by the logger onto DDS: the recorded CDR samples
// decoded with the project's types and written with their headers as recorded
// (seq, robot id; stamps shifted by one constant with restamp), at the
// original inter-message timing scaled by the rate. Construction reads the
// logs and creates the writers; errors (unreadable file, a log without any of
// the project's topics, a topic pattern that selects nothing) throw
// std::runtime_error / std::invalid_argument naming the file or pattern.
class LogPlayer {
 public:
  LogPlayer(const PlayerOptions& options, std::ostream& log);
  ~LogPlayer();
  LogPlayer(const LogPlayer&) = delete;
  LogPlayer& operator=(const LogPlayer&) = delete;

  // Plays until the end (or forever with loop) or until app::StopSignal;
  // then waits for reliable readers to acknowledge. Returns per-topic counts.
  std::vector<TopicReport> play();

 // One played topic (defined in the .cpp).
  class Channel;

 private:
  struct Entry {
    std::size_t file = 0;
    std::size_t message = 0;
    std::size_t channel = 0;  // index into channels_, or npos: not played
  };

  void wait_for_readers();
  void log_summary(const std::vector<TopicReport>& reports) const;

  PlayerOptions options_;
  std::ostream& log_;
  std::vector<std::unique_ptr<mcap::McapReader>> readers_;
  std::vector<Entry> entries_;  // every message of every file, by log time
  std::vector<std::uint64_t> log_times_ns_;
  std::unique_ptr<dds::Participant> participant_;
  std::vector<std::unique_ptr<Channel>> channels_;
};

}  // namespace pixyslam::player
