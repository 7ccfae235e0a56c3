#pragma once

#include <string>
#include <vector>

#include "pixyslam/logger_node/logger_options.h"

namespace pixyslam::logger_node {

// The known topics that `patterns` (names, globs, "!" exclusions; see
// dds::select_topics) select, in known_topics() order. Throws
// std::invalid_argument naming `what` (the flag) and the bad pattern.
std::vector<std::string> select_known_topics(const std::vector<std::string>& patterns, const std::string& what);

// Records with `options` until SIGINT/SIGTERM (app::StopSignal, installed by
// the caller first in main), a recording failure, or `duration_s` (> 0)
// seconds. Then drains, closes the file(s) and prints to stderr, each line
// prefixed "TOOL: ", per-topic counters and one line per file. Returns the exit
// status: 0 clean, 1 the recording failed or samples were lost to write failures.
int record_until_stopped(const LoggerOptions& options, const std::string& tool, double duration_s = 0.0);

}  // namespace pixyslam::logger_node
