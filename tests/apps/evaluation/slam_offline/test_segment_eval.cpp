// Summary statistics, truth interpolation, segment starts and pose NEES of
// mrclam_eval --segments (pixyslam/offline/segment_eval.h). No data files.
#include <cmath>
#include <stdexcept>
#include <vector>

#include <gtest/gtest.h>

#include "pixyslam/offline/segment_eval.h"

namespace pixyslam::offline {
namespace {

TEST(SegmentSummary, MeanMedianP90AndMax) {
  // Unsorted on purpose; sorted 1..10: median 5.5, p90 at rank 8.1 -> 9.1.
  const Summary s = summarize({7, 3, 10, 1, 5, 9, 2, 8, 6, 4});
  EXPECT_EQ(s.count, 10u);
  EXPECT_DOUBLE_EQ(s.mean, 5.5);
  EXPECT_DOUBLE_EQ(s.median, 5.5);
  EXPECT_NEAR(s.p90, 9.1, 1e-12);
  EXPECT_DOUBLE_EQ(s.max, 10.0);
}

TEST(SegmentSummary, OddCountSingleValueAndEmpty) {
  const Summary odd = summarize({0.3, 0.1, 0.2});
  EXPECT_DOUBLE_EQ(odd.median, 0.2);
  EXPECT_NEAR(odd.p90, 0.28, 1e-12);  // rank 1.8 between 0.2 and 0.3
  const Summary one = summarize({2.5});
  EXPECT_EQ(one.count, 1u);
  EXPECT_DOUBLE_EQ(one.mean, 2.5);
  EXPECT_DOUBLE_EQ(one.median, 2.5);
  EXPECT_DOUBLE_EQ(one.p90, 2.5);
  EXPECT_DOUBLE_EQ(one.max, 2.5);
  const Summary none = summarize({});
  EXPECT_EQ(none.count, 0u);
  EXPECT_DOUBLE_EQ(none.mean, 0.0);
  EXPECT_DOUBLE_EQ(none.max, 0.0);
}

TEST(SegmentTruth, InterpolatesAcrossTheShorterArc) {
  const std::vector<eval::TimedPose> truth{{10.0, 0.0, 0.0, 3.0}, {11.0, 2.0, -1.0, -3.0}, {13.0, 2.0, -1.0, 0.0}};
  const auto mid = interpolate_pose(truth, 10.5, 1.5);
  ASSERT_TRUE(mid.has_value());
  EXPECT_DOUBLE_EQ(mid->x_m, 1.0);
  EXPECT_DOUBLE_EQ(mid->y_m, -0.5);
  // 3.0 -> -3.0 rad goes through pi (0.283 rad), not through 0 (6 rad).
  EXPECT_NEAR(std::abs(mid->theta_rad), M_PI, 1e-12);
  const auto exact = interpolate_pose(truth, 13.0, 0.5);
  ASSERT_TRUE(exact.has_value());
  EXPECT_DOUBLE_EQ(exact->theta_rad, 0.0);
  EXPECT_FALSE(interpolate_pose(truth, 9.99, 10.0).has_value());   // before the truth
  EXPECT_FALSE(interpolate_pose(truth, 13.01, 10.0).has_value());  // after it
  EXPECT_FALSE(interpolate_pose(truth, 12.0, 1.5).has_value());    // inside a 2-s gap
  EXPECT_TRUE(interpolate_pose(truth, 12.0, 2.0).has_value());
}

TEST(SegmentStarts, EveryPeriodWithAFullPeriodOfTruthLeft) {
  const double t0 = 1248444175.103;  // unix times as in MRCLAM
  const std::vector<eval::TimedPose> truth{{t0, 0, 0, 0}, {t0 + 900.0, 0, 0, 0}};
  const std::vector<double> starts = segment_starts(truth, 60.0);
  ASSERT_EQ(starts.size(), 15u);
  EXPECT_DOUBLE_EQ(starts.front(), t0);
  EXPECT_NEAR(starts.back() - t0, 840.0, 1e-6);
  const std::vector<eval::TimedPose> short_truth{{0.0, 0, 0, 0}, {771.9, 0, 0, 0}};
  EXPECT_EQ(segment_starts(short_truth, 60.0).size(), 12u);  // last start 660 s
  EXPECT_TRUE(segment_starts({}, 60.0).empty());
  EXPECT_TRUE(segment_starts(short_truth, 1000.0).empty());
  EXPECT_THROW(segment_starts(truth, 0.0), std::invalid_argument);
}

TEST(PoseNees, KnownCovarianceGivesKnownValue) {
  // Diagonal: (0.2/0.1)^2 + (0.3/0.3)^2 + (0.05/0.05)^2 = 6.
  const Eigen::Matrix3d diag = Eigen::Vector3d(0.01, 0.09, 0.0025).asDiagonal();
  const auto nees = pose_nees(Eigen::Vector3d(0.2, -0.3, 0.05), diag);
  ASSERT_TRUE(nees.has_value());
  EXPECT_NEAR(*nees, 6.0, 1e-12);
  // Correlated x, y: the closed-form inverse of [[2, 1], [1, 2]] is [[2, -1], [-1, 2]] / 3.
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  cov << 2, 1, 0, 1, 2, 0, 0, 0, 4;
  const auto correlated = pose_nees(Eigen::Vector3d(1.0, 1.0, 2.0), cov);
  ASSERT_TRUE(correlated.has_value());
  EXPECT_NEAR(*correlated, (2.0 - 2.0 + 2.0) / 3.0 + 1.0, 1e-12);
}

TEST(PoseNees, HeadingErrorIsWrapped) {
  const Eigen::Matrix3d cov = Eigen::Vector3d(1.0, 1.0, 0.01).asDiagonal();
  // 2 pi - 0.1 is a 0.1 rad error: (0.1 / 0.1)^2 = 1.
  const auto nees = pose_nees(Eigen::Vector3d(0.0, 0.0, 2.0 * M_PI - 0.1), cov);
  ASSERT_TRUE(nees.has_value());
  EXPECT_NEAR(*nees, 1.0, 1e-9);
}

TEST(PoseNees, SingularOrNonFiniteCovarianceIsSkipped) {
  EXPECT_FALSE(pose_nees(Eigen::Vector3d(0.1, 0.1, 0.1), Eigen::Matrix3d::Zero()).has_value());
  Eigen::Matrix3d rank2 = Eigen::Matrix3d::Zero();
  rank2 << 1, 1, 0, 1, 1, 0, 0, 0, 1;
  EXPECT_FALSE(pose_nees(Eigen::Vector3d(0.1, 0.1, 0.1), rank2).has_value());
  Eigen::Matrix3d nan = Eigen::Matrix3d::Identity();
  nan(2, 2) = std::nan("");
  EXPECT_FALSE(pose_nees(Eigen::Vector3d(0.1, 0.1, 0.1), nan).has_value());
}

TEST(PoseNees, TrajectoryCountsBoundsAndSingularSteps) {
  std::vector<eval::TimedPose> truth;  // every 0.25 s: closer than kTruthMaxGapS
  for (int i = 0; i <= 40; ++i) truth.push_back({0.25 * i, 0.25 * i, 0.0, 0.0});
  const Eigen::Matrix3d unit = Eigen::Matrix3d::Identity();
  // Truth at t is (t, 0, 0); errors in x of 0.1, 1, 2, 4 -> NEES 0.01, 1, 4, 16.
  const std::vector<eval::TimedPose> est{
      {1.0, 1.1, 0, 0}, {2.0, 3.0, 0, 0}, {3.0, 5.0, 0, 0}, {4.0, 8.0, 0, 0}, {5.0, 5.0, 0, 0}, {11.0, 11.0, 0, 0}};
  const std::vector<Eigen::Matrix3d> cov{unit, unit, unit, unit, Eigen::Matrix3d::Zero(), unit};
  const NeesStats s = trajectory_nees(est, cov, truth);
  EXPECT_EQ(s.steps, 4u);     // the last step has no truth
  EXPECT_EQ(s.singular, 1u);  // the zero covariance
  EXPECT_EQ(s.inside_95, 2u);    // 1 and 4 (0.01 is below the lower bound)
  EXPECT_EQ(s.below_upper, 3u);  // all but 16
  EXPECT_NEAR(s.mean(), (0.01 + 1 + 4 + 16) / 4.0, 1e-12);
  EXPECT_DOUBLE_EQ(s.fraction_inside(), 0.5);
  EXPECT_DOUBLE_EQ(s.fraction_below_upper(), 0.75);
  NeesStats pooled = s;
  pooled.merge(s);
  EXPECT_EQ(pooled.steps, 8u);
  EXPECT_EQ(pooled.singular, 2u);
  EXPECT_NEAR(pooled.mean(), s.mean(), 1e-12);
  EXPECT_THROW(trajectory_nees(est, {unit}, truth), std::invalid_argument);
  // Across a truth gap wider than kTruthMaxGapS nothing is compared.
  const std::vector<eval::TimedPose> sparse{{0.0, 0.0, 0.0, 0.0}, {10.0, 10.0, 0.0, 0.0}};
  const NeesStats gap = trajectory_nees(est, cov, sparse);
  EXPECT_EQ(gap.steps + gap.singular, 0u);
}

TEST(PoseNees, ChiSquareBoundsOf3Dof) {
  // chi2.ppf(0.025, 3) and chi2.ppf(0.975, 3).
  EXPECT_NEAR(kNees3Lower95, 0.215795, 1e-4);
  EXPECT_NEAR(kNees3Upper95, 9.348404, 1e-4);
}

}  // namespace
}  // namespace pixyslam::offline
