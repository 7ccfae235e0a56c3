#include "pixyslam/eval/trajectory_output.h"

#include <cstdio>
#include <exception>
#include <filesystem>
#include <utility>

namespace pixyslam::eval {
namespace {

std::string prepared(const std::string& dir) {
  std::filesystem::create_directories(dir);
  return dir + "/trajectory.csv";
}

}  // namespace

TrajectoryOutput::TrajectoryOutput(const std::string& dir, std::string process)
    : process_(std::move(process)), writer_(prepared(dir)) {}

void TrajectoryOutput::add(std::uint64_t stamp_ns, double x_m, double y_m, double theta_rad) {
  if (failed_) return;
  try {
    writer_.append({static_cast<double>(stamp_ns) * 1e-9, x_m, y_m, theta_rad});
  } catch (const std::exception& e) {
    failed_ = true;
    std::fprintf(stderr, "%s: ERROR: %s; the trajectory file ends here, the process goes on\n", process_.c_str(),
                 e.what());
  }
}

std::size_t TrajectoryOutput::finish() {
  if (failed_) return writer_.rows();
  try {
    writer_.flush();
  } catch (const std::exception& e) {
    failed_ = true;
    std::fprintf(stderr, "%s: ERROR: %s\n", process_.c_str(), e.what());
  }
  return writer_.rows();
}

}  // namespace pixyslam::eval
