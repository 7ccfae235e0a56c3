#pragma once

#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

#include "ground_truth.h"
#include "map_state.h"
#include "optimised_map.h"
#include "pixyslam/map_view/msg_conversion.h"
#include "pixyslam/map_view/view_transform.h"

namespace pixyslam::map_view {

// A bad command-line option or output path (the map_view command exits with 2).
class InputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// A log that cannot be read or holds no map: unreadable, not MCAP, no MapState
// (exits with 1, as pixyslam_spy and pixyslam_play do for such a file).
class LogError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// The MapState, GroundTruth, OptimisedMap and FleetMap messages of an MCAP log (the
// logger's run.mcap), decoded, in log-time order (MCAP log_time, ties in file order). Other
// topics are ignored; payloads that do not decode are skipped and counted. A
// file cut short (killed logger) is read as far as it is complete. Immutable
// after read(); thread-safe for const use.
class MapLog {
 public:
  enum class Kind { kMapState, kGroundTruth, kOptimisedMap, kFleetMap };
  struct Entry {
    std::uint64_t time_ns = 0;
    Kind kind = Kind::kMapState;
    std::size_t index = 0;  // into map_states(), ground_truths(), optimised_maps() or fleet_maps()
  };

  // Throws LogError naming the file: unreadable or not MCAP, no
  // pixyslam/map_state channel, a channel not CDR-encoded, no MapState that decodes.
  static MapLog read(const std::string& path);

  const std::string& path() const { return path_; }
  const std::vector<Entry>& entries() const { return entries_; }
  const std::vector<msg::MapState>& map_states() const { return map_states_; }
  const std::vector<msg::GroundTruth>& ground_truths() const { return ground_truths_; }
  const std::vector<msg::OptimisedMap>& optimised_maps() const { return optimised_maps_; }
  const std::vector<msg::FleetMap>& fleet_maps() const { return fleet_maps_; }
  std::size_t undecodable() const { return undecodable_; }
  // "" for a complete file, else what the reader had to skip (one line).
  const std::string& recovery_note() const { return recovery_note_; }
  std::uint64_t start_ns() const { return entries_.empty() ? 0 : entries_.front().time_ns; }
  std::uint64_t end_ns() const { return entries_.empty() ? 0 : entries_.back().time_ns; }

 private:
  std::string path_;
  std::vector<Entry> entries_;
  std::vector<msg::MapState> map_states_;
  std::vector<msg::GroundTruth> ground_truths_;
  std::vector<msg::OptimisedMap> optimised_maps_;
  std::vector<msg::FleetMap> fleet_maps_;
  std::size_t undecodable_ = 0;
  std::string recovery_note_;
};

// Replays a MapLog into a FleetViewBuilder (every robot of the log) up to a
// log time. Holds a reference to the log. Thread-compatible.
class LogPlayer {
 public:
  LogPlayer(const MapLog& log, double trajectory_min_step_m);
  // Feeds every entry with time <= time_ns not fed yet.
  void advance_to(std::uint64_t time_ns);
  void advance_to_end();
  MapViewState state() const { return builder_.state(); }
  const FleetViewBuilder& builder() const { return builder_; }

 private:
  const MapLog& log_;
  FleetViewBuilder builder_;
  std::size_t next_ = 0;
};

// The final map of a log: every message replayed.
MapViewState final_state(const MapLog& log, double trajectory_min_step_m);

// Bounds of everything drawn at any time of the run (every particle subsample,
// pose, landmark ellipse, optimised solution, and with include_truth the
// ground truth): a fixed
// view under which a video's frame does not jump.
WorldBox run_bounds(const MapLog& log, double sigma_scale, bool include_truth);

// Log times of a video's frames: from start to end every rate / fps seconds
// of log time, plus the end itself. Throws std::invalid_argument unless
// fps > 0 and rate > 0 (finite), or if that would be more than 10^6 frames.
std::vector<std::uint64_t> frame_times(std::uint64_t start_ns, std::uint64_t end_ns, double fps, double rate);

}  // namespace pixyslam::map_view
