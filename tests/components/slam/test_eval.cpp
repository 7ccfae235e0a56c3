#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "pixyslam/eval/csv_io.h"
#include "pixyslam/eval/rigid_alignment.h"
#include "pixyslam/eval/trajectory_metrics.h"

namespace pixyslam::eval {
namespace {

constexpr double kPi = 3.14159265358979323846;

Eigen::Vector2d rotate(double theta, const Eigen::Vector2d& p) {
  return Eigen::Vector2d(std::cos(theta) * p.x() - std::sin(theta) * p.y(),
                         std::sin(theta) * p.x() + std::cos(theta) * p.y());
}

// ---------------------------------------------------------------- rigid fit

TEST(RigidAlignment, RecoversKnownRotationAndTranslation) {
  const std::vector<Eigen::Vector2d> from = {{0, 0}, {1, 0}, {3, 2}, {-1, 4}, {2.5, -3}};
  for (const double theta : {0.7, -2.5, 3.0, 0.0}) {
    const Eigen::Vector2d t(1.5, -2.0);
    std::vector<Eigen::Vector2d> to;
    for (const auto& p : from) to.push_back(rotate(theta, p) + t);

    const Rigid2 fit = fit_rigid_2d(from, to);
    EXPECT_NEAR(wrap_angle(fit.theta_rad - theta), 0.0, 1e-12) << "theta " << theta;
    EXPECT_NEAR(fit.translation.x(), 1.5, 1e-12);
    EXPECT_NEAR(fit.translation.y(), -2.0, 1e-12);
    double sum_sq = 0;
    for (std::size_t i = 0; i < from.size(); ++i) sum_sq += (fit.apply(from[i]) - to[i]).squaredNorm();
    EXPECT_NEAR(std::sqrt(sum_sq / from.size()), 0.0, 1e-12);
  }
}

TEST(RigidAlignment, ApplyRotatesThenTranslates) {
  Rigid2 r;
  r.theta_rad = kPi / 2;
  r.translation = Eigen::Vector2d(10, 0);
  const Eigen::Vector2d q = r.apply(Eigen::Vector2d(1, 0));
  EXPECT_NEAR(q.x(), 10.0, 1e-12);
  EXPECT_NEAR(q.y(), 1.0, 1e-12);
}

TEST(RigidAlignment, RejectsBadInput) {
  const std::vector<Eigen::Vector2d> two = {{0, 0}, {1, 0}};
  const std::vector<Eigen::Vector2d> three = {{0, 0}, {1, 0}, {2, 0}};
  const std::vector<Eigen::Vector2d> one = {{0, 0}};
  EXPECT_THROW(fit_rigid_2d(two, three), std::invalid_argument);
  EXPECT_THROW(fit_rigid_2d(one, one), std::invalid_argument);
  EXPECT_NO_THROW(fit_rigid_2d(two, two));
}

TEST(WrapAngle, MapsIntoHalfOpenInterval) {
  EXPECT_DOUBLE_EQ(wrap_angle(kPi), kPi);
  EXPECT_DOUBLE_EQ(wrap_angle(-kPi), kPi);
  EXPECT_NEAR(wrap_angle(1.5 * kPi), -0.5 * kPi, 1e-12);
  EXPECT_NEAR(wrap_angle(-1.5 * kPi), 0.5 * kPi, 1e-12);
  EXPECT_NEAR(wrap_angle(0.1 + 4 * kPi), 0.1, 1e-12);
  EXPECT_DOUBLE_EQ(wrap_angle(0.25), 0.25);
}

// ---------------------------------------------------------------- trajectory

// Straight line at constant speed and yaw rate: x = t, y = 2t, theta = 0.1 t.
TimedPose line_pose(double t) { return TimedPose{t, t, 2 * t, wrap_angle(0.1 * t)}; }

TEST(CompareTrajectory, InterpolatesBetweenEstimateKnots) {
  std::vector<TimedPose> truth;
  for (int i = 0; i <= 10; ++i) truth.push_back(line_pose(i));
  // Estimate sampled on the same line but half a second out of phase: linear
  // interpolation reproduces truth exactly at the integer times 1..9.
  std::vector<TimedPose> estimate;
  for (int i = 0; i < 10; ++i) estimate.push_back(line_pose(i + 0.5));

  const TrajectoryErrors e = compare_trajectory(estimate, truth);
  EXPECT_EQ(e.samples, 9u);  // t = 0 and t = 10 lie outside [0.5, 9.5]
  EXPECT_NEAR(e.ate_rmse_m, 0.0, 1e-12);
  EXPECT_NEAR(e.heading_rmse_rad, 0.0, 1e-12);
  EXPECT_NEAR(e.max_position_error_m, 0.0, 1e-12);
  EXPECT_NEAR(e.ate_rmse_aligned_m, 0.0, 1e-9);
}

TEST(CompareTrajectory, DelayedEstimateGivesConstantErrorRemovedByAlignment) {
  std::vector<TimedPose> truth;
  std::vector<TimedPose> estimate;
  for (int i = 0; i <= 20; ++i) {
    truth.push_back(line_pose(i * 0.5));
    TimedPose late = line_pose(i * 0.5 - 0.5);  // estimate lags truth by 0.5 s
    late.t_s = i * 0.5;
    estimate.push_back(late);
  }
  const TrajectoryErrors e = compare_trajectory(estimate, truth);
  EXPECT_EQ(e.samples, 21u);
  EXPECT_NEAR(e.ate_rmse_m, 0.5 * std::sqrt(5.0), 1e-12);
  EXPECT_NEAR(e.max_position_error_m, 0.5 * std::sqrt(5.0), 1e-12);
  EXPECT_NEAR(e.heading_rmse_rad, 0.05, 1e-12);
  EXPECT_NEAR(e.ate_rmse_aligned_m, 0.0, 1e-9);  // a pure translation
}

TEST(PoseErrors, OnePerTruthPoseInTheSpanInTruthOrderAggregatingToCompareTrajectory) {
  // Estimate 0.3 m to the side of a straight line and 0.1 rad off, from t = 1 to 3 s;
  // truth every 0.5 s from 0 to 4 s, given newest first.
  const std::vector<TimedPose> estimate = {{1.0, 1.0, 0.3, 0.1}, {3.0, 3.0, 0.3, 0.1}};
  std::vector<TimedPose> truth;
  for (int i = 8; i >= 0; --i) truth.push_back({0.5 * i, 0.5 * i, 0.0, 0.0});
  const std::vector<PoseError> errors = pose_errors(estimate, truth);
  ASSERT_EQ(errors.size(), 5u);  // t = 3.0, 2.5, ..., 1.0
  for (std::size_t i = 0; i < errors.size(); ++i) {
    EXPECT_DOUBLE_EQ(errors[i].t_s, 3.0 - 0.5 * static_cast<double>(i));
    EXPECT_NEAR(errors[i].position_m, 0.3, 1e-12);
    EXPECT_NEAR(errors[i].heading_rad, 0.1, 1e-12);
  }
  const TrajectoryErrors e = compare_trajectory(estimate, truth);
  EXPECT_EQ(e.samples, errors.size());
  EXPECT_NEAR(e.ate_rmse_m, 0.3, 1e-12);
  EXPECT_THROW(pose_errors({}, truth), std::invalid_argument);
  EXPECT_THROW(pose_errors(estimate, {{9.0, 0, 0, 0}}), std::invalid_argument);
}

TEST(CompareTrajectory, HeadingInterpolatesAcrossPi) {
  const std::vector<TimedPose> estimate = {{0.0, 0, 0, kPi - 0.1}, {1.0, 0, 0, -kPi + 0.1}};
  // Shortest path from pi-0.1 to -pi+0.1 passes through pi: at t=0.5 heading is
  // +-pi, at t=0.25 it is pi-0.05. Naive interpolation would give 0 at t=0.5.
  const std::vector<TimedPose> truth = {{0.5, 0, 0, kPi}, {0.25, 0, 0, kPi - 0.05}, {0.75, 0, 0, -kPi + 0.05}};
  const TrajectoryErrors e = compare_trajectory(estimate, truth);
  EXPECT_EQ(e.samples, 3u);
  EXPECT_NEAR(e.heading_rmse_rad, 0.0, 1e-12);

  // A heading error across the cut is wrapped, not ~2 pi.
  const std::vector<TimedPose> off = {{0.0, 0, 0, kPi - 0.1}, {1.0, 0, 0, kPi - 0.1}};
  const std::vector<TimedPose> truth_cut = {{0.5, 0, 0, -kPi + 0.1}};
  EXPECT_NEAR(compare_trajectory(off, truth_cut).heading_rmse_rad, 0.2, 1e-12);
}

TEST(CompareTrajectory, RepeatedTimestampsUseLastPose) {
  const std::vector<TimedPose> estimate = {{0.0, 0, 0, 0}, {1.0, 100, 0, 0}, {1.0, 2, 0, 0}, {2.0, 4, 0, 0}};
  const std::vector<TimedPose> truth = {{0.5, 1, 0, 0}, {1.0, 2, 0, 0}, {1.5, 3, 0, 0}};
  const TrajectoryErrors e = compare_trajectory(estimate, truth);
  EXPECT_EQ(e.samples, 3u);
  EXPECT_NEAR(e.ate_rmse_m, 0.0, 1e-12);
  EXPECT_NEAR(e.max_position_error_m, 0.0, 1e-12);
}

TEST(CompareTrajectory, MaxAndRmseDiffer) {
  const std::vector<TimedPose> estimate = {{0.0, 0, 0, 0}, {2.0, 0, 0, 0}};
  const std::vector<TimedPose> truth = {{0.0, 3, 0, 0}, {1.0, 0, 4, 0}, {2.0, 0, 0, 0}};
  const TrajectoryErrors e = compare_trajectory(estimate, truth);
  EXPECT_EQ(e.samples, 3u);
  EXPECT_NEAR(e.max_position_error_m, 4.0, 1e-12);
  EXPECT_EQ(e.max_position_error_t_s, 1.0);  // the truth pose of the maximum
  EXPECT_NEAR(e.ate_rmse_m, std::sqrt(25.0 / 3.0), 1e-12);
}

TEST(CompareTrajectory, ThrowsWithoutOverlapOrOrder) {
  const std::vector<TimedPose> estimate = {{10.0, 0, 0, 0}, {11.0, 0, 0, 0}};
  const std::vector<TimedPose> truth = {{0.0, 0, 0, 0}, {9.99, 0, 0, 0}, {11.01, 0, 0, 0}};
  EXPECT_THROW(compare_trajectory(estimate, truth), std::invalid_argument);
  EXPECT_THROW(compare_trajectory({}, truth), std::invalid_argument);
  const std::vector<TimedPose> unsorted = {{1.0, 0, 0, 0}, {0.5, 0, 0, 0}};
  EXPECT_THROW(compare_trajectory(unsorted, {{0.75, 0, 0, 0}}), std::invalid_argument);
}

// ---------------------------------------------------------------- landmarks

TEST(CompareLandmarks, CountsMissingExtraAndAligns) {
  const std::vector<LandmarkPoint> truth = {{1, 0, 0}, {2, 4, 0}, {3, 4, 3}, {4, -2, 5}};
  // Estimate: ids 2,3,4 rigidly moved, id 1 missing, id 9 extra.
  std::vector<LandmarkPoint> estimate;
  const double theta = 0.3;
  const Eigen::Vector2d shift(1.0, -0.5);
  double raw_sum_sq = 0;
  for (const auto& l : truth) {
    if (l.id == 1) continue;
    const Eigen::Vector2d p = rotate(theta, Eigen::Vector2d(l.x_m, l.y_m)) + shift;
    estimate.push_back({l.id, p.x(), p.y()});
    raw_sum_sq += (p - Eigen::Vector2d(l.x_m, l.y_m)).squaredNorm();
  }
  estimate.push_back({9, 50, 50});

  const LandmarkErrors e = compare_landmarks(estimate, truth);
  EXPECT_EQ(e.matched, 3u);
  EXPECT_EQ(e.missing, 1u);
  EXPECT_EQ(e.extra, 1u);
  EXPECT_NEAR(e.rmse_m, std::sqrt(raw_sum_sq / 3.0), 1e-12);
  EXPECT_GT(e.rmse_m, 0.5);
  EXPECT_NEAR(e.rmse_aligned_m, 0.0, 1e-9);
}

TEST(CompareLandmarks, SingleMatchAlignedEqualsRaw) {
  const LandmarkErrors e = compare_landmarks({{5, 3, 4}}, {{5, 0, 0}, {6, 1, 1}});
  EXPECT_EQ(e.matched, 1u);
  EXPECT_EQ(e.missing, 1u);
  EXPECT_EQ(e.extra, 0u);
  EXPECT_NEAR(e.rmse_m, 5.0, 1e-12);
  EXPECT_DOUBLE_EQ(e.rmse_aligned_m, e.rmse_m);
}

TEST(CompareLandmarks, RejectsDuplicateIds) {
  EXPECT_THROW(compare_landmarks({{1, 0, 0}, {1, 1, 1}}, {{1, 0, 0}}), std::invalid_argument);
}

// ---------------------------------------------------------------- CSV

class CsvTest : public ::testing::Test {
 protected:
  void SetUp() override {
    std::random_device rd;
    dir_ = std::filesystem::temp_directory_path() /
           ("pixyslam_test_eval_" + std::to_string(rd()) + "_" + std::to_string(rd()));
    std::filesystem::create_directories(dir_);
  }
  void TearDown() override {
    std::error_code ec;
    std::filesystem::remove_all(dir_, ec);
  }
  std::string path(const std::string& name) const { return (dir_ / name).string(); }
  void write_text(const std::string& name, const std::string& text) const {
    std::ofstream(path(name), std::ios::binary) << text;
  }
  static std::string read_text(const std::string& p) {
    std::ifstream in(p, std::ios::binary);
    return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  }

