#include "pixyslam/map_view/map_log.h"

#include <algorithm>
#include <cmath>
#include <memory>

#include "pixyslam/dds/topics.h"
#include "pixyslam/mcap/mcap_reader.h"
#include "pixyslam/dds/cdr_payload.h"

namespace pixyslam::map_view {
namespace {

template <class Message>
void decode_channel(const mcap::McapReader& reader, const mcap::McapChannel& channel, MapLog::Kind kind,
                    std::vector<Message>& out, std::vector<MapLog::Entry>& entries, std::size_t& undecodable) {
  typename dds::MessageTraits<Message>::PubSubType type;
  std::string error;
  for (const mcap::McapMessage& m : reader.messages()) {
    if (m.channel_id != channel.id) continue;
    Message sample;
    if (!dds::deserialize_payload(type, m.data.data(), m.data.size(), &sample, error)) {
      ++undecodable;
      continue;
    }
    entries.push_back({m.log_time_ns, kind, out.size()});
    out.push_back(std::move(sample));
  }
}

void check_encoding(const std::string& path, const mcap::McapChannel& channel) {
  if (channel.message_encoding != "cdr") {
    throw LogError(path + ": channel '" + channel.topic + "' has message encoding '" + channel.message_encoding +
                     "', expected 'cdr'");
  }
}

}  // namespace

MapLog MapLog::read(const std::string& path) {
  std::unique_ptr<mcap::McapReader> reader;
  try {
    reader = std::make_unique<mcap::McapReader>(path);
  } catch (const std::exception& e) {
    throw LogError(e.what());  // names the file
  }
  MapLog log;
  log.path_ = path;
  const std::string map_topic(dds::kMapStateTopic);
  const std::string truth_topic(dds::kGroundTruthTopic);
  const std::string optimised_topic(dds::kOptimisedMapTopic);
  const mcap::McapChannel* map_channel = reader->find_channel(map_topic);
  if (map_channel == nullptr) {
    std::string topics;
    for (const mcap::McapChannel& c : reader->channels()) topics += (topics.empty() ? "" : ", ") + c.topic;
    throw LogError(path + ": no '" + map_topic + "' channel (topics: " + (topics.empty() ? "none" : topics) +
                     "); record it with the logger");
  }
  check_encoding(path, *map_channel);
  decode_channel(*reader, *map_channel, Kind::kMapState, log.map_states_, log.entries_, log.undecodable_);
  if (log.map_states_.empty()) {
    throw LogError(path + ": no MapState message" +
                     (log.undecodable_ > 0 ? " that decodes (" + std::to_string(log.undecodable_) + " bad payloads)"
                                           : std::string(" on '" + map_topic + "'")));
  }
  if (const mcap::McapChannel* truth_channel = reader->find_channel(truth_topic)) {
    check_encoding(path, *truth_channel);
    decode_channel(*reader, *truth_channel, Kind::kGroundTruth, log.ground_truths_, log.entries_, log.undecodable_);
  }
  if (const mcap::McapChannel* optimised_channel = reader->find_channel(optimised_topic)) {
    check_encoding(path, *optimised_channel);
    decode_channel(*reader, *optimised_channel, Kind::kOptimisedMap, log.optimised_maps_, log.entries_,
                   log.undecodable_);
  }
  if (const mcap::McapChannel* fleet_channel = reader->find_channel(std::string(dds::kFleetMapTopic))) {
    check_encoding(path, *fleet_channel);
    decode_channel(*reader, *fleet_channel, Kind::kFleetMap, log.fleet_maps_, log.entries_, log.undecodable_);
  }
  std::stable_sort(log.entries_.begin(), log.entries_.end(),
                   [](const Entry& a, const Entry& b) { return a.time_ns < b.time_ns; });
  if (!reader->clean()) {
    const mcap::McapRecovery& r = reader->recovery();
    log.recovery_note_ = "file not complete or damaged: " + std::to_string(reader->diagnostics().size()) +
                         " problem(s), " + std::to_string(r.rejected_chunks) + " chunk(s) rejected, " +
                         std::to_string(r.bytes_ignored_at_end) + " byte(s) ignored at the end";
  }
  return log;
}

LogPlayer::LogPlayer(const MapLog& log, double trajectory_min_step_m) : log_(log), builder_(trajectory_min_step_m) {}

void LogPlayer::advance_to(std::uint64_t time_ns) {
  const std::vector<MapLog::Entry>& entries = log_.entries();
  while (next_ < entries.size() && entries[next_].time_ns <= time_ns) {
    const MapLog::Entry& e = entries[next_++];
    switch (e.kind) {
      case MapLog::Kind::kMapState: builder_.add(log_.map_states()[e.index]); break;
      case MapLog::Kind::kGroundTruth: builder_.add(log_.ground_truths()[e.index]); break;
      case MapLog::Kind::kOptimisedMap: builder_.add(log_.optimised_maps()[e.index]); break;
      case MapLog::Kind::kFleetMap: builder_.add(log_.fleet_maps()[e.index]); break;
    }
  }
}

void LogPlayer::advance_to_end() { advance_to(log_.end_ns()); }

MapViewState final_state(const MapLog& log, double trajectory_min_step_m) {
  LogPlayer player(log, trajectory_min_step_m);
  player.advance_to_end();
  return player.state();
}

WorldBox run_bounds(const MapLog& log, double sigma_scale, bool include_truth) {
  WorldBox box;
  for (const msg::MapState& m : log.map_states()) {
    MapViewState one;
    for (const msg::Pose2D& p : m.particle_poses()) one.particles.push_back(to_pose(p));
    one.current_pose = to_pose(m.mean_pose());
    one.landmarks = to_landmarks(m);
    box.extend(content_bounds(one, sigma_scale, false));
  }
  for (const msg::OptimisedMap& m : log.optimised_maps()) {
    MapViewState one;
    one.optimised_trajectory = to_trajectory(m);
    one.optimised_landmarks = to_landmarks(m);
    box.extend(content_bounds(one, sigma_scale, false));
  }
  for (const msg::FleetMap& m : log.fleet_maps()) {
    MapViewState one;
    one.fleet_landmarks = to_landmarks(m);
    box.extend(content_bounds(one, sigma_scale, false));
  }
  if (include_truth) {
    for (const msg::GroundTruth& g : log.ground_truths()) {
      MapViewState one;
      one.true_pose = to_pose(g.pose());
      one.true_landmarks = to_true_landmarks(g);
      box.extend(content_bounds(one, sigma_scale, true));
    }
  }
  return box;
}

std::vector<std::uint64_t> frame_times(std::uint64_t start_ns, std::uint64_t end_ns, double fps, double rate) {
  if (!(fps > 0.0) || !std::isfinite(fps)) throw std::invalid_argument("fps must be a number > 0");
  if (!(rate > 0.0) || !std::isfinite(rate)) throw std::invalid_argument("rate must be a number > 0");
  std::vector<std::uint64_t> out;
  const double step_ns = rate / fps * 1e9;
  if (end_ns < start_ns) return {end_ns};
  const double span_ns = static_cast<double>(end_ns - start_ns);
  constexpr double kMaxFrames = 1e6;
  if (span_ns / step_ns > kMaxFrames) {
    throw std::invalid_argument("fps and rate would give more than 1000000 frames for this log");
  }
  for (double k = 0.0; k * step_ns < span_ns; k += 1.0) {
    out.push_back(start_ns + static_cast<std::uint64_t>(k * step_ns));
  }
  out.push_back(end_ns);
  return out;
}

}  // namespace pixyslam::map_view
