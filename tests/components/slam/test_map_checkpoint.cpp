// The estimator's checkpoint file (pose + map to resume from) and the filter
// started from a pose Gaussian, as a restart uses them.
#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>

#include <gtest/gtest.h>
#include <unistd.h>

#include "pixyslam/config/yaml_reader.h"
#include "pixyslam/slam/fastslam2.h"
#include "pixyslam/slam/map_checkpoint.h"

namespace pixyslam::slam {
namespace {

MapCheckpoint sample_checkpoint() {
  MapCheckpoint c;
  c.stamp_ns = 1732400000123456789ull;
  c.pose.mean = slam::Pose2(1.25, -0.5, 2.9);
  c.pose.cov << 0.01, 0.002, 0.0001, 0.002, 0.02, -0.0003, 0.0001, -0.0003, 0.004;
  c.landmarks.push_back({3, Eigen::Vector2d(2.0 / 3.0, 1e-7), (Eigen::Matrix2d() << 0.003, 0.001, 0.001, 0.002).finished(), 17});
  c.landmarks.push_back({12, Eigen::Vector2d(-4.5, 3.25), Eigen::Matrix2d::Identity() * 0.05, 1});
  c.control_v_mps = 0.25;
  c.control_w_radps = -0.5;
  c.control_age_s = 0.125;
  return c;
}

TEST(MapCheckpoint, RoundTripsExactly) {
  const MapCheckpoint c = sample_checkpoint();
  const MapCheckpoint back = parse_map_checkpoint(to_yaml(c), "checkpoint.yaml");
  EXPECT_EQ(back.stamp_ns, c.stamp_ns);
  EXPECT_EQ(back.pose.mean, c.pose.mean);
  EXPECT_EQ(back.pose.cov, c.pose.cov);
  EXPECT_EQ(back.control_v_mps, c.control_v_mps);
  EXPECT_EQ(back.control_w_radps, c.control_w_radps);
  EXPECT_EQ(back.control_age_s, c.control_age_s);
  ASSERT_EQ(back.landmarks.size(), 2u);
  for (std::size_t i = 0; i < 2; ++i) {
    EXPECT_EQ(back.landmarks[i].id, c.landmarks[i].id);
    EXPECT_EQ(back.landmarks[i].mean, c.landmarks[i].mean);
    EXPECT_EQ(back.landmarks[i].cov, c.landmarks[i].cov);
    EXPECT_EQ(back.landmarks[i].times_observed, c.landmarks[i].times_observed);
  }
  MapCheckpoint empty;
  EXPECT_TRUE(parse_map_checkpoint(to_yaml(empty), "empty.yaml").landmarks.empty());
  // A version-1 file (before the held control was saved) still loads, holding none.
  std::string v1 = to_yaml(c);
  v1.replace(v1.find("version: 2"), 10, "version: 1");
  v1.erase(v1.find("control: {"), v1.find("landmarks:") - v1.find("control: {"));
  const MapCheckpoint old = parse_map_checkpoint(v1, "v1.yaml");
  EXPECT_EQ(old.pose.mean, c.pose.mean);
  EXPECT_EQ(old.control_v_mps, 0.0);
  EXPECT_EQ(old.control_w_radps, 0.0);
}

TEST(MapCheckpoint, BadFilesAreErrorsNamingFileAndKey) {
  const std::string good = to_yaml(sample_checkpoint());
  auto replaced = [&](const std::string& from, const std::string& to) {
    std::string text = good;
    const std::size_t at = text.find(from);
    EXPECT_NE(at, std::string::npos) << from;
    return text.replace(at, from.size(), to);
  };
  const std::vector<std::pair<std::string, std::string>> cases = {
      {replaced("version: 2", "version: 3"), "key 'version'"},
      {replaced("w_radps: -0.5", "w_radps: .inf"), "key 'control.w_radps'"},
      {replaced("age_s: 0.125", "age_s: -1"), "key 'control.age_s'"},
      {replaced("  x_m: 1.25", "  x_m: .nan"), "key 'pose.x_m'"},
      {replaced("  cov_tt: 0.004", "  cov_tt: -1"), "key 'pose.cov_tt'"},
      {replaced("  cov_xy: 0.002", "  cov_xy: 0.9"), "not positive semi-definite"},
      {replaced("{id: 12,", "{id: 3,"), "appears twice"},
      {replaced("cov_yy_m2: 0.05", "cov_yy_m2: oops"), "key 'landmarks[1].cov_yy_m2'"},
      {replaced("stamp_ns:", "stamp:"), "stamp"},
      {good.substr(0, good.size() / 2), "torn.yaml"},
  };
  for (const auto& [text, expected] : cases) {
    try {
      parse_map_checkpoint(text, "torn.yaml");
      ADD_FAILURE() << "accepted:\n" << text;
    } catch (const config::ConfigError& e) {
      const std::string what = e.what();
      EXPECT_NE(what.find("torn.yaml"), std::string::npos) << what;
      EXPECT_NE(what.find(expected), std::string::npos) << "wanted '" << expected << "' in: " << what;
    }
  }
  EXPECT_THROW(read_map_checkpoint("/nonexistent/checkpoint.yaml"), config::ConfigError);
}

TEST(MapCheckpoint, WriteReplacesTheFileWholeAndLeavesNoTemporary) {
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / ("pixyslam_ckpt_unit_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const std::string path = (dir / "c.yaml").string();
  MapCheckpoint c = sample_checkpoint();
  write_map_checkpoint(path, c);
  c.landmarks.pop_back();
  c.stamp_ns += 1000;
  write_map_checkpoint(path, c);
  const MapCheckpoint back = read_map_checkpoint(path);
  EXPECT_EQ(back.stamp_ns, c.stamp_ns);
  EXPECT_EQ(back.landmarks.size(), 1u);
  EXPECT_FALSE(std::filesystem::exists(path + ".tmp"));
  EXPECT_THROW(write_map_checkpoint((dir / "missing" / "c.yaml").string(), c), std::runtime_error);
  std::filesystem::remove_all(dir);
}

// Was: yaml-cpp read the directory through an ifstream and std::ios_base::failure
// escaped the estimator's start (exit 1, the path not named).
TEST(MapCheckpoint, DirectoryIsAConfigErrorNamingIt) {
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / ("pixyslam_ckpt_dir_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  try {
    read_map_checkpoint(dir.string());
    ADD_FAILURE() << "read a directory as a checkpoint";
  } catch (const config::ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find(dir.string() + ": not a regular file"), std::string::npos) << e.what();
  }
  std::filesystem::remove_all(dir);
}

// A checkpoint may be larger than the 1 MiB limit of a configuration file.
TEST(MapCheckpoint, ACheckpointOverTheConfigFileLimitStillLoads) {
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / ("pixyslam_ckpt_big_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const std::string path = (dir / "c.yaml").string();
  MapCheckpoint c = sample_checkpoint();
  c.landmarks.clear();
  for (int id = 0; id < 8000; ++id) {
    c.landmarks.push_back({id, Eigen::Vector2d(id * 0.123456789, -id * 0.987654321),
                           (Eigen::Matrix2d() << 0.0031234567, 0.0011234567, 0.0011234567, 0.0021234567).finished(),
                           1000u + static_cast<std::uint32_t>(id)});
  }
  write_map_checkpoint(path, c);
  ASSERT_GT(std::filesystem::file_size(path), config::kMaxConfigFileBytes);
  EXPECT_EQ(read_map_checkpoint(path).landmarks.size(), 8000u);
  std::filesystem::remove_all(dir);
}

TEST(MapCheckpoint, ResumePoseWidensWithTheGap) {
  MapCheckpoint c = sample_checkpoint();
  c.control_v_mps = c.control_w_radps = 0.0;
  const slam::PoseGaussian now = resume_pose(c, 0.0, 0.5, 1.0, 5.0);
  EXPECT_EQ(now.cov, c.pose.cov);
  const slam::PoseGaussian later = resume_pose(c, 2.0, 0.5, 1.0, 5.0);
  EXPECT_EQ(later.mean, c.pose.mean);
  EXPECT_NEAR(later.cov(0, 0), c.pose.cov(0, 0) + 0.25, 1e-12);  // (0.5 m/s * 2 s / 2)^2
  EXPECT_NEAR(later.cov(1, 1), c.pose.cov(1, 1) + 0.25, 1e-12);
  EXPECT_NEAR(later.cov(2, 2), c.pose.cov(2, 2) + 1.0, 1e-12);    // (1 rad/s * 2 s / 2)^2
  EXPECT_NEAR(resume_pose(c, 1e6, 0.5, 1.0, 5.0).cov(2, 2), c.pose.cov(2, 2) + M_PI * M_PI, 1e-9);
}

// The robot most likely went on with the command the filter held: the resumed
// pose is moved by it over the gap, for as long as the filter would have held
// it (control_timeout_s after it came), as the filter predicts a gap in its
// odometry. The covariance is widened as without it.
TEST(MapCheckpoint, ResumePoseMovesOnWithTheHeldControl) {
  MapCheckpoint c = sample_checkpoint();
  c.control_v_mps = 0.3;
  c.control_w_radps = 0.5;
  c.control_age_s = 0.2;
  const slam::PoseGaussian resumed = resume_pose(c, 1.0, 0.5, 1.0, 5.0);
  EXPECT_TRUE(resumed.mean.isApprox(slam::move(c.pose.mean, 0.3, 0.5, 1.0), 1e-12));
  c.control_v_mps = c.control_w_radps = 0.0;
  EXPECT_EQ(resumed.cov, resume_pose(c, 1.0, 0.5, 1.0, 5.0).cov);
  // Held only until the control times out: 5 s after it came, 4.8 s after the checkpoint.
  c.control_v_mps = 0.3;
  c.control_w_radps = 0.5;
  EXPECT_TRUE(resume_pose(c, 20.0, 0.5, 1.0, 5.0).mean.isApprox(slam::move(c.pose.mean, 0.3, 0.5, 4.8), 1e-12));
  c.control_age_s = 6.0;
  EXPECT_EQ(resume_pose(c, 2.0, 0.5, 1.0, 5.0).mean, c.pose.mean);
}

// A filter restarted 0.4 m and 0.15 rad off with a saved map: started with the
// widened covariance it locks on to the map within a few frames.
TEST(MapCheckpoint, FilterStartedFromAWidePoseGaussianLocksOnToThePriorMap) {
  slam::FilterOptions options;
  options.particles = 100;
  options.seed = 3;
  const slam::Pose2 truth(1.0, 0.5, 0.3);
  std::vector<slam::LandmarkEstimate> map;
  for (int i = 0; i < 6; ++i) {
    const double a = -0.6 + 0.25 * i;
    map.push_back({i + 1, truth.head<2>() + 2.5 * Eigen::Vector2d(std::cos(truth.z() + a), std::sin(truth.z() + a)),
                   Eigen::Matrix2d::Identity() * 1e-4, 20});
  }
  MapCheckpoint c;
  c.pose.mean = truth + slam::Pose2(0.3, -0.25, 0.15);
  c.pose.cov = Eigen::Vector3d(1e-4, 1e-4, 1e-4).asDiagonal();
  c.landmarks = map;
  slam::FastSlam2 filter(options, resume_pose(c, 2.0, 0.5, 0.3, 5.0));
  filter.set_prior_map(map);
  for (int k = 0; k < 5; ++k) {
    slam::ObservationFrame frame;
    frame.t_s = 0.1 * k;
    for (const slam::LandmarkEstimate& l : map) {
      const Eigen::Vector2d d = l.mean - truth.head<2>();
      frame.detections.push_back({l.id, d.norm(), slam::wrap_angle(std::atan2(d.y(), d.x()) - truth.z()), 0.05, 0.02});
    }
    filter.add_observations(frame);
  }
  const slam::PoseEstimate e = filter.pose_estimate();
  EXPECT_LT((e.mean.head<2>() - truth.head<2>()).norm(), 0.05);
  EXPECT_LT(std::abs(slam::wrap_angle(e.mean.z() - truth.z())), 0.03);
  EXPECT_EQ(filter.counters().observations_gated, 0u);
}

TEST(MapCheckpoint, FilterRejectsANonFiniteStartPose) {
  slam::PoseGaussian bad;
  bad.cov(2, 2) = std::nan("");
  EXPECT_THROW(slam::FastSlam2(slam::FilterOptions{}, bad), std::invalid_argument);
}

// The checkpoint is the filter's own estimate (not a copy of a published
// message): pose and covariance as pose_estimate() gives them, the map chosen
// as the estimator publishes it.
TEST(MapCheckpoint, IsTheFiltersEstimate) {
  FilterOptions o;
  o.particles = 20;
  FastSlam2 filter(o, Pose2(0.5, -0.25, 0.3));
  for (int i = 1; i <= 30; ++i) {
    const double t = 0.1 * i;
    filter.add_odometry({t, 0.2, 0.1});
    ObservationFrame f;
    f.t_s = t + 0.05;
    f.detections.push_back({1, 2.0 - 0.02 * i, 0.3, 0.05, 0.02});
    f.detections.push_back({2, 3.0 - 0.02 * i, -0.4, 0.05, 0.02});
    filter.add_observations(f);
  }
  const PoseEstimate e = filter.pose_estimate();
  const MapCheckpoint c = checkpoint_of(filter, 42);
  EXPECT_EQ(c.stamp_ns, 42u);
  EXPECT_EQ(c.pose.mean, e.mean);
  EXPECT_TRUE(c.pose.cov.isApprox(e.cov, 1e-12));
  EXPECT_EQ(c.pose.cov, c.pose.cov.transpose());
  // The control held since the last odometry sample (0.05 s before the last frame).
  EXPECT_EQ(c.control_v_mps, 0.2);
  EXPECT_EQ(c.control_w_radps, 0.1);
  EXPECT_NEAR(c.control_age_s, 0.05, 1e-9);
  // The map is the mixture over the particles (its covariance with their spread).
  ASSERT_EQ(c.landmarks.size(), 2u);
  const std::vector<LandmarkEstimate> of_best = filter.landmarks_of_best();
  const std::vector<LandmarkEstimate> mixture = filter.landmarks_mixture();
  for (std::size_t i = 0; i < 2; ++i) {
    EXPECT_EQ(c.landmarks[i].id, mixture[i].id);
    EXPECT_EQ(c.landmarks[i].mean, mixture[i].mean);
    EXPECT_EQ(c.landmarks[i].cov, mixture[i].cov);
  }
  // Particles disagree a little: the mixture's covariance holds their spread.
  EXPECT_NE(mixture[0].cov, of_best[0].cov);
}

}  // namespace
}  // namespace pixyslam::slam
