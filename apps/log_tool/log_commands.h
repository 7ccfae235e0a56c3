#pragma once

#include <cstdint>
#include <map>
#include <ostream>
#include <string>

namespace pixyslam::log_tool {

// `pixyslam_log info FILE`: what is in an MCAP file and how complete it is.
// Returns the exit status: 0 when the file could be read (recovered or not).
int run_info(const std::string& path, std::ostream& out);

struct CheckRequest {
  std::string path;
  std::map<std::string, std::uint64_t> expected;  // topic -> message count (--expect)
  bool allow_recovered = false;                   // a file without footer / with diagnostics may pass
};

// `pixyslam_log check FILE`: decodes every message with the project's types
// and checks per topic (and robot) that header seq is exactly 1..N, that the
// MCAP sequence and publish time agree with the header, and the expected
// counts. One line per topic. Returns 0 only if everything checks, else 1.
int run_check(const CheckRequest& request, std::ostream& out);

}  // namespace pixyslam::log_tool
