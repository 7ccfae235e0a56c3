// The OpenCV camera backend: colour-code detection in images rendered by the
// synthetic camera, alone and driven through the simulated world.
#include <cmath>
#include <random>
#include <utility>

#include <opencv2/imgproc.hpp>

#include <gtest/gtest.h>

#include "pixyslam/camera_eval/camera_eval.h"
#include "pixyslam/camera/colour_code_detector.h"
#include "pixyslam/sim/synthetic_camera.h"
#include "pixyslam/config/yaml_reader.h"
#include "pixyslam/pixy/pixy_options.h"
#include "pixyslam/slam/slam_options_yaml.h"

namespace pixyslam::camera {
namespace {

using sim::SyntheticPole;
using sim::SyntheticCameraOptions;
using sim::render_camera_image;

pixy::PixyOptions shipped_pixy_options() {
  config::YamlReader root = config::YamlReader::from_file(std::string(PIXYSLAM_CONFIG_DIR) + "/pixy_bridge.yaml");
  config::YamlReader pixy = root.child("pixy");
  return pixy::read_pixy_options(pixy);
}

TEST(ColourCodeDetector, FindsOneCodeAtTheRightRangeAndBearing) {
  const pixy::PixyOptions pixy = shipped_pixy_options();
  SyntheticCameraOptions options;
  options.camera = pixy.camera;
  const DetectorOptions detector = default_detector_options();
  std::mt19937_64 rng(5);
  for (const double range : {0.5, 1.0, 1.5}) {
    for (const double bearing : {-0.4, 0.0, 0.25}) {
      // Pole 1 at (range, bearing) from the camera at the origin: tags 1 over 2.
      const SyntheticPole pole{1, range * std::cos(bearing), range * std::sin(bearing), 1, 2};
      const cv::Mat image = render_camera_image(slam::Pose2::Zero(), {pole}, options, detector, rng);
      const std::vector<pixy::PixyBlock> blocks = detect_colour_codes(image, detector);
      ASSERT_EQ(blocks.size(), 1u) << range << " m, " << bearing << " rad";
      EXPECT_EQ(blocks[0].signature, 012);  // PixyMon's "12": landmark 1 in config/pixy_bridge.yaml
      EXPECT_TRUE(blocks[0].colour_code);
      EXPECT_NEAR(pixy::range_m(pixy.camera, blocks[0].height), range, 0.05 * range);
      EXPECT_NEAR(pixy::bearing_rad(pixy.camera, blocks[0].x), bearing, 0.02);
      EXPECT_EQ(pixy.signatures.landmark_of(blocks[0]), std::optional<int>(1));
    }
  }
}

TEST(ColourCodeDetector, TagOrderMakesTheCodeAndTheCarpetMakesNone) {
  const DetectorOptions detector = default_detector_options();
  SyntheticCameraOptions options;
  options.camera.sensor_width_mm = 4.297;
  std::mt19937_64 rng(9);
  const cv::Mat swapped =
      render_camera_image(slam::Pose2::Zero(), {SyntheticPole{1, 1.0, 0.0, 2, 1}}, options, detector, rng);
  const auto blocks = detect_colour_codes(swapped, detector);
  ASSERT_EQ(blocks.size(), 1u);
  EXPECT_EQ(blocks[0].signature, 021);
  // The floor alone, many times: pale tiles, saturated specks and patches, never a code.
  for (int k = 0; k < 50; ++k) {
    EXPECT_TRUE(detect_colour_codes(render_camera_image(slam::Pose2::Zero(), {}, options, detector, rng), detector).empty());
  }
  // Two patches of pole colours stacked on the floor (the paper's carpet trap):
  // a code without the horizon check, nothing with it.
  cv::Mat floor(200, 320, CV_8UC3, cv::Scalar(150, 155, 160));
  cv::Mat hsv(1, 1, CV_8UC3), bgr;
  for (const auto& [hue, top] : {std::pair{0, 150}, std::pair{30, 160}}) {
    hsv.at<cv::Vec3b>(0, 0) = cv::Vec3b(static_cast<uchar>(hue), 220, 210);
    cv::cvtColor(hsv, bgr, cv::COLOR_HSV2BGR);
    const cv::Vec3b c = bgr.at<cv::Vec3b>(0, 0);
    cv::rectangle(floor, cv::Rect(100, top, 5, 10), cv::Scalar(c[0], c[1], c[2]), cv::FILLED);
  }
  DetectorOptions no_horizon = detector;
  no_horizon.horizon_row_fraction = -1.0;
  ASSERT_EQ(detect_colour_codes(floor, no_horizon).size(), 1u);
  EXPECT_EQ(detect_colour_codes(floor, no_horizon)[0].signature, 012);
  EXPECT_TRUE(detect_colour_codes(floor, detector).empty());
  EXPECT_THROW(detect_colour_codes(cv::Mat(), detector), std::invalid_argument);
  EXPECT_THROW(detect_colour_codes(cv::Mat(10, 10, CV_8UC1), detector), std::invalid_argument);
}

// The acceptance numbers on the simulated world (150 s, 1500 frames):
// detected in at least 95 % of the frames a pole is wholly in view, unoccluded
// and within 2 m; range error under 5 % at 1 m; no wrong id, in the detections
// or in the map FastSLAM 2.0 builds from them.
TEST(CameraEndToEnd, SyntheticWorldDetectionRateRangeErrorAndMapIds) {
  const pixy::PixyOptions pixy = shipped_pixy_options();
  config::YamlReader sim_root = config::YamlReader::from_file(std::string(PIXYSLAM_CONFIG_DIR) + "/slam_sim.yaml");
  config::YamlReader world_yaml = sim_root.child("world");
  config::YamlReader filter_yaml = sim_root.child("filter");
  camera_eval::EvalOptions options;
  options.world = sim::read_world_options(world_yaml);
  options.filter = slam::read_filter_options(filter_yaml);
  pixy::CameraModel model = pixy.camera;
  model.aspect_tolerance_px = 1;
  const camera_eval::EvalResult r = camera_eval::evaluate(options, pixy.signatures, model);
  EXPECT_GT(r.frames, 1000);
  EXPECT_EQ(r.poles.size(), 20u);
  EXPECT_GE(r.detection_rate(), 0.95);
  for (const auto& [id, s] : r.poles) EXPECT_GE(s.detected, s.in_view * 9 / 10) << "landmark " << id;
  EXPECT_GT(r.range_samples_1m, 50);
  EXPECT_LT(r.range_error_1m, 0.05);
  EXPECT_EQ(r.wrong_ids, 0);
  EXPECT_EQ(r.map_landmarks, 20);
  EXPECT_EQ(r.map_wrong_ids, 0);
  EXPECT_LT(r.pose_ate_m, 0.2);
  RecordProperty("detection_rate", std::to_string(r.detection_rate()));
  RecordProperty("range_error_1m", std::to_string(r.range_error_1m));
}

}  // namespace
}  // namespace pixyslam::camera