  std::filesystem::path dir_;
};

TEST_F(CsvTest, TrajectoryRoundTripIsExact) {
  const std::vector<TimedPose> poses = {{1248444175.103, 1.4127729, -3.8910776, 2.2696},
                                        {1248444175.115123456, -0.1, 1e-7, -3.14159},
                                        {1248445075.1, 0, 0, 0}};
  write_trajectory_csv(path("traj.csv"), poses);
  const std::string text = read_text(path("traj.csv"));
  EXPECT_EQ(text.substr(0, text.find('\n')), "t,x,y,theta");

  const std::vector<TimedPose> back = read_trajectory_csv(path("traj.csv"));
  ASSERT_EQ(back.size(), poses.size());
  for (std::size_t i = 0; i < poses.size(); ++i) {
    EXPECT_EQ(back[i].t_s, poses[i].t_s);  // exact: millisecond unix times survive
    EXPECT_EQ(back[i].x_m, poses[i].x_m);
    EXPECT_EQ(back[i].y_m, poses[i].y_m);
    EXPECT_EQ(back[i].theta_rad, poses[i].theta_rad);
  }
}

// The streamed file (a live estimator's --out-dir) is the same file as the one
// written at once: the rows readable while it is still open, non-finite poses
// skipped and counted, an unwritable path named.
TEST_F(CsvTest, AStreamedTrajectoryIsTheSameFileAsOneWrittenAtOnce) {
  const std::vector<TimedPose> poses = {{1248444175.103, 1.4127729, -3.8910776, 2.2696},
                                        {1248444175.115123456, -0.1, 1e-7, -3.14159}};
  write_trajectory_csv(path("whole.csv"), poses);
  TrajectoryCsvWriter writer(path("streamed.csv"));
  writer.append(poses[0]);
  writer.append({1248444175.11, std::nan(""), 0.0, 0.0});
  writer.append(poses[1]);
  writer.flush();
  EXPECT_EQ(read_text(path("streamed.csv")), read_text(path("whole.csv")));
  EXPECT_EQ(writer.rows(), 2u);
  EXPECT_EQ(writer.skipped(), 1u);
  try {
    TrajectoryCsvWriter missing(path("no_such_dir/x.csv"));
    FAIL() << "expected std::runtime_error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("no_such_dir/x.csv: cannot open"), std::string::npos) << e.what();
  }
}

TEST_F(CsvTest, TrajectoryReaderAcceptsCrlfAndBlankLines) {
  write_text("crlf.csv", "t,x,y,theta\r\n1.5,2,3,0.25\r\n\r\n2.5, 4 ,5,-0.5\r\n");
  const std::vector<TimedPose> poses = read_trajectory_csv(path("crlf.csv"));
  ASSERT_EQ(poses.size(), 2u);
  EXPECT_EQ(poses[1].t_s, 2.5);
  EXPECT_EQ(poses[1].x_m, 4.0);
  EXPECT_EQ(poses[1].theta_rad, -0.5);
}

TEST_F(CsvTest, MalformedTrajectoryLineNamesFileAndLine) {
  write_text("bad.csv", "t,x,y,theta\n1,2,3,4\n2,3,4,5\n3,abc,5,6\n");
  try {
    read_trajectory_csv(path("bad.csv"));
    FAIL() << "expected std::runtime_error";
  } catch (const std::runtime_error& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("bad.csv:4"), std::string::npos) << msg;
    EXPECT_NE(msg.find("abc"), std::string::npos) << msg;
  }

