// The fit of the MRCLAM corrections (pixyslam/mrclam/mrclam_fit.h) on
// synthesised robots with known corrections: a robot driven by random commands
// that act delay_s late and at speed v (scale - loss |w|), motion capture at
// 100 Hz, a camera at 5 Hz reading poles on a grid with
// range = r* scale cos(b)^exponent (1 % noise). With 5 % gross outliers:
// misread ranges, and motion-capture glitches (position off by up to 1 m,
// random heading). No data files.
#include <cmath>
#include <cstdint>
#include <random>
#include <stdexcept>
#include <vector>

#include <gtest/gtest.h>

#include "pixyslam/mrclam/mrclam_fit.h"

namespace pixyslam::mrclam {
namespace {

struct Truth {
  double range_scale = 1.03;
  double exponent = 0.85;
  double delay_s = 0.15;
  double speed_scale = 1.04;
  double speed_loss = 1.13;
};

double wrap(double a) { return std::remainder(a, 2.0 * M_PI); }

// One synthesised robot: duration_s of data, `outliers` the fraction of
// range readings and of motion-capture samples replaced by gross errors.
RobotData synthesise(std::uint32_t seed, const Truth& truth, double outliers, double duration_s = 600.0) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> uni(0.0, 1.0);
  std::normal_distribution<double> normal(0.0, 1.0);
  RobotData d;
  d.robot = 1;
  for (int i = 0; i < 81; ++i) {
    d.landmarks.push_back({6 + i, -8.0 + 2.0 * (i % 9), -8.0 + 2.0 * (i / 9)});
  }
  const double t0 = 1248444175.0;  // unix times as in MRCLAM
  double x = 0.0, y = 0.0, th = 0.3;
  // Commands: piecewise constant for 0.1-1.5 s, logged every 15 ms.
  double v_cmd = 0.0, w_cmd = 0.0, segment_end = 0.0;
  const double dt = 0.001;
  const int steps = static_cast<int>(duration_s / dt);
  double next_log = 0.0, next_truth = 0.0, next_frame = 1.0;
  // The command in force at time s: the last logged row at or before s.
  std::size_t applied = 0;
  for (int k = 0; k <= steps; ++k) {
    const double t = k * dt;
    if (t >= segment_end) {
      segment_end = t + 0.1 + 1.4 * uni(rng);
      v_cmd = uni(rng) < 0.15 ? 0.0 : 0.06 + 0.14 * uni(rng);
      w_cmd = uni(rng) < 0.3 ? 0.0 : -0.5 + uni(rng);
      if (std::hypot(x, y) > 4.0) {  // head back towards the middle
        w_cmd = wrap(std::atan2(-y, -x) - th) > 0.0 ? 0.4 : -0.4;
      }
    }
    if (t >= next_log) {
      d.odometry.push_back({t0 + t, v_cmd, w_cmd});
      next_log += 0.015;
    }
    // Truth at 100 Hz, with a 2-s motion-capture gap at 300 s.
    if (t >= next_truth) {
      if (t < 300.0 || t > 302.0) {
        eval::TimedPose p{t0 + t, x + 0.0005 * normal(rng), y + 0.0005 * normal(rng), wrap(th + 0.002 * normal(rng))};
        if (uni(rng) < outliers) {
          p.x_m += -1.0 + 2.0 * uni(rng);
          p.y_m += -1.0 + 2.0 * uni(rng);
          p.theta_rad = -M_PI + 2.0 * M_PI * uni(rng);
        }
        d.groundtruth.push_back(p);
      }
      next_truth += 0.01;
    }
    if (t >= next_frame) {
      MeasurementFrame f{t0 + t, {}};
      for (const eval::LandmarkPoint& l : d.landmarks) {
        const double r_true = std::hypot(l.x_m - x, l.y_m - y);
        const double b_true = wrap(std::atan2(l.y_m - y, l.x_m - x) - th);
        if (r_true < 0.3 || r_true > 6.0 || std::abs(b_true) > 0.6) continue;
        const double b = b_true + 0.005 * normal(rng);
        double r = r_true * truth.range_scale * std::pow(std::cos(b), truth.exponent) * std::exp(0.01 * normal(rng));
        if (uni(rng) < outliers) r = 0.3 + 7.7 * uni(rng);
        f.detections.push_back({l.id, r, b});
      }
      // Another robot (subject 3) and a pole without a known position: never used.
      f.detections.push_back({3, 0.1 + 5.0 * uni(rng), 0.2});
      f.detections.push_back({99, 0.1 + 5.0 * uni(rng), -0.2});
      d.frames.push_back(std::move(f));
      next_frame += 0.2;
    }
    // Motion under the command logged delay_s earlier.
    while (applied + 1 < d.odometry.size() && d.odometry[applied + 1].t_s - t0 <= t - truth.delay_s) ++applied;
    double v = 0.0, w = 0.0;
    if (!d.odometry.empty() && d.odometry[applied].t_s - t0 <= t - truth.delay_s) {
      w = d.odometry[applied].w_radps;
      v = d.odometry[applied].v_mps * std::max(0.0, truth.speed_scale - truth.speed_loss * std::abs(w));
    }
    x += v * dt * std::cos(th + 0.5 * w * dt);
    y += v * dt * std::sin(th + 0.5 * w * dt);
    th += w * dt;
  }
  return d;
}

// The synthesised robots, made once per test program.
const RobotData& robot(int which) {
  static const RobotData clean = synthesise(11, Truth{}, 0.0);
  static const RobotData dirty = synthesise(12, Truth{}, 0.05);
  static const RobotData neutral = synthesise(13, Truth{1.0, 0.0, 0.0, 1.0, 0.0}, 0.05);
  static const RobotData late = synthesise(14, Truth{0.97, 1.2, 0.32, 0.95, 0.6}, 0.05);
  switch (which) {
    case 0: return clean;
    case 1: return dirty;
    case 2: return neutral;
    default: return late;
  }
}

TEST(MrclamFitRegression, RecoversALineDespiteGrossOutliers) {
  std::mt19937 rng(5);
  std::normal_distribution<double> normal(0.0, 0.1);
  std::uniform_real_distribution<double> uni(0.0, 1.0);
  const int n = 2000;
  Eigen::MatrixXd X(n, 2);
  Eigen::VectorXd y(n);
  for (int i = 0; i < n; ++i) {
    const double x = -1.0 + 2.0 * uni(rng);
    X(i, 0) = 1.0;
    X(i, 1) = x;
    y[i] = 2.0 + 3.0 * x + normal(rng);
    if (i % 20 == 0) y[i] += 20.0 + 30.0 * uni(rng);  // 5 %, all on one side
  }
  const RobustLinearFit f = robust_linear_fit(X, y);
  EXPECT_NEAR(f.coef[0], 2.0, 0.015);
  EXPECT_NEAR(f.coef[1], 3.0, 0.02);
  EXPECT_NEAR(f.sigma, 0.1, 0.01);
  EXPECT_EQ(f.samples, 2000u);
  EXPECT_LE(f.inliers, 1900u + 10u);  // the outliers are out
  EXPECT_GE(f.inliers, 1880u);
  EXPECT_THROW(robust_linear_fit(X.topRows(3), y.head(3)), std::invalid_argument);
  EXPECT_THROW(robust_linear_fit(X, y.head(10)), std::invalid_argument);
  Eigen::MatrixXd singular = X;
  singular.col(1) = singular.col(0);
  EXPECT_THROW(robust_linear_fit(singular, y), std::invalid_argument);
}

TEST(MrclamFitRange, RecoversScaleAndExponent) {
  const RangeFit f = fit_range({&robot(0)});
  EXPECT_NEAR(f.range_scale, 1.03, 0.002);
  EXPECT_NEAR(f.cos_bearing_exponent, 0.85, 0.015);
  EXPECT_GT(f.samples, 5000u);
  EXPECT_NEAR(f.log_sigma, 0.01, 0.002);
  EXPECT_NEAR(f.bearing_sigma_rad, 0.005, 0.001);
  EXPECT_LT(f.range_sigma_m, 0.5 * f.range_sigma_before_m);
}

TEST(MrclamFitRange, RecoversScaleAndExponentWithGrossOutliers) {
  const RangeFit f = fit_range({&robot(1)});
  EXPECT_NEAR(f.range_scale, 1.03, 0.002);
  EXPECT_NEAR(f.cos_bearing_exponent, 0.85, 0.015);
  EXPECT_LT(f.inliers, f.samples - f.samples / 25);  // the misreadings are out
  const RangeFit other = fit_range({&robot(3)});
  EXPECT_NEAR(other.range_scale, 0.97, 0.002);
  EXPECT_NEAR(other.cos_bearing_exponent, 1.2, 0.015);
  const RangeFit neutral = fit_range({&robot(2)});
  EXPECT_NEAR(neutral.range_scale, 1.0, 0.002);
  EXPECT_NEAR(neutral.cos_bearing_exponent, 0.0, 0.015);
}

TEST(MrclamFitDelay, FindsTheCommandLag) {
  const DelayFit f = fit_delay({&robot(0)});
  EXPECT_NEAR(f.delay_s, 0.15, 0.005);
  EXPECT_GT(f.correlation, 0.95);
  EXPECT_GT(f.correlation, f.correlation_at_zero);
  EXPECT_EQ(f.lags_s.size(), 51u);
  EXPECT_EQ(f.correlations.size(), 51u);
}

TEST(MrclamFitDelay, FindsTheCommandLagWithMotionCaptureGlitches) {
  EXPECT_NEAR(fit_delay({&robot(1)}).delay_s, 0.15, 0.005);
  EXPECT_NEAR(fit_delay({&robot(3)}).delay_s, 0.32, 0.005);
  EXPECT_NEAR(fit_delay({&robot(2)}).delay_s, 0.0, 0.005);
}

TEST(MrclamFitSpeed, RecoversScaleAndTurningLoss) {
  const SpeedFit f = fit_speed({&robot(0)}, 0.15);
  EXPECT_NEAR(f.speed_scale, 1.04, 0.005);
  EXPECT_NEAR(f.speed_loss_per_radps, 1.13, 0.015);
  EXPECT_GT(f.samples, 5000u);
}

TEST(MrclamFitSpeed, RecoversScaleAndTurningLossWithMotionCaptureGlitches) {
  const SpeedFit f = fit_speed({&robot(1)}, 0.15);
  EXPECT_NEAR(f.speed_scale, 1.04, 0.005);
  EXPECT_NEAR(f.speed_loss_per_radps, 1.13, 0.015);
  const SpeedFit other = fit_speed({&robot(3)}, 0.32);
  EXPECT_NEAR(other.speed_scale, 0.95, 0.005);
  EXPECT_NEAR(other.speed_loss_per_radps, 0.6, 0.015);
  const SpeedFit neutral = fit_speed({&robot(2)}, 0.0);
  EXPECT_NEAR(neutral.speed_scale, 1.0, 0.005);
  EXPECT_NEAR(neutral.speed_loss_per_radps, 0.0, 0.015);
}

TEST(MrclamFitAll, PoolsRobotsAndUsesTheFittedDelay) {
  // Two robots with the same corrections, one clean and one with outliers.
  const CorrectionFit f = fit_corrections({&robot(0), &robot(1)});
  EXPECT_NEAR(f.range.range_scale, 1.03, 0.002);
  EXPECT_NEAR(f.range.cos_bearing_exponent, 0.85, 0.015);
  EXPECT_NEAR(f.delay.delay_s, 0.15, 0.005);
  EXPECT_NEAR(f.speed.speed_scale, 1.04, 0.005);
  EXPECT_NEAR(f.speed.speed_loss_per_radps, 1.13, 0.015);
  EXPECT_EQ(f.range.samples, fit_range({&robot(0)}).samples + fit_range({&robot(1)}).samples);
}

TEST(MrclamFitAll, NeedsRobotsWithGroundTruth) {
  EXPECT_THROW(fit_corrections({}), std::invalid_argument);
  RobotData no_truth = robot(0);
  no_truth.robot = 4;
  no_truth.groundtruth.clear();
  EXPECT_THROW(fit_corrections({&robot(0), &no_truth}), std::invalid_argument);
  RobotData short_run = synthesise(21, Truth{}, 0.0, 0.5);  // no camera frame, few windows
  EXPECT_THROW(fit_range({&short_run}), std::invalid_argument);
}

}  // namespace
}  // namespace pixyslam::mrclam
