// The fleet map's core: landmark maps of several robots fused by id after a
// check that their frames agree.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <stdexcept>
#include <vector>

#include <Eigen/Geometry>

#include "pixyslam/fleet_map/map_fusion.h"

namespace pixyslam::fleet_map {
namespace {

LandmarkEstimate landmark(int id, double x, double y, double sigma) {
  LandmarkEstimate l;
  l.id = id;
  l.mean = {x, y};
  l.cov = Eigen::Matrix2d::Identity() * sigma * sigma;
  return l;
}

// Robot `name`'s map of the true landmarks (id, x, y) with noise `sigma`,
// moved by a rotation `yaw` about the origin and a shift (dx, dy).
RobotMap noisy_map(const std::string& name, const std::vector<Eigen::Vector3d>& truth, double sigma, std::mt19937& prng,
                   double yaw = 0.0, double dx = 0.0, double dy = 0.0) {
  std::normal_distribution<double> noise(0.0, sigma);
  RobotMap m;
  m.robot_id = name;
  const Eigen::Rotation2Dd r(yaw);
  for (const Eigen::Vector3d& t : truth) {
    const Eigen::Vector2d p = r * Eigen::Vector2d(t.y(), t.z()) + Eigen::Vector2d(dx, dy);
    m.landmarks.push_back(landmark(static_cast<int>(t.x()), p.x() + noise(prng), p.y() + noise(prng), sigma));
  }
  return m;
}

std::vector<Eigen::Vector3d> truth_grid() {
  std::vector<Eigen::Vector3d> t;
  for (int i = 0; i < 15; ++i) t.emplace_back(6 + i, (i % 5) * 1.2, (i / 5) * 1.5);
  return t;
}

FusionOptions set_aside() {
  FusionOptions o;
  o.disagreement = FusionOptions::Disagreement::kSetAside;
  return o;
}

double rmse(const FleetMap& fleet, const std::vector<Eigen::Vector3d>& truth) {
  double sum = 0.0;
  for (const FusedLandmark& l : fleet.landmarks) {
    const Eigen::Vector3d& t = truth[static_cast<std::size_t>(l.id - 6)];
    sum += (l.mean - Eigen::Vector2d(t.y(), t.z())).squaredNorm();
  }
  return std::sqrt(sum / static_cast<double>(fleet.landmarks.size()));
}

TEST(FQuantile, MatchesTables) {
  EXPECT_NEAR(f_quantile(0.95, 1, 10), 4.965, 1e-3);
  EXPECT_NEAR(f_quantile(0.99, 3, 10), 6.552, 1e-3);
  EXPECT_NEAR(f_quantile(0.95, 2, 2), 19.0, 1e-6);
  EXPECT_NEAR(f_quantile(0.999, 3, 27), 7.27, 0.01);
  EXPECT_THROW(f_quantile(1.0, 3, 3), std::invalid_argument);
  EXPECT_THROW(f_quantile(0.5, 0, 3), std::invalid_argument);
}

TEST(FuseMaps, OneLandmarkIsTheInformationWeightedMean) {
  RobotMap a{"robot1", 0, {landmark(7, 1.0, 0.0, 0.1)}};
  RobotMap b{"robot2", 0, {landmark(7, 1.1, 0.0, 0.2)}};
  const FleetMap f = fuse_maps({a, b});
  ASSERT_EQ(f.landmarks.size(), 1u);
  // Weights 1/0.01 and 1/0.04: (100 * 1.0 + 25 * 1.1) / 125 = 1.02, variance 1/125.
  EXPECT_NEAR(f.landmarks[0].mean.x(), 1.02, 1e-12);
  EXPECT_NEAR(f.landmarks[0].cov(0, 0), 1.0 / 125.0, 1e-12);
  EXPECT_EQ(f.landmarks[0].robots, 2u);
  // One shared landmark is below min_common_landmarks (4): unchecked, fused.
  EXPECT_EQ(f.robots[0].verdict, FrameVerdict::kUnchecked);
  EXPECT_EQ(f.robots[0].common, 1u);
}

TEST(FuseMaps, RobotsInOneFrameAgreeAndTheFusionBeatsEachOfThem) {
  std::mt19937 prng(5);
  const auto truth = truth_grid();
  std::vector<RobotMap> maps;
  for (int r = 1; r <= 4; ++r) maps.push_back(noisy_map("robot" + std::to_string(r), truth, 0.05, prng));
  const FleetMap f = fuse_maps(maps);
  ASSERT_EQ(f.landmarks.size(), 15u);
  for (const FrameCheck& c : f.robots) {
    EXPECT_EQ(c.verdict, FrameVerdict::kAgrees) << c.robot_id << " F " << c.f_statistic << " / " << c.threshold;
    EXPECT_EQ(c.common, 15u);
    EXPECT_LT(c.offset_m, 0.05);
    EXPECT_LT(c.residual_m, 0.1);
  }
  double best_single = 1e9;
  for (const RobotMap& m : maps) {
    const FleetMap alone = fuse_maps({m});
    best_single = std::min(best_single, rmse(alone, truth));
  }
  // Four independent maps: about half the error of one.
  EXPECT_LT(rmse(f, truth), 0.75 * best_single);
}

TEST(FuseMaps, ARobotInAnotherFrameIsSetAsideAndNamed) {
  std::mt19937 prng(9);
  const auto truth = truth_grid();
  std::vector<RobotMap> maps = {noisy_map("robot1", truth, 0.05, prng), noisy_map("robot2", truth, 0.05, prng),
                                noisy_map("robot3", truth, 0.05, prng, 0.3, 0.5, -0.2)};
  const FleetMap f = fuse_maps(maps, set_aside());
  EXPECT_EQ(f.robots[0].verdict, FrameVerdict::kAgrees);
  EXPECT_EQ(f.robots[1].verdict, FrameVerdict::kAgrees);
  EXPECT_EQ(f.robots[2].verdict, FrameVerdict::kDisagrees);
  EXPECT_NEAR(f.robots[2].rotation_rad, -0.3, 0.03);  // the rotation that takes it back
  EXPECT_GT(f.robots[2].offset_m, 0.3);
  EXPECT_FALSE(f.robots[2].fused);
  for (const FusedLandmark& l : f.landmarks) EXPECT_EQ(l.robots, 2u);
  EXPECT_LT(rmse(f, truth), 0.06);
}

TEST(FuseMaps, AlignMovesEveryMapOntoTheMeanFrame) {
  // Given three maps whose frames are off by -0.1, 0 and +0.1 rad and shifted
  // (their mean: the true frame),
  std::mt19937 prng(4);
  const auto truth = truth_grid();
  std::vector<RobotMap> maps = {noisy_map("robot1", truth, 0.03, prng, -0.1, 0.2, 0.0),
                                noisy_map("robot2", truth, 0.03, prng),
                                noisy_map("robot3", truth, 0.03, prng, 0.1, -0.2, 0.0)};
  // when fused with kAlign (the default), the frames are reported as they came,
  const FleetMap f = fuse_maps(maps);
  EXPECT_EQ(f.robots[0].verdict, FrameVerdict::kDisagrees);
  EXPECT_EQ(f.robots[2].verdict, FrameVerdict::kDisagrees);
  // each map was moved back by its own rotation,
  EXPECT_NEAR(f.robots[0].moved_rotation_rad, 0.1, 0.02);
  EXPECT_NEAR(f.robots[1].moved_rotation_rad, 0.0, 0.02);
  EXPECT_NEAR(f.robots[2].moved_rotation_rad, -0.1, 0.02);
  for (const FrameCheck& c : f.robots) EXPECT_TRUE(c.fused);
  // and the fleet map lies in the true frame, better than any one map.
  for (const FusedLandmark& l : f.landmarks) EXPECT_EQ(l.robots, 3u);
  EXPECT_LT(rmse(f, truth), 0.04);
  const FleetMap set_apart = fuse_maps(maps, set_aside());
  EXPECT_GT(rmse(set_apart, truth), rmse(f, truth));
}

TEST(FuseMaps, OfTwoThatDisagreeTheOneWithFewerLandmarksIsSetAside) {
  std::mt19937 prng(2);
  auto truth = truth_grid();
  RobotMap a = noisy_map("robot1", truth, 0.05, prng);
  truth.pop_back();
  RobotMap b = noisy_map("robot2", truth, 0.05, prng, 0.0, 1.0, 0.0);
  const FleetMap f = fuse_maps({a, b}, set_aside());
  EXPECT_EQ(f.robots[1].verdict, FrameVerdict::kDisagrees);
  EXPECT_EQ(f.robots[0].verdict, FrameVerdict::kUnchecked);  // nothing left to check against
  for (const FusedLandmark& l : f.landmarks) EXPECT_EQ(l.robots, 1u);
}

TEST(FuseMaps, BrokenCovariancesAreSkippedAndBadInputRefused) {
  RobotMap a{"robot1", 0, {landmark(7, 1.0, 0.0, 0.1), landmark(8, 2.0, 0.0, 0.1)}};
  a.landmarks[1].cov(0, 0) = std::nan("");
  RobotMap b{"robot2", 0, {landmark(8, 2.0, 0.0, 0.1)}};
  b.landmarks[0].cov << 1.0, 2.0, 2.0, 1.0;  // not positive definite
  const FleetMap f = fuse_maps({a, b});
  ASSERT_EQ(f.landmarks.size(), 1u);
  EXPECT_EQ(f.landmarks[0].id, 7);
  EXPECT_THROW(fuse_maps({a, a}), std::invalid_argument);
  FusionOptions bad;
  bad.agreement_probability = 1.0;
  EXPECT_THROW(fuse_maps({a}, bad), std::invalid_argument);
  EXPECT_TRUE(fuse_maps({}).landmarks.empty());
}

// What no estimator of a real map sends (a hostile or broken participant):
// far-off positions, vanishing or enormous variances. Each is skipped; the
// fused map of the honest robots stays where it is, finite.
TEST(FuseMaps, ImplausibleLandmarksAreSkippedAndCannotSpoilTheFusion) {
  std::mt19937 prng(5);
  const std::vector<Eigen::Vector3d> truth = truth_grid();
  const RobotMap a = noisy_map("robot1", truth, 0.05, prng);
  const RobotMap b = noisy_map("robot2", truth, 0.05, prng);
  const double honest = rmse(fuse_maps({a, b}), truth);
  for (const auto& [x, sigma] : std::vector<std::pair<double, double>>{{1e200, 1e-75}, {1e300, 1.0}, {1e7, 0.1},
                                                                         {3.0, 1e-9}, {3.0, 1e4}}) {
    RobotMap hostile{"intruder", 0, {}};
    for (const Eigen::Vector3d& t : truth) hostile.landmarks.push_back(landmark(static_cast<int>(t.x()), t.y(), t.z(), 0.05));
    hostile.landmarks.push_back(landmark(static_cast<int>(truth.front().x()), x, 0.0, sigma));
    hostile.landmarks.erase(hostile.landmarks.begin());  // the implausible one instead of the first
    const FleetMap f = fuse_maps({a, b, hostile});
    for (const FusedLandmark& l : f.landmarks) {
      EXPECT_TRUE(l.mean.allFinite()) << x << " " << sigma;
      EXPECT_LT(l.mean.norm(), 100.0) << x << " " << sigma;
    }
    EXPECT_LT(rmse(f, truth), 2.0 * honest + 0.05) << x << " " << sigma;
  }
}

}  // namespace
}  // namespace pixyslam::fleet_map