  write_text("short.csv", "t,x,y,theta\n1,2,3,4\n2,3,4\n");
  try {
    read_trajectory_csv(path("short.csv"));
    FAIL() << "expected std::runtime_error";
  } catch (const std::runtime_error& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("short.csv:3"), std::string::npos) << msg;
    EXPECT_NE(msg.find("expected 4 fields, found 3"), std::string::npos) << msg;
  }
}

TEST_F(CsvTest, WrongHeaderAndMissingFileThrow) {
  write_text("hdr.csv", "time,x,y,theta\n1,2,3,4\n");
  EXPECT_THROW(read_trajectory_csv(path("hdr.csv")), std::runtime_error);
  write_text("empty.csv", "");
  EXPECT_THROW(read_trajectory_csv(path("empty.csv")), std::runtime_error);
  EXPECT_THROW(read_trajectory_csv(path("does_not_exist.csv")), std::runtime_error);
  EXPECT_THROW(write_trajectory_csv(path("no_such_dir/x.csv"), {}), std::runtime_error);
  EXPECT_THROW(write_trajectory_csv(path("nan.csv"), {{0, std::nan(""), 0, 0}}), std::runtime_error);
}

TEST_F(CsvTest, LandmarkRoundTrip) {
  const std::vector<LandmarkRow> rows = {{6, 0.58831396, -4.28264845, 1e-4, -2.5e-6, 3e-4},
                                         {17, -1.25, 2.5, 0.01, 0.0, 0.02}};
  write_landmarks_csv(path("lm.csv"), rows);
  const std::string text = read_text(path("lm.csv"));
  EXPECT_EQ(text.substr(0, text.find('\n')), "id,x,y,cov_xx,cov_xy,cov_yy");

  const std::vector<LandmarkRow> back = read_landmarks_csv(path("lm.csv"));
  ASSERT_EQ(back.size(), rows.size());
  for (std::size_t i = 0; i < rows.size(); ++i) {
    EXPECT_EQ(back[i].id, rows[i].id);
    EXPECT_EQ(back[i].x_m, rows[i].x_m);
    EXPECT_EQ(back[i].y_m, rows[i].y_m);
    EXPECT_EQ(back[i].cov_xx, rows[i].cov_xx);
    EXPECT_EQ(back[i].cov_xy, rows[i].cov_xy);
    EXPECT_EQ(back[i].cov_yy, rows[i].cov_yy);
  }

  write_text("lm_bad.csv", "id,x,y,cov_xx,cov_xy,cov_yy\n6,1,2,0,0,0\n7.5,1,2,0,0,0\n");
  try {
    read_landmarks_csv(path("lm_bad.csv"));
    FAIL() << "expected std::runtime_error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("lm_bad.csv:3"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace pixyslam::eval
