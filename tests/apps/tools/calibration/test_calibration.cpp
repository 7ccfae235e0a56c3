// Camera and odometry calibration (apps/tools/calibration): the fits recover known
// parameters from measurements made with them, and bad input names its place.
#include <cmath>
#include <random>
#include <string>

#include <gtest/gtest.h>

#include "pixyslam/calibration/calibration.h"
#include "pixyslam/config/yaml_reader.h"
#include "pixyslam/encoder/arduino_line_parser.h"

namespace pixyslam::calibration {
namespace {

// Poles at 0.3..3 m, blocks measured as a Pixy would (whole pixels), with a
// camera whose focal length and sensor width differ from the nominal ones.
TEST(CameraCalibration, RecoversFocalLengthAndSensorWidthFromRoundedBlocks) {
  pixy::CameraModel truth;
  truth.focal_length_mm = 2.95;
  truth.sensor_width_mm = 4.1;
  std::vector<PoleSample> samples;
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> bearing(-0.5, 0.5);
  for (double d = 0.3; d <= 3.0; d += 0.15) {
    PoleSample s;
    s.distance_m = d;
    // Eq. 5 solved for the block height, rounded to a whole pixel.
    s.height_px = std::round(truth.focal_length_mm * truth.landmark_height_m / truth.sensor_height_mm *
                             truth.image_height_px / d);
    s.has_bearing = true;
    s.bearing_rad = bearing(rng);
    // Eq. 6 solved for the column, rounded.
    s.x_px = std::round(0.5 * truth.image_width_px - std::tan(s.bearing_rad) * truth.focal_length_mm *
                                                         truth.image_width_px / truth.sensor_width_mm);
    samples.push_back(s);
  }
  pixy::CameraModel nominal;  // f 2.8, S_w 3.888
  const CameraFit fit = fit_camera(samples, nominal);
  EXPECT_NEAR(fit.focal_length_mm, truth.focal_length_mm, 0.01 * truth.focal_length_mm);
  ASSERT_TRUE(fit.has_sensor_width);
  EXPECT_NEAR(fit.sensor_width_mm, truth.sensor_width_mm, 0.01 * truth.sensor_width_mm);
  EXPECT_LT(fit.rms_height_px, 0.5);          // only the rounding is left
  EXPECT_LT(fit.rms_range_error, 0.03);
  EXPECT_LT(fit.rms_bearing_rad, 0.01);
  ASSERT_EQ(fit.range_error.size(), samples.size());
  // With the nominal focal length the ranges would be 5 % short.
  EXPECT_NEAR(pixy::range_m(nominal, samples[0].height_px) / samples[0].distance_m, 2.8 / 2.95, 0.03);
}

TEST(CameraCalibration, BadSampleFilesNameTheLine) {
  const std::string good = "# poles\ndistance_m,height_px\n0.5,60\n1.0,30\n";
  EXPECT_EQ(parse_pole_samples(good, "p.csv").size(), 2u);
  EXPECT_EQ(parse_pole_samples(good, "p.csv")[1].line, 4);
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"distance,height\n1,2\n", "p.csv:1: the header"},
      {"distance_m,height_px\n0.5,sixty\n", "p.csv:2: height_px 'sixty' is not a number"},
      {"distance_m,height_px\n0.5\n", "p.csv:2: 2 fields expected, got 1"},
      {"distance_m,height_px\n-1,30\n", "p.csv:2: distance_m must be in (0, 100]"},
      {"distance_m,height_px,x_px,bearing_rad\n1,30,160,2\n", "p.csv:2: bearing_rad"},
      {"distance_m,height_px\n1,nan\n", "is not a number"},
      {"# nothing\n", "p.csv: no header line"},
  };
  for (const auto& [text, expected] : cases) {
    try {
      parse_pole_samples(text, "p.csv");
      ADD_FAILURE() << "accepted: " << text;
    } catch (const config::ConfigError& e) {
      EXPECT_NE(std::string(e.what()).find(expected), std::string::npos) << e.what();
    }
  }
  EXPECT_THROW(fit_camera(parse_pole_samples("distance_m,height_px\n1,30\n", "p.csv"), pixy::CameraModel{}),
               std::invalid_argument);
}

