#include "pixyslam/camera/colour_code_detector.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <opencv2/imgproc.hpp>

namespace pixyslam::camera {
namespace {

struct Blob {
  int signature = 0;
  cv::Rect box;
  bool used = false;
};

}  // namespace

bool HsvRange::contains(int h, int s, int v) const {
  const bool hue = h_min <= h_max ? (h >= h_min && h <= h_max) : (h >= h_min || h <= h_max);
  return hue && s >= s_min && s <= s_max && v >= v_min && v <= v_max;
}

DetectorOptions default_detector_options() {
  DetectorOptions o;
  const int hues[6] = {0, 30, 60, 90, 120, 150};
  for (int k = 0; k < 6; ++k) {
    o.signatures[k] = {(hues[k] + 180 - 8) % 180, (hues[k] + 8) % 180, 100, 255, 100, 255};
  }
  o.signatures[6] = {0, 0, 1, 0, 0, 0};  // signature 7 unused (s_min > s_max)
  return o;
}

std::vector<pixy::PixyBlock> detect_colour_codes(const cv::Mat& bgr, const DetectorOptions& options) {
  if (bgr.empty() || bgr.type() != CV_8UC3) throw std::invalid_argument("detect_colour_codes: want a CV_8UC3 image");
  cv::Mat hsv;
  cv::cvtColor(bgr, hsv, cv::COLOR_BGR2HSV);
  const cv::Mat kernel = cv::getStructuringElement(cv::MORPH_RECT, {3, 3});
  std::vector<Blob> blobs;
  for (int k = 0; k < 7; ++k) {
    const HsvRange& r = options.signatures[static_cast<std::size_t>(k)];
    if (r.s_min > r.s_max) continue;
    cv::Mat mask;
    if (r.h_min <= r.h_max) {
      cv::inRange(hsv, cv::Scalar(r.h_min, r.s_min, r.v_min), cv::Scalar(r.h_max, r.s_max, r.v_max), mask);
    } else {
      cv::Mat low, high;
      cv::inRange(hsv, cv::Scalar(r.h_min, r.s_min, r.v_min), cv::Scalar(179, r.s_max, r.v_max), low);
      cv::inRange(hsv, cv::Scalar(0, r.s_min, r.v_min), cv::Scalar(r.h_max, r.s_max, r.v_max), high);
      mask = low | high;
    }
    cv::morphologyEx(mask, mask, cv::MORPH_OPEN, kernel);
    cv::Mat labels, stats, centroids;
    const int n = cv::connectedComponentsWithStats(mask, labels, stats, centroids, 8, CV_32S);
    for (int i = 1; i < n; ++i) {
      if (stats.at<int>(i, cv::CC_STAT_AREA) < options.min_blob_area_px) continue;
      blobs.push_back({k + 1, cv::Rect(stats.at<int>(i, cv::CC_STAT_LEFT), stats.at<int>(i, cv::CC_STAT_TOP),
                                       stats.at<int>(i, cv::CC_STAT_WIDTH), stats.at<int>(i, cv::CC_STAT_HEIGHT))});
    }
  }
  // Pair each blob with the closest blob of another signature right below it.
  std::sort(blobs.begin(), blobs.end(), [](const Blob& a, const Blob& b) { return a.box.y < b.box.y; });
  std::vector<pixy::PixyBlock> blocks;
  for (Blob& top : blobs) {
    if (top.used) continue;
    Blob* best = nullptr;
    int best_gap = options.max_gap_px + 1;
    for (Blob& bottom : blobs) {
      if (&bottom == &top || bottom.used || bottom.signature == top.signature) continue;
      const int gap = bottom.box.y - (top.box.y + top.box.height);
      if (gap < -1 || gap > options.max_gap_px) continue;
      const int overlap = std::min(top.box.x + top.box.width, bottom.box.x + bottom.box.width) -
                          std::max(top.box.x, bottom.box.x);
      if (overlap < options.min_overlap * std::min(top.box.width, bottom.box.width)) continue;
      if (gap < best_gap) {
        best_gap = gap;
        best = &bottom;
      }
    }
    if (!best) continue;
    const cv::Rect u = top.box | best->box;
    if (options.horizon_row_fraction >= 0.0) {
      const double offset = std::abs(u.y + 0.5 * u.height - options.horizon_row_fraction * bgr.rows);
      if (offset > options.max_horizon_offset * u.height + 2.0) continue;
    }
    top.used = best->used = true;
    pixy::PixyBlock b;
    b.signature = static_cast<std::uint16_t>(top.signature * 8 + best->signature);
    b.x = static_cast<std::uint16_t>(u.x + u.width / 2);
    b.y = static_cast<std::uint16_t>(u.y + u.height / 2);
    b.width = static_cast<std::uint16_t>(u.width);
    b.height = static_cast<std::uint16_t>(u.height);
    b.angle_deg = 90;
    b.colour_code = true;
    blocks.push_back(b);
  }
  std::sort(blocks.begin(), blocks.end(), [](const pixy::PixyBlock& a, const pixy::PixyBlock& b) { return a.x < b.x; });
  return blocks;
}

}  // namespace pixyslam::camera
