#pragma once

#include <chrono>
#include <cstdint>
#include <deque>
#include <memory>
#include <string>
#include <vector>

#include "pixyslam/bridge/byte_source.h"
#include "pixyslam/bridge/device_reader.h"
#include "pixyslam/camera/colour_code_detector.h"
#include "pixyslam/camera/y4m_stream.h"
#include "pixyslam/config/yaml_reader.h"
#include "pixyslam/parameters/parameters.h"

namespace cv {
class VideoCapture;
}

namespace pixyslam::camera {

// `camera:` of the pixy bridge's config: a camera instead of the Pixy.
struct CameraSourceOptions {
  // /dev/videoN: a V4L2 camera (OpenCV videoio); a FIFO or a *.y4m file: a
  // YUV4MPEG2 stream (robot_sim's synthetic camera, or ffmpeg ... -f yuv4mpegpipe);
  // anything else: a video file OpenCV's videoio reads.
  std::string input;
  double file_fps = 10.0;  // frames per second read from a file (a FIFO or camera sets its own pace)
  int image_width_px = 320;   // frames of another size are resized to this (the camera model's I_w x I_h)
  int image_height_px = 200;
  DetectorOptions detector = default_detector_options();
};

// The scalar keys of `camera:` (the signatures' HSV ranges apart).
const parameters::Table<CameraSourceOptions>& camera_source_parameters();
void validate(const CameraSourceOptions& options);

// Reads `camera:` (input required; `signatures:` maps 1..7 to {h: [min, max],
// s: [min, max], v: [min, max]}, OpenCV scales; absent ones keep the defaults)
// and calls finish(). The image size comes from the camera model.
CameraSourceOptions read_camera_source_options(config::YamlReader& camera, int image_width_px, int image_height_px);
std::string to_yaml(const CameraSourceOptions& options);

// A software Pixy: reads camera frames, detects colour codes in each
// (detect_colour_codes) and delivers them as the Pixy's UART block stream
// (pixy::encode_frame), so the pixy bridge runs its parser, checks and
// geometry unchanged. A frame's bytes are delivered right after it was read.
// Files end quietly (timeouts, logged once); a FIFO whose writer left or a
// camera that stops delivering reports a hang-up, and the bridge reopens it.
// Malformed y4m bytes are skipped, counted and logged with their offset.
class CameraByteSource final : public bridge::ByteSource {
 public:
  CameraByteSource(CameraSourceOptions options, bridge::LogFunction log);
  ~CameraByteSource() override;

  void open() override;
  void close() override;
  bool is_open() const override { return open_; }
  serial::ReadResult read_some(std::uint8_t* buffer, std::size_t max, std::chrono::milliseconds timeout) override;
  std::string name() const override { return "camera " + options_.input; }

  std::uint64_t frames() const { return frames_; }
  const Y4mCounters& y4m_counters() const { return y4m_.counters(); }

 private:
  enum class Kind { kY4m, kVideo };
  // Runs detection on a frame and queues its Pixy bytes.
  void deliver(const cv::Mat& frame);
  serial::ReadResult next_y4m(std::chrono::milliseconds timeout);
  serial::ReadResult next_video(std::chrono::milliseconds timeout);
  serial::ReadResult end_of_file();
  // A file's next frame is due (waits up to `timeout` for it); always true for a live input.
  bool file_frame_due(std::chrono::milliseconds timeout);

  CameraSourceOptions options_;
  bridge::LogFunction log_;
  Kind kind_ = Kind::kY4m;
  bool open_ = false;
  bool is_file_ = false;     // a regular file: paced at file_fps, ends quietly
  bool ended_ = false;
  int fd_ = -1;
  std::unique_ptr<cv::VideoCapture> capture_;
  Y4mParser y4m_;
  std::deque<cv::Mat> y4m_frames_;
  std::vector<std::uint8_t> pending_;
  std::chrono::steady_clock::time_point next_due_{};
  std::uint64_t frames_ = 0;
  bool size_logged_ = false;
};

}  // namespace pixyslam::camera
