#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <vector>

namespace pixyslam::diagnostics {

// One running total of a process. `bad`: its growth means input was rejected
// or lost (malformed bytes, invalid samples, gaps): a warning.
struct Counter {
  std::string name;
  std::uint64_t value = 0;
  bool bad = false;
};

enum class Level : std::uint8_t { kOk = 0, kWarn = 1, kError = 2 };

struct Health {
  Level level = Level::kOk;
  std::string status;  // "" when OK
};

// Level and status of successive reports: ERROR with `error` when the process
// says it cannot work (e.g. its device is missing); else WARN naming each bad
// counter that grew since the previous report ("lines_rejected +3"); else OK.
// A counter seen for the first time counts from 0. Thread-compatible.
class HealthTracker {
 public:
  Health update(const std::vector<Counter>& counters, const std::string& error = "");

 private:
  std::map<std::string, std::uint64_t> previous_;
};

const char* level_name(Level level);

}  // namespace pixyslam::diagnostics
