#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <opencv2/core/mat.hpp>

namespace pixyslam::robot_sim {

// The synthetic camera's output: a FIFO at `path` carrying a YUV4MPEG2 stream
// (camera::y4m_header / encode_y4m_frame), which the pixy bridge's camera
// backend (or `ffplay PATH`) reads. Never blocks the simulation: with no
// reader a frame is dropped; a frame that does not fit in the pipe's free
// space is dropped whole; a reader that comes (back) gets a new stream header
// first. Removes the FIFO when destroyed.
class CameraVideoFifo {
 public:
  struct Counters {
    std::uint64_t frames_written = 0;
    std::uint64_t dropped_no_reader = 0;
    std::uint64_t dropped_pipe_full = 0;
  };

  CameraVideoFifo(std::string path, int width, int height, int fps);
  ~CameraVideoFifo();
  CameraVideoFifo(const CameraVideoFifo&) = delete;
  CameraVideoFifo& operator=(const CameraVideoFifo&) = delete;

  void write_frame(const cv::Mat& bgr);
  const Counters& counters() const { return counters_; }
  const std::string& path() const { return path_; }

 private:
  bool try_open();
  bool write_all(const std::uint8_t* data, std::size_t size);

  std::string path_;
  std::string header_;
  int fd_ = -1;
  int pipe_bytes_ = 0;
  Counters counters_;
};

}  // namespace pixyslam::robot_sim
