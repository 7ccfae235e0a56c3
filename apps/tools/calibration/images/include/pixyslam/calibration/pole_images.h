#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "pixyslam/calibration/calibration.h"
#include "pixyslam/camera/colour_code_detector.h"
#include "pixyslam/pixy/pixy_geometry.h"

namespace pixyslam::calibration {

// One photo of a pole at a measured place.
struct PoleImage {
  std::string path;   // resolved against the list's folder
  double distance_m = 0.0;
  bool has_bearing = false;
  double bearing_rad = 0.0;
  int line = 0;
};

// CSV with the header image,distance_m[,bearing_rad]; relative image paths are
// taken from `folder`. config::ConfigError naming origin:line on a bad row.
std::vector<PoleImage> parse_pole_images(std::string_view text, const std::string& origin, const std::string& folder);

// The pole's colour-code block in each image (detect_colour_codes with
// `detector`; the largest when several; images of another size than the
// camera model's are resized to it, as the bridge's camera backend does):
// its height and column become a PoleSample for fit_camera(). Throws
// config::ConfigError naming the image (and list line) when it cannot be read
// or holds no colour code.
std::vector<PoleSample> pole_samples_from_images(const std::vector<PoleImage>& images,
                                                 const camera::DetectorOptions& detector,
                                                 const pixy::CameraModel& camera, const std::string& origin);

}  // namespace pixyslam::calibration
