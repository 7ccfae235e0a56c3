#include "pixyslam/slam/map_checkpoint.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>
#include <stdexcept>

#include <Eigen/Eigenvalues>
#include <fcntl.h>
#include <unistd.h>

#include "pixyslam/config/yaml_reader.h"
#include "pixyslam/config/yaml_text.h"

namespace pixyslam::slam {
namespace {

constexpr double kMaxCoordinate = 1e6;
constexpr double kMaxVariance = 1e6;
// A checkpoint is written by the estimator, not by hand: ~170 bytes per landmark,
// so 16 MiB (~100000 landmarks) instead of the 1 MiB limit of a configuration file.
constexpr std::size_t kMaxCheckpointFileBytes = std::size_t{16} << 20;

using config::yaml_number;

// Symmetric positive semi-definite (up to rounding of the written digits).
template <int N>
bool is_covariance(const Eigen::Matrix<double, N, N>& c) {
  if (!c.allFinite() || !c.isApprox(c.transpose(), 1e-9)) return false;
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, N, N>> eig(c);
  return eig.eigenvalues().minCoeff() >= -1e-12 * std::max(1.0, c.diagonal().maxCoeff());
}

}  // namespace

MapCheckpoint checkpoint_of(const FastSlam2& filter, std::uint64_t stamp_ns) {
  const PoseEstimate estimate = filter.pose_estimate();
  MapCheckpoint c;
  c.stamp_ns = stamp_ns;
  c.pose.mean = estimate.mean;
  c.pose.cov = 0.5 * (estimate.cov + estimate.cov.transpose());
  c.landmarks = filter.landmarks_mixture();
  c.control_v_mps = filter.held_control().v_mps;
  c.control_w_radps = filter.held_control().w_radps;
  // Past control_timeout_s the command is not held any more: an older age means nothing more
  // (and a filter time far from the control's, e.g. after a hostile stamp, stays within the file's bounds).
  c.control_age_s = std::clamp(filter.time_s() - filter.held_control_since_s(), 0.0, filter.options().control_timeout_s);
  return c;
}

std::string to_yaml(const MapCheckpoint& c) {
  std::ostringstream out;
  const Eigen::Matrix3d& p = c.pose.cov;
  out << "# pixyslam estimator checkpoint: pose and map to resume from (slam_estimator)\n"
      << "version: 2\n"
      << "stamp_ns: " << c.stamp_ns << "\n"
      << "pose:\n"
      << "  x_m: " << yaml_number(c.pose.mean.x()) << "\n"
      << "  y_m: " << yaml_number(c.pose.mean.y()) << "\n"
      << "  theta_rad: " << yaml_number(c.pose.mean.z()) << "\n"
      << "  # covariance over (x, y, theta): xx xy xt yy yt tt\n"
      << "  cov_xx: " << yaml_number(p(0, 0)) << "\n  cov_xy: " << yaml_number(p(0, 1))
      << "\n  cov_xt: " << yaml_number(p(0, 2)) << "\n  cov_yy: " << yaml_number(p(1, 1))
      << "\n  cov_yt: " << yaml_number(p(1, 2)) << "\n  cov_tt: " << yaml_number(p(2, 2)) << "\n"
      << "# the odometry command held at stamp_ns, and for how long (s)\n"
      << "control: {v_mps: " << yaml_number(c.control_v_mps) << ", w_radps: " << yaml_number(c.control_w_radps)
      << ", age_s: " << yaml_number(c.control_age_s) << "}\n"
      << "landmarks:" << (c.landmarks.empty() ? " []\n" : "\n");
  for (const slam::LandmarkEstimate& l : c.landmarks) {
    out << "  - {id: " << l.id << ", x_m: " << yaml_number(l.mean.x()) << ", y_m: " << yaml_number(l.mean.y())
        << ", cov_xx_m2: " << yaml_number(l.cov(0, 0)) << ", cov_xy_m2: " << yaml_number(l.cov(0, 1))
        << ", cov_yy_m2: " << yaml_number(l.cov(1, 1)) << ", times_observed: " << l.times_observed << "}\n";
  }
  return out.str();
}

namespace {

MapCheckpoint parse(config::YamlReader root) {
  MapCheckpoint c;
  const std::int64_t version = root.integer("version", 1, 2);
  c.stamp_ns = static_cast<std::uint64_t>(root.integer("stamp_ns", 0, INT64_MAX));
  config::YamlReader pose = root.child("pose");
  c.pose.mean = slam::Pose2(pose.number("x_m", -kMaxCoordinate, kMaxCoordinate),
                            pose.number("y_m", -kMaxCoordinate, kMaxCoordinate),
                            pose.number("theta_rad", -2.0 * M_PI, 2.0 * M_PI));
  Eigen::Matrix3d& p = c.pose.cov;
  p(0, 0) = pose.number("cov_xx", 0.0, kMaxVariance);
  p(0, 1) = p(1, 0) = pose.number("cov_xy", -kMaxVariance, kMaxVariance);
  p(0, 2) = p(2, 0) = pose.number("cov_xt", -kMaxVariance, kMaxVariance);
  p(1, 1) = pose.number("cov_yy", 0.0, kMaxVariance);
  p(1, 2) = p(2, 1) = pose.number("cov_yt", -kMaxVariance, kMaxVariance);
  p(2, 2) = pose.number("cov_tt", 0.0, kMaxVariance);
  if (!is_covariance(p)) pose.fail("cov_xx", "the pose covariance is not positive semi-definite");
  pose.finish();
  if (version >= 2) {  // version 1 had no control: none held
    config::YamlReader control = root.child("control");
    c.control_v_mps = control.number("v_mps", -1000.0, 1000.0);
    c.control_w_radps = control.number("w_radps", -1000.0, 1000.0);
    c.control_age_s = control.number("age_s", 0.0, 1e9);
    control.finish();
  }
  for (config::YamlReader& l : root.mapping_list("landmarks")) {
    slam::LandmarkEstimate e;
    e.id = static_cast<int>(l.integer("id", INT32_MIN, INT32_MAX));
    e.mean = Eigen::Vector2d(l.number("x_m", -kMaxCoordinate, kMaxCoordinate),
                             l.number("y_m", -kMaxCoordinate, kMaxCoordinate));
    e.cov(0, 0) = l.number("cov_xx_m2", 0.0, kMaxVariance);
    e.cov(0, 1) = e.cov(1, 0) = l.number("cov_xy_m2", -kMaxVariance, kMaxVariance);
    e.cov(1, 1) = l.number("cov_yy_m2", 0.0, kMaxVariance);
    if (!is_covariance(e.cov)) l.fail("cov_xx_m2", "the landmark covariance is not positive semi-definite");
    e.times_observed = static_cast<std::uint32_t>(l.integer("times_observed", 0, UINT32_MAX));
    for (const slam::LandmarkEstimate& other : c.landmarks) {
      if (other.id == e.id) l.fail("id", "landmark " + std::to_string(e.id) + " appears twice");
    }
    l.finish();
    c.landmarks.push_back(e);
  }
  root.finish();
  return c;
}

}  // namespace

MapCheckpoint parse_map_checkpoint(const std::string& text, const std::string& origin) {
  return parse(config::YamlReader::from_string(text, origin));
}

MapCheckpoint read_map_checkpoint(const std::string& path) {
  return parse(config::YamlReader::from_file(path, kMaxCheckpointFileBytes));
}

void write_map_checkpoint(const std::string& path, const MapCheckpoint& checkpoint) {
  const std::string text = to_yaml(checkpoint);
  const std::string tmp = path + ".tmp";
  const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) throw std::runtime_error("cannot write the checkpoint '" + tmp + "'");
  std::size_t done = 0;
  while (done < text.size()) {
    const ssize_t n = ::write(fd, text.data() + done, text.size() - done);
    if (n <= 0) {
      ::close(fd);
      throw std::runtime_error("cannot write the checkpoint '" + tmp + "' (disk full?)");
    }
    done += static_cast<std::size_t>(n);
  }
  const bool synced = ::fsync(fd) == 0;
  ::close(fd);
  if (!synced || std::rename(tmp.c_str(), path.c_str()) != 0) {
    throw std::runtime_error("cannot replace the checkpoint '" + path + "'");
  }
}

slam::PoseGaussian resume_pose(const MapCheckpoint& checkpoint, double gap_s, double max_speed_mps,
                               double max_turn_rate_radps, double control_timeout_s) {
  slam::PoseGaussian g = checkpoint.pose;
  const double gap = std::max(0.0, gap_s);
  const double held_s = std::clamp(control_timeout_s - checkpoint.control_age_s, 0.0, gap);
  g.mean = slam::move(g.mean, checkpoint.control_v_mps, checkpoint.control_w_radps, held_s);
  const double sd_position = 0.5 * max_speed_mps * gap;
  const double sd_heading = std::min(M_PI, 0.5 * max_turn_rate_radps * gap);
  g.cov(0, 0) += sd_position * sd_position;
  g.cov(1, 1) += sd_position * sd_position;
  g.cov(2, 2) += sd_heading * sd_heading;
  return g;
}

}  // namespace pixyslam::slam
