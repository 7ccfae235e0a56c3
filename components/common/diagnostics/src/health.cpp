#include "pixyslam/diagnostics/health.h"

namespace pixyslam::diagnostics {

Health HealthTracker::update(const std::vector<Counter>& counters, const std::string& error) {
  Health h;
  std::string grown;
  for (const Counter& c : counters) {
    std::uint64_t& before = previous_[c.name];
    if (c.bad && c.value > before) {
      grown += (grown.empty() ? "" : ", ") + c.name + " +" + std::to_string(c.value - before);
    }
    before = c.value;
  }
  if (!error.empty()) {
    h.level = Level::kError;
    h.status = error;
  } else if (!grown.empty()) {
    h.level = Level::kWarn;
    h.status = grown;
  }
  return h;
}

const char* level_name(Level level) {
  switch (level) {
    case Level::kOk:
      return "OK";
    case Level::kWarn:
      return "WARN";
    case Level::kError:
      return "ERROR";
  }
  return "?";
}

}  // namespace pixyslam::diagnostics
