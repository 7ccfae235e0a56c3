// Camera calibration from photos: poles rendered by the synthetic camera with
// a lens the config does not know (2.95 mm instead of 2.8) are measured by the
// colour-code detector, and fit_camera recovers the focal length; a photo
// without a pole, or an unreadable one, is an error naming it.
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <random>
#include <string>

#include <opencv2/imgcodecs.hpp>

#include <gtest/gtest.h>

#include "pixyslam/calibration/pole_images.h"
#include "pixyslam/sim/synthetic_camera.h"
#include "pixyslam/config/yaml_reader.h"
#include "pixyslam/pixy/pixy_options.h"

namespace pixyslam::calibration {
namespace {

class CalibrationImages : public ::testing::Test {
 protected:
  void SetUp() override {
    char tmpl[] = "/tmp/pixyslam_calibration_images_XXXXXX";
    ASSERT_NE(::mkdtemp(tmpl), nullptr);
    folder_ = tmpl;
    config::YamlReader root = config::YamlReader::from_file(std::string(PIXYSLAM_CONFIG_DIR) + "/pixy_bridge.yaml");
    config::YamlReader pixy = root.child("pixy");
    model_ = pixy::read_pixy_options(pixy).camera;
  }
  void TearDown() override { std::filesystem::remove_all(folder_); }

  std::string folder_;
  pixy::CameraModel model_;
};

TEST_F(CalibrationImages, RecoversTheFocalLengthFromPhotosOfAPole) {
  sim::SyntheticCameraOptions lens;
  lens.camera = model_;
  lens.camera.focal_length_mm = 2.95;  // the true lens
  std::mt19937_64 rng(4);
  std::string list = "image,distance_m,bearing_rad\n";
  int k = 0;
  for (const double d : {0.5, 0.7, 1.0, 1.3, 1.6}) {
    for (const double bearing : {-0.3, 0.2}) {
      const sim::SyntheticPole pole{1, d * std::cos(bearing), d * std::sin(bearing), 1, 2};
      const cv::Mat photo =
          sim::render_camera_image(slam::Pose2::Zero(), {pole}, lens, camera::default_detector_options(), rng);
      const std::string name = "pole" + std::to_string(k++) + ".png";
      ASSERT_TRUE(cv::imwrite(folder_ + "/" + name, photo));
      list += name + "," + std::to_string(d) + "," + std::to_string(bearing) + "\n";
    }
  }
  const auto images = parse_pole_images(list, "photos.csv", folder_);
  ASSERT_EQ(images.size(), 10u);
  const std::vector<PoleSample> samples =
      pole_samples_from_images(images, camera::default_detector_options(), model_, "photos.csv");
  const CameraFit fit = fit_camera(samples, model_);
  std::printf("fitted focal_length_mm %.4f (true 2.95), RMS %.2f px, range RMS %.2f %%, sensor_width_mm %.3f\n",
              fit.focal_length_mm, fit.rms_height_px, 100.0 * fit.rms_range_error, fit.sensor_width_mm);
  EXPECT_NEAR(fit.focal_length_mm, 2.95, 0.05) << "config says " << model_.focal_length_mm;
  EXPECT_LT(fit.rms_range_error, 0.05);
  ASSERT_TRUE(fit.has_sensor_width);
  EXPECT_NEAR(fit.sensor_width_mm, model_.sensor_width_mm, 0.1);
}

TEST_F(CalibrationImages, APhotoWithoutAPoleOrUnreadableIsNamed) {
  const cv::Mat empty(model_.image_height_px, model_.image_width_px, CV_8UC3, cv::Scalar(90, 90, 90));
  ASSERT_TRUE(cv::imwrite(folder_ + "/wall.png", empty));
  const auto images = parse_pole_images("image,distance_m\nwall.png,1.0\n", "photos.csv", folder_);
  try {
    pole_samples_from_images(images, camera::default_detector_options(), model_, "photos.csv");
    FAIL() << "a photo without a pole gave a sample";
  } catch (const config::ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("photos.csv:2: " + folder_ + "/wall.png: no colour code found"),
              std::string::npos)
        << e.what();
  }
  const auto missing = parse_pole_images("image,distance_m\nnone.png,1.0\n", "photos.csv", folder_);
  EXPECT_THROW(pole_samples_from_images(missing, camera::default_detector_options(), model_, "photos.csv"),
               config::ConfigError);
  EXPECT_THROW(parse_pole_images("image,distance\nx.png,1\n", "photos.csv", folder_), config::ConfigError);
  EXPECT_THROW(parse_pole_images("image,distance_m\nx.png,far\n", "photos.csv", folder_), config::ConfigError);
}

}  // namespace
}  // namespace pixyslam::calibration
