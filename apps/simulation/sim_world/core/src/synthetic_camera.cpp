#include "pixyslam/sim/synthetic_camera.h"

#include <algorithm>
#include <cmath>

#include <opencv2/imgproc.hpp>

namespace pixyslam::sim {
namespace {

// The middle of a signature's HSV box as a BGR colour, value scaled by `shade`.
cv::Scalar signature_colour(const camera::HsvRange& r, double shade) {
  const int h = r.h_min <= r.h_max ? (r.h_min + r.h_max) / 2 : ((r.h_min + r.h_max + 180) / 2) % 180;
  const int s = std::clamp((std::max(r.s_min, 100) + r.s_max) / 2 + 20, 0, 255);
  const int v = std::clamp(static_cast<int>(210 * shade), 0, 255);
  cv::Mat hsv(1, 1, CV_8UC3, cv::Scalar(h, s, v)), bgr;
  cv::cvtColor(hsv, bgr, cv::COLOR_HSV2BGR);
  const cv::Vec3b c = bgr.at<cv::Vec3b>(0, 0);
  return cv::Scalar(c[0], c[1], c[2]);
}

}  // namespace

cv::Mat render_camera_image(const slam::Pose2& pose, const std::vector<SyntheticPole>& poles,
                            const SyntheticCameraOptions& options, const camera::DetectorOptions& detector,
                            std::mt19937_64& rng, std::vector<RenderedPole>* drawn) {
  const pixy::CameraModel& c = options.camera;
  const int w = c.image_width_px, h = c.image_height_px;
  cv::Mat image(h, w, CV_8UC3, cv::Scalar(150, 155, 160));  // a pale wall
  std::uniform_int_distribution<int> byte(0, 255);
  if (options.carpet) {
    // Pale tiles, and small saturated specks of any hue (the paper's carpet).
    const int tile = 8;
    for (int y = h / 2; y < h; y += tile) {
      for (int x = 0; x < w; x += tile) {
        cv::Mat hsv(1, 1, CV_8UC3, cv::Scalar(byte(rng) % 180, 20 + byte(rng) % 60, 90 + byte(rng) % 100)), bgr;
        cv::cvtColor(hsv, bgr, cv::COLOR_HSV2BGR);
        const cv::Vec3b t = bgr.at<cv::Vec3b>(0, 0);
        cv::rectangle(image, cv::Rect(x, y, tile, tile), cv::Scalar(t[0], t[1], t[2]), cv::FILLED);
      }
    }
    // Specks (removed by the detector's opening) and a few larger patches of
    // pole colours (blobs of their own; a pair stacked by chance is a false code).
    for (int k = 0; k < 44; ++k) {
      const camera::HsvRange& r = detector.signatures[static_cast<std::size_t>(byte(rng) % 6)];
      const int side = k < 40 ? 2 : 5;
      cv::rectangle(image, cv::Rect(byte(rng) * w / 256, h / 2 + byte(rng) * (h / 2) / 256, side, side),
                    signature_colour(r, 1.0), cv::FILLED);
    }
  }
  struct Projected {
    const SyntheticPole* pole;
    RenderedPole info;
    cv::Rect box;
  };
  std::vector<Projected> visible;
  const double cos_t = std::cos(pose.z()), sin_t = std::sin(pose.z());
  for (const SyntheticPole& p : poles) {
    const double dx = p.x_m - pose.x(), dy = p.y_m - pose.y();
    const double fwd = cos_t * dx + sin_t * dy, left = -sin_t * dx + cos_t * dy;
    if (fwd <= 0.05) continue;  // behind the camera
    Projected q{&p, {}, {}};
    q.info.id = p.id;
    q.info.range_m = std::hypot(fwd, left);
    q.info.bearing_rad = std::atan2(left, fwd);
    // Eq. 6 solved for the column, Eq. 5 for the height; width by the same horizontal scale.
    const double cx = pixy::block_x_px(c, q.info.bearing_rad);
    const double height = pixy::block_height_px(c, q.info.range_m);
    const double width = options.pole_width_m / q.info.range_m * pixy::px_per_tan(c);
    const int top = static_cast<int>(std::lround(0.5 * h - 0.5 * height));
    const int bottom = static_cast<int>(std::lround(0.5 * h + 0.5 * height));
    const int x0 = static_cast<int>(std::lround(cx - 0.5 * width));
    const int x1 = static_cast<int>(std::lround(cx + 0.5 * width));
    q.box = cv::Rect(x0, top, std::max(1, x1 - x0), std::max(1, bottom - top));
    q.info.in_image = x0 >= 0 && x1 <= w && top >= 0 && bottom <= h;
    visible.push_back(q);
  }
  // Far to near, so that nearer poles cover farther ones.
  std::sort(visible.begin(), visible.end(),
            [](const Projected& a, const Projected& b) { return a.info.range_m > b.info.range_m; });
  std::uniform_real_distribution<double> shade(0.8, 1.1);
  for (std::size_t i = 0; i < visible.size(); ++i) {
    for (std::size_t j = i + 1; j < visible.size(); ++j) {
      if ((visible[i].box & visible[j].box).area() > 0) visible[i].info.occluded = true;
    }
    const Projected& q = visible[i];
    const int mid = q.box.y + q.box.height / 2;
    const double s = shade(rng);
    cv::rectangle(image, cv::Rect(q.box.x, q.box.y, q.box.width, mid - q.box.y),
                  signature_colour(detector.signatures[static_cast<std::size_t>(q.pole->top_signature - 1)], s),
                  cv::FILLED);
    cv::rectangle(image, cv::Rect(q.box.x, mid, q.box.width, q.box.y + q.box.height - mid),
                  signature_colour(detector.signatures[static_cast<std::size_t>(q.pole->bottom_signature - 1)], s),
                  cv::FILLED);
  }
  if (options.pixel_noise > 0.0) {
    cv::Mat noise(image.size(), CV_16SC3);
    cv::randn(noise, 0.0, options.pixel_noise);
    cv::Mat with_noise;
    image.convertTo(with_noise, CV_16SC3);
    with_noise += noise;
    with_noise.convertTo(image, CV_8UC3);
  }
  if (drawn) {
    drawn->clear();
    for (const Projected& q : visible) drawn->push_back(q.info);
  }
  return image;
}

}  // namespace pixyslam::sim
