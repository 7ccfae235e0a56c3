#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include <opencv2/core/mat.hpp>

#include "pixyslam/pixy/pixy_block_parser.h"

namespace pixyslam::camera {

// A colour signature (Pixy's 1..7) as an HSV box in OpenCV's scales (H 0..179,
// S and V 0..255). h_min > h_max wraps through red (e.g. 170..10).
struct HsvRange {
  int h_min = 0, h_max = 0;
  int s_min = 0, s_max = 255;
  int v_min = 0, v_max = 255;
  bool contains(int h, int s, int v) const;
};

struct DetectorOptions {
  // signatures[k] is signature k + 1; an empty range (s_min > s_max) is unused.
  std::array<HsvRange, 7> signatures{};
  int min_blob_area_px = 6;     // smaller blobs of a colour are noise
  int max_gap_px = 2;           // most rows between the two bands of a code
  double min_overlap = 0.5;     // horizontal overlap of the bands, fraction of the narrower
  // Poles stand on the floor with their middle at the camera's height, so a
  // code's centre lies on the horizon row (this fraction of the image height)
  // within max_horizon_offset of its height (+ 2 px): codes on the floor
  // (the paper's carpet) are dropped. A negative fraction turns the check off.
  double horizon_row_fraction = 0.5;
  double max_horizon_offset = 0.25;
};

// Six well separated hues (red, yellow, green, cyan, blue, magenta) for
// signatures 1..6, saturation and value at least 100: the defaults of the
// synthetic camera and a starting point for a real one (tune per site).
DetectorOptions default_detector_options();

// Pixy-style colour-code detection in a BGR image: per signature an HSV
// threshold, a 3x3 opening, connected components (blobs of at least
// min_blob_area_px); then every pair of blobs of different signatures stacked
// vertically (bands of one pole: horizontal overlap >= min_overlap, at most
// max_gap_px rows apart) becomes one colour-code block: signature = the tags
// from top to bottom in octal (top 1, bottom 2 -> 012 = 10, PixyMon's "12"),
// the union box, angle 90 (an upright code). A blob pairs at most once (the
// closest partner), and off-horizon pairs are dropped. Blocks come sorted by x. Throws std::invalid_argument for
// an empty image or one not CV_8UC3.
std::vector<pixy::PixyBlock> detect_colour_codes(const cv::Mat& bgr, const DetectorOptions& options);

}  // namespace pixyslam::camera
