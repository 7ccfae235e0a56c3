#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

#include "pixyslam/eval/csv_io.h"

namespace pixyslam::eval {

// DIR/trajectory.csv of a live process, written as the poses come (t in
// seconds of the stamps' clock): a station that runs for days holds no
// trajectory in memory. The folder is created, and one that cannot be written
// fails in the constructor, not at the end. A later write failure (disk full)
// is reported once on stderr under `process`; the process goes on.
class TrajectoryOutput {
 public:
  TrajectoryOutput(const std::string& dir, std::string process);

  void add(std::uint64_t stamp_ns, double x_m, double y_m, double theta_rad);
  // Flushes; the number of rows written.
  std::size_t finish();
  // A write failed (reported once): the file ends early.
  bool failed() const { return failed_; }
  const std::string& path() const { return writer_.path(); }

 private:
  std::string process_;
  TrajectoryCsvWriter writer_;
  bool failed_ = false;
};

}  // namespace pixyslam::eval
