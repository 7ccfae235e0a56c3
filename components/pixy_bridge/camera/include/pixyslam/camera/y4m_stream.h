#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include <opencv2/core/mat.hpp>

namespace pixyslam::camera {

// YUV4MPEG2 ("y4m"), the raw video stream format of mjpegtools and FFmpeg
// (`ffmpeg -f v4l2 -i /dev/video0 -pix_fmt yuv444p -f yuv4mpegpipe -`, `ffplay x.y4m`):
//   "YUV4MPEG2 W<width> H<height> [F<n>:<d>] [C<colourspace>] [other tags]\n"
//   then per frame "FRAME[ tags]\n" and the planes Y, Cb, Cr (or Y alone for Cmono).
// Colour spaces read: 444, 420, 420jpeg, 420paldv, 420mpeg2 (chroma (w+1)/2 x (h+1)/2),
// mono; default 420jpeg. Colour is taken as full-range BT.601 YCbCr (OpenCV's YCrCb).

// The stream header for frames of width x height at fps_num/fps_den, C444.
std::string y4m_header(int width, int height, int fps_num, int fps_den);
// One frame ("FRAME\n" + Y, Cb, Cr planes, 4:4:4) of a CV_8UC3 BGR image.
std::vector<std::uint8_t> encode_y4m_frame(const cv::Mat& bgr);

struct Y4mCounters {
  std::uint64_t bytes_in = 0;
  std::uint64_t headers = 0;        // stream headers read (a writer that reopens sends a new one)
  std::uint64_t frames = 0;         // frames delivered
  std::uint64_t bad_headers = 0;    // stream headers rejected (size, colour space, syntax)
  std::uint64_t bytes_skipped = 0;  // bytes that were part of no header or frame
};

// Incremental parser: bytes in chunks of any size, split anywhere; frames out as
// BGR images. Where a frame marker is expected and something else comes, bytes
// are skipped (counted) up to the next "FRAME" or "YUV4MPEG2"; a rejected header
// skips until the next header. `on_error` gets a message naming the byte offset
// in the stream for every rejected header and every start of skipping. Sizes up
// to 4096 x 4096. Thread-compatible.
class Y4mParser {
 public:
  using FrameCallback = std::function<void(cv::Mat&&)>;
  using ErrorCallback = std::function<void(const std::string&)>;

  explicit Y4mParser(ErrorCallback on_error = {}) : on_error_(std::move(on_error)) {}
  void feed(const std::uint8_t* data, std::size_t size, const FrameCallback& on_frame);
  // Forgets any partial header or frame (a new stream starts, e.g. after a reopen).
  void reset();
  const Y4mCounters& counters() const { return counters_; }

 private:
  enum class State { kHeader, kFrameMarker, kPlanes };
  bool parse_header(const std::string& line);
  void skip(std::size_t n, const char* why);
  void error(const std::string& message);

  ErrorCallback on_error_;
  std::vector<std::uint8_t> buffer_;
  State state_ = State::kHeader;
  int width_ = 0, height_ = 0;
  int chroma_w_ = 0, chroma_h_ = 0;  // 0: mono
  std::uint64_t offset_ = 0;         // stream offset of buffer_[0]
  bool skipping_ = false;
  Y4mCounters counters_;
};

}  // namespace pixyslam::camera
