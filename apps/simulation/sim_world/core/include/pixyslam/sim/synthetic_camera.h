#pragma once

// The simulator's camera: renders the landmark poles as a camera at a pose
// sees them (images for the camera backend's tests and robot_sim's video).

#include <cstdint>
#include <random>
#include <vector>

#include <opencv2/core/mat.hpp>

#include "pixyslam/camera/colour_code_detector.h"
#include "pixyslam/pixy/pixy_geometry.h"
#include "pixyslam/slam/types.h"

namespace pixyslam::sim {

// A landmark pole for the synthetic camera: two colour bands, top and bottom
// (signatures 1..7 of the detector's options), at (x, y) in the map frame.
struct SyntheticPole {
  int id = 0;
  double x_m = 0.0;
  double y_m = 0.0;
  int top_signature = 1;
  int bottom_signature = 2;
};

struct SyntheticCameraOptions {
  pixy::CameraModel camera;     // image size, optics, pole height (Eq. 5, 6)
  double pole_width_m = 0.042;  // 80 x 42 mm: 2.1:1 in the Pixy's image, mid the 2.0-2.2 aspect check
  double pixel_noise = 6.0;     // sd of Gaussian noise per channel (0..255)
  bool carpet = true;           // a patterned floor in the lower half (pale tiles, saturated specks)
};

// What the renderer drew of one pole: where, and whether it is wholly in the
// image and not covered by a nearer pole.
struct RenderedPole {
  int id = 0;
  double range_m = 0.0;
  double bearing_rad = 0.0;
  bool in_image = false;   // the whole pole inside the image
  bool occluded = false;   // a nearer pole overlaps it
};

// The camera's view from `pose` (camera at the robot origin looking along x,
// at the poles' mid height): a wall, the floor, and the poles from far to near
// with perspective size from Eq. 5 and column from Eq. 6 (so that a perfect
// detector recovers the range and bearing exactly, up to pixel rounding), each
// band in its signature's hue with shading and noise. `detector` gives the
// hues. Deterministic for a given rng state.
cv::Mat render_camera_image(const slam::Pose2& pose, const std::vector<SyntheticPole>& poles,
                            const SyntheticCameraOptions& options, const camera::DetectorOptions& detector,
                            std::mt19937_64& rng, std::vector<RenderedPole>* drawn = nullptr);

}  // namespace pixyslam::sim
