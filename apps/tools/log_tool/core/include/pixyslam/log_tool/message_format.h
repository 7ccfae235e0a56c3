#pragma once

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "diagnostics.h"
#include "ground_truth.h"
#include "landmark_observation.h"
#include "map_state.h"
#include "odometry.h"
#include "optimised_map.h"
#include "fleet_map.h"
#include "robot_sighting.h"

namespace pixyslam::log_tool {

// A message as a tree of named fields, in IDL order, for printing: structs,
// sequences/arrays and scalars. Field names are the IDL names (units included,
// e.g. `v_mps`). Plain value type, no DDS; thread-compatible.
class Value {
 public:
  enum class Kind { kFloat, kInt, kUInt, kBool, kString, kStruct, kList };

  static Value number(double v);
  static Value integer(std::int64_t v);
  static Value unsigned_integer(std::uint64_t v);
  static Value boolean(bool v);
  static Value string(std::string v);
  static Value structure() { return Value(Kind::kStruct); }
  static Value list() { return Value(Kind::kList); }

  // Builders: add(name, value) on a struct, push(value) on a list. Return *this.
  Value& add(std::string name, Value value);
  Value& push(Value value);

  Kind kind() const { return kind_; }
  double float_value() const { return float_; }
  std::int64_t int_value() const { return int_; }
  std::uint64_t uint_value() const { return uint_; }
  bool bool_value() const { return uint_ != 0; }
  const std::string& string_value() const { return text_; }
  const std::vector<std::pair<std::string, Value>>& fields() const { return fields_; }
  const std::vector<Value>& items() const { return items_; }
  // The field `name` of a struct (dotted path "header.seq" allowed); nullptr if absent.
  const Value* find(const std::string& path) const;

 private:
  explicit Value(Kind kind) : kind_(kind) {}
  Kind kind_;
  double float_ = 0.0;
  std::int64_t int_ = 0;
  std::uint64_t uint_ = 0;  // also a boolean's value (0 or 1)
  std::string text_;
  std::vector<std::pair<std::string, Value>> fields_;
  std::vector<Value> items_;
};

// Every field of a message (nested structs and sequences included).
Value to_value(const msg::Odometry& m);
Value to_value(const msg::LandmarkObservation& m);
Value to_value(const msg::MapState& m);
Value to_value(const msg::GroundTruth& m);
Value to_value(const msg::Diagnostics& m);
Value to_value(const msg::OptimisedMap& m);
Value to_value(const msg::RobotSighting& m);
Value to_value(const msg::FleetMap& m);

// One report per process (sorted by robot, process, pid): a line "robot process
// (pid P): LEVEL, up S s[: status]", then its counters, wrapped at 100 columns.
std::string diagnostics_table(std::vector<msg::Diagnostics> reports);

// One YAML document: "---\n" then a block mapping; lists of scalars in flow
// style ([1, 2]), lists of structs as block sequences, strings double-quoted
// (JSON escapes), non-finite floats as .nan / .inf / -.inf.
std::string to_yaml_document(const Value& value);
// One line of JSON (no trailing newline); non-finite floats as null.
std::string to_json_line(const Value& value);
// Shortest text that reads back as exactly `v` ("0.1", "1e-09", "3").
std::string format_double(double v);

// Field-by-field differences between two messages of one type, as lines
// "path: a != b" (paths like "landmarks[3].x_m"), at most `max_lines`.
// A path is skipped when it, or it with the list indices removed
// ("landmarks.x_m"), is in `ignored`. Floats differ when
// |a - b| > tolerance * max(1, |a|, |b|) (0: bit-for-bit, NaN equals NaN);
// lists of different lengths differ by their length. Pure.
std::vector<std::string> compare_values(const Value& a, const Value& b, const std::vector<std::string>& ignored,
                                        double tolerance, std::size_t max_lines);

// False when `path` ("pose.x_m", "landmarks[2].x_m" or "landmarks.x_m") names
// no field of `message`: a struct lacks a name on it, or a number or text has
// a field below it. Below an empty list nothing can be checked: true. Pure.
bool field_path_exists(const Value& message, const std::string& path);

// Messages of two recordings paired by the values of `key_fields` (e.g. the
// input sequence numbers a MapState includes), in order among equal keys;
// without key fields, by position. Pure.
struct MessagePairs {
  std::vector<std::pair<std::size_t, std::size_t>> pairs;  // (index in first, index in second)
  std::vector<std::size_t> only_first, only_second;
};
MessagePairs pair_messages(const std::vector<Value>& first, const std::vector<Value>& second,
                           const std::vector<std::string>& key_fields);
// How many of p.pairs come before the first message of either file that has no
// partner (all of them when every message has one). Pure.
std::size_t pairs_before_first_unmatched(const MessagePairs& p);
// compare --until-unmatched: the pairs before the first message without a
// partner must all agree (differing_before 0), and at least half of all pairs
// must agree; pairs after it may differ. Pure.
bool until_unmatched_passes(std::size_t pairs, std::size_t differing_before, std::size_t differing_after);

// Inter-arrival statistics of a stream (pixyslam_spy hz), times in seconds.
struct GapStats {
  std::size_t messages = 0;
  double rate_hz = 0.0;  // 1 / mean gap (0 with fewer than two messages)
  double mean_s = 0.0;
  double min_s = 0.0;
  double max_s = 0.0;
  double std_s = 0.0;    // population standard deviation of the gaps (jitter)
};
// `arrivals_s` in arrival order (non-decreasing).
GapStats gap_stats(const std::vector<double>& arrivals_s);

// The same statistics kept as the times come (Welford's running mean and
// variance of the gaps), in constant memory: `pixyslam_spy hz` listens for days.
class GapAccumulator {
 public:
  void add(double t_s);
  GapStats stats() const;

 private:
  std::size_t messages_ = 0;
  double last_s_ = 0.0;
  double min_s_ = 0.0, max_s_ = 0.0;
  double mean_s_ = 0.0, m2_ = 0.0;  // of the gaps
};

}  // namespace pixyslam::log_tool
