#pragma once

#include <cstddef>
#include <string>

#include <opencv2/core/mat.hpp>
#include <opencv2/videoio.hpp>

namespace pixyslam::map_view {

// Writes `image` as PNG to `path` through a temporary file in the same folder
// and a rename, so a reader (e.g. an image viewer polling map_latest.png)
// never sees half a file. Throws std::runtime_error naming the path.
void write_png(const std::string& path, const cv::Mat& image);

// True when `out` names a video file (".avi", any case).
bool is_video_path(const std::string& out);

// Where a video's frames go: an MJPG .avi (cv::VideoWriter) when `out` ends in
// .avi, otherwise the folder `out` (created) with frame_00000.png,
// frame_00001.png, ... Every frame must have `size` and be CV_8UC3.
// Thread-compatible.
class FrameSink {
 public:
  // Throws InputError naming `out` when it cannot be created/opened.
  FrameSink(const std::string& out, double fps, cv::Size size);
  void write(const cv::Mat& frame);
  // Finishes the video file (also done by the destructor).
  void close();
  std::size_t frames() const { return frames_; }
  bool is_video() const { return video_; }

 private:
  std::string out_;
  cv::Size size_;
  bool video_ = false;
  cv::VideoWriter writer_;
  std::size_t frames_ = 0;
};

}  // namespace pixyslam::map_view