// The Arduino's lines for wheel counters moving from `start` by (dl, dr).
std::string recording(std::int32_t start, std::int32_t dl, std::int32_t dr, int steps, bool reset_inside = false) {
  const encoder::EncoderReset reset{"uno-1", 1320};
  std::string text = "garbage before the first line\r\n" + encoder::format_line(reset);
  for (int i = 0; i <= steps; ++i) {
    encoder::EncoderSample s;
    s.seq = static_cast<std::uint32_t>(i);
    s.arduino_time_us = static_cast<std::uint32_t>(20000 * i);
    // Counters wrap: start near INT32_MAX to check the modular difference.
    s.left_ticks = static_cast<std::int32_t>(static_cast<std::uint32_t>(start) +
                                             static_cast<std::uint32_t>(static_cast<std::int64_t>(dl) * i / steps));
    s.right_ticks = static_cast<std::int32_t>(static_cast<std::uint32_t>(start) +
                                              static_cast<std::uint32_t>(static_cast<std::int64_t>(dr) * i / steps));
    text += encoder::format_line(s);
    if (reset_inside && i == steps / 2) text += encoder::format_line(reset);
    if (i == 3) text += "$ENC,3,bad*00\r\n";
  }
  return text;
}

TEST(OdometryCalibration, NetTicksAcrossCounterWrapAndBadLines) {
  const TickCount t = net_ticks(recording(2147483000, 5000, 4990, 50), "straight.txt");
  EXPECT_EQ(t.left, 5000);
  EXPECT_EQ(t.right, 4990);
  EXPECT_EQ(t.samples, 51u);
  EXPECT_EQ(t.rejected_lines, 1u);
  EXPECT_THROW(net_ticks(recording(0, 100, 100, 10, true), "reset.txt"), config::ConfigError);
  EXPECT_THROW(net_ticks("$RST nothing useful\n", "empty.txt"), config::ConfigError);
}

TEST(OdometryCalibration, RecoversWheelRadiusAndBaseFromRunsMadeWithThem) {
  const double r = 0.0331, b = 0.1412;
  const int n = 1320;
  const double metres_per_tick = 2.0 * M_PI * r / n;
  auto straight = [&](double d) {
    TickCount t;
    t.left = std::llround(d / metres_per_tick);
    t.right = t.left;
    return OdometryRun{t, d, "s"};
  };
  auto turn = [&](double angle) {  // in place: the wheels move +-angle b / 2
    TickCount t;
    t.right = std::llround(angle * b / 2.0 / metres_per_tick);
    t.left = -t.right;
    return OdometryRun{t, angle, "t"};
  };
  const OdometryFit fit = fit_odometry({straight(1.0), straight(2.5)}, {turn(2 * M_PI), turn(-4 * M_PI)}, n, 1, 1);
  EXPECT_NEAR(fit.wheel_radius_m, r, 1e-5);
  EXPECT_NEAR(fit.wheel_base_m, b, 1e-4);
  for (double e : fit.straight_error_m) EXPECT_LT(std::abs(e), 0.002);
  for (double e : fit.turn_error_rad) EXPECT_LT(std::abs(e), 0.002);
  for (double e : fit.straight_rotation_rad) EXPECT_LT(std::abs(e), 1e-9);
  // A left wheel wired backwards (sign not set) shows as no forward motion.
  OdometryRun backwards = straight(1.0);
  backwards.ticks.left = -backwards.ticks.left;
  EXPECT_THROW(fit_odometry({backwards}, {turn(1.0)}, n, 1, 1), std::invalid_argument);
  EXPECT_THROW(fit_odometry({}, {turn(1.0)}, n, 1, 1), std::invalid_argument);
}

TEST(CalibrationOutput, ReplacesOneValueInItsSectionAndKeepsTheComment) {
  const std::string yaml =
      "node:\n  focal_length_mm: 9  # not this one\npixy:\n  focal_length_mm: 2.8        # f\n"
      "  sensor_height_mm: 2.43\n";
  const std::string out = replace_yaml_value(yaml, "pixy", "focal_length_mm", "2.9512");
  EXPECT_EQ(out,
            "node:\n  focal_length_mm: 9  # not this one\npixy:\n  focal_length_mm: 2.9512     # f\n"
            "  sensor_height_mm: 2.43\n");
  EXPECT_EQ(replace_yaml_value(yaml, "pixy", "sensor_height_mm", "2.5"),
            "node:\n  focal_length_mm: 9  # not this one\npixy:\n  focal_length_mm: 2.8        # f\n"
            "  sensor_height_mm: 2.5\n");
  EXPECT_THROW(replace_yaml_value(yaml, "pixy", "wheel_base_m", "1"), std::invalid_argument);
}

}  // namespace
}  // namespace pixyslam::calibration
