#pragma once

#include <cstdint>
#include <map>
#include <ostream>
#include <string>
#include <vector>

namespace pixyslam::log_tool {

// `pixyslam_log info FILE`: what is in an MCAP file and how complete it is:
// status complete, not closed (a writer that did not close it: every record up
// to the cut intact) or damaged (records, offsets, bytes skipped). Returns the
// exit status: 0 when complete or not closed, 1 when damaged (then every
// diagnostic with its byte offset goes to `err`). `json`: the same facts as one
// JSON object on one line.
int run_info(const std::string& path, bool json, std::ostream& out, std::ostream& err);

struct CheckRequest {
  std::string path;
  std::map<std::string, std::uint64_t> expected;  // topic -> message count (--expect)
  bool allow_recovered = false;                   // a file without footer / with diagnostics may pass
};

// `pixyslam_log check FILE`: decodes every message with the project's types
// and checks per topic (and robot) that header seq is exactly 1..N, that the
// MCAP sequence and publish time agree with the header, and the expected
// counts. One line per topic. A file that is not complete fails unless
// allow_recovered; the damage of a damaged one goes to `err` with its byte
// offsets. Returns 0 only if everything checks, else 1.
int run_check(const CheckRequest& request, std::ostream& out, std::ostream& err);

struct PrintRequest {
  std::string path;
  // Names, globs and !exclusions (dds::select_topics over the file's
  // channels, as pixyslam_play --topics); empty = every topic.
  std::vector<std::string> topics;
  bool json = false;  // JSON lines instead of YAML documents
};

// `pixyslam_log print FILE.mcap [--topics LIST] [--json]`: every message decoded
// with the project's types, in file order, with its topic and log time (the
// same printers as `echo`). Prints the messages it could read; on `err`, a
// file that is not closed is noted, and the damage of a damaged one listed
// with byte offsets. Returns 0, or 1 if a payload cannot be decoded or the
// file is damaged.
int run_print(const PrintRequest& request, std::ostream& out, std::ostream& err);

struct CompareRequest {
  std::string first_path;
  std::string second_path;
  std::string topic;
  std::vector<std::string> ignored;  // field paths, e.g. header.stamp_ns, landmarks.times_observed
  double tolerance = 0.0;            // relative; 0: bit-for-bit
  std::size_t max_lines = 20;
  // Pair messages by these fields' values instead of by position, e.g.
  // odometry_sequence,observation_sequence: a MapState is compared with the one
  // that includes the same inputs. Messages without a partner are counted.
  std::vector<std::string> match;
  std::uint64_t max_unmatched = 0;  // of each file (uint64: the CLI binds it on 32-bit hosts too)
  // With match: pairs after the first message without a partner may differ
  // (a replayed estimator that took an odometry sample after a newer frame,
  // where the live one did not, applies it at another time from there on);
  // every pair before it must agree, and at least half of all pairs must.
  bool until_unmatched = false;
};

// `pixyslam_log compare A.mcap B.mcap --topic T`: decodes the topic's messages
// of both files in order and compares them field by field (e.g. a recorded
// MapState against the one a replay through the estimator produced). Reports
// the count of each, the constant or varying offset of the header stamps, and
// the first differences. Returns 0 only if every compared field of every pair
// agrees and at most max_unmatched messages of each file have no partner (by
// position: the same number of messages), else 1.
int run_compare(const CompareRequest& request, std::ostream& out);

struct FoxgloveRequest {
  std::string input_path;
  std::string output_path;
  std::string compression = "zstd";  // none | zstd | lz4 (zstd falls back to none where not built)
};

// `pixyslam_log foxglove IN.mcap OUT.mcap`: OUT holds every message of IN
// unchanged (same topics, schemas, times) plus the foxglove_bridge's
// pixyslam/viz/* channels (foxglove.SceneUpdate, PosesInFrame, FrameTransform
// in OMG IDL, CDR) made from each MapState and GroundTruth, at the log time of
// the message they come from, so Foxglove draws the recording in 3D. Prints a
// line per visual channel on `err`. Returns 0; 1 if a MapState or GroundTruth
// did not decode (counted, skipped: the rest is converted) or IN is damaged
// (what could be read is converted).
int run_foxglove(const FoxgloveRequest& request, std::ostream& err);

}  // namespace pixyslam::log_tool
