#pragma once

#include <fstream>
#include <string>
#include <vector>

#include "pixyslam/eval/trajectory_metrics.h"

namespace pixyslam::eval {

// One row of a landmark map file: id, position (m) and the 2x2 position
// covariance entries (m^2), world frame.
struct LandmarkRow {
  int id;
  double x_m, y_m, cov_xx, cov_xy, cov_yy;
};

// Trajectory CSV files: header line exactly "t,x,y,theta", then one pose per
// line (seconds, metres, metres, radians). Numbers are written in the shortest
// form that reads back to the identical double, so unix times keep full
// precision. Readers skip blank lines and accept LF or CRLF line ends. Errors
// are std::runtime_error naming the file and, for content errors, the 1-based
// line number and the offending text ("path:line: ..."); writers also throw
// std::runtime_error if the file cannot be written or a value is not finite.
std::vector<TimedPose> read_trajectory_csv(const std::string& path);
void write_trajectory_csv(const std::string& path, const std::vector<TimedPose>& poses);

// The same file written as the poses come (a live estimator that runs for
// days holds none of them): the header at construction, a row per append().
// Non-finite poses are skipped and counted, not written. Throws
// std::runtime_error naming the file when it cannot be opened or written.
class TrajectoryCsvWriter {
 public:
  explicit TrajectoryCsvWriter(const std::string& path);
  void append(const TimedPose& pose);
  // Writes what is buffered; the destructor closes the file (without throwing).
  void flush();
  std::size_t rows() const { return rows_; }
  std::size_t skipped() const { return skipped_; }
  const std::string& path() const { return path_; }

 private:
  std::string path_;
  std::ofstream out_;
  std::string line_;
  std::size_t rows_ = 0;
  std::size_t skipped_ = 0;
};

// Landmark CSV files: header line exactly "id,x,y,cov_xx,cov_xy,cov_yy", then
// one landmark per line; same conventions and errors as the trajectory files.
std::vector<LandmarkRow> read_landmarks_csv(const std::string& path);
void write_landmarks_csv(const std::string& path, const std::vector<LandmarkRow>& rows);

}  // namespace pixyslam::eval
