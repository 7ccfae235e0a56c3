#include "pixyslam/camera/y4m_stream.h"

#include <algorithm>
#include <cstring>
#include <sstream>
#include <stdexcept>

#include <opencv2/imgproc.hpp>

namespace pixyslam::camera {
namespace {

constexpr char kMagic[] = "YUV4MPEG2";
constexpr std::size_t kMagicSize = sizeof(kMagic) - 1;
constexpr char kFrame[] = "FRAME";
constexpr std::size_t kFrameSize = sizeof(kFrame) - 1;
constexpr std::size_t kMaxHeaderLine = 1024;
constexpr std::size_t kMaxFrameLine = 256;
constexpr int kMaxSide = 4096;

bool starts_with(const std::vector<std::uint8_t>& b, const char* text, std::size_t n) {
  return b.size() >= n && std::memcmp(b.data(), text, n) == 0;
}

// Position of the first '\n' within `limit` bytes, or npos.
std::size_t line_end(const std::vector<std::uint8_t>& b, std::size_t limit) {
  const auto end = b.begin() + static_cast<std::ptrdiff_t>(std::min(b.size(), limit));
  const auto it = std::find(b.begin(), end, '\n');
  return it == end ? std::string::npos : static_cast<std::size_t>(it - b.begin());
}

// First position >= 1 where `text` starts, or where a prefix of it runs to the end.
std::size_t find_from_1(const std::vector<std::uint8_t>& b, const char* text, std::size_t n) {
  for (std::size_t i = 1; i < b.size(); ++i) {
    const std::size_t m = std::min(n, b.size() - i);
    if (std::memcmp(b.data() + i, text, m) == 0) return i;
  }
  return b.size();
}

}  // namespace

std::string y4m_header(int width, int height, int fps_num, int fps_den) {
  std::ostringstream os;
  os << kMagic << " W" << width << " H" << height << " F" << fps_num << ":" << fps_den
     << " Ip A1:1 C444 XCOLORRANGE=FULL\n";
  return os.str();
}

std::vector<std::uint8_t> encode_y4m_frame(const cv::Mat& bgr) {
  if (bgr.empty() || bgr.type() != CV_8UC3) throw std::invalid_argument("encode_y4m_frame: need a CV_8UC3 BGR image");
  cv::Mat ycrcb;
  cv::cvtColor(bgr, ycrcb, cv::COLOR_BGR2YCrCb);
  cv::Mat planes[3];
  cv::split(ycrcb, planes);
  const std::size_t plane = static_cast<std::size_t>(bgr.rows) * static_cast<std::size_t>(bgr.cols);
  std::vector<std::uint8_t> out(kFrameSize + 1 + 3 * plane);
  std::memcpy(out.data(), "FRAME\n", kFrameSize + 1);
  std::uint8_t* p = out.data() + kFrameSize + 1;
  for (int c : {0, 2, 1}) {  // Y, Cb, Cr
    const cv::Mat m = planes[c].isContinuous() ? planes[c] : planes[c].clone();
    std::memcpy(p, m.data, plane);
    p += plane;
  }
  return out;
}

void Y4mParser::reset() {
  buffer_.clear();
  state_ = State::kHeader;
  skipping_ = false;
}

void Y4mParser::error(const std::string& message) {
  if (on_error_) on_error_(message);
}

void Y4mParser::skip(std::size_t n, const char* why) {
  if (n == 0) return;
  if (!skipping_) {
    error("y4m: byte offset " + std::to_string(offset_) + ": " + why + ", skipping");
    skipping_ = true;
  }
  counters_.bytes_skipped += n;
  offset_ += n;
  buffer_.erase(buffer_.begin(), buffer_.begin() + static_cast<std::ptrdiff_t>(n));
}

bool Y4mParser::parse_header(const std::string& line) {
  std::istringstream is(line.substr(kMagicSize));
  std::string tag;
  int w = 0, h = 0;
  std::string colour = "420jpeg";
  while (is >> tag) {
    char* end = nullptr;
    if (tag[0] == 'W') w = static_cast<int>(std::strtol(tag.c_str() + 1, &end, 10));
    else if (tag[0] == 'H') h = static_cast<int>(std::strtol(tag.c_str() + 1, &end, 10));
    else if (tag[0] == 'C') colour = tag.substr(1);
    if (end && *end != '\0') w = h = 0;
  }
  std::string why;
  if (w <= 0 || h <= 0 || w > kMaxSide || h > kMaxSide) {
    why = "width/height missing or outside 1.." + std::to_string(kMaxSide);
  } else if (colour == "444") {
    chroma_w_ = w, chroma_h_ = h;
  } else if (colour == "420" || colour == "420jpeg" || colour == "420paldv" || colour == "420mpeg2") {
    chroma_w_ = (w + 1) / 2, chroma_h_ = (h + 1) / 2;
  } else if (colour == "mono") {
    chroma_w_ = chroma_h_ = 0;
  } else {
    why = "colour space C" + colour + " is not read (444, 420*, mono are)";
  }
  if (!why.empty()) {
    ++counters_.bad_headers;
    error("y4m: byte offset " + std::to_string(offset_) + ": header rejected: " + why);
    return false;
  }
  width_ = w;
  height_ = h;
  ++counters_.headers;
  return true;
}

void Y4mParser::feed(const std::uint8_t* data, std::size_t size, const FrameCallback& on_frame) {
  counters_.bytes_in += size;
  buffer_.insert(buffer_.end(), data, data + size);
  for (;;) {
    if (state_ == State::kPlanes) {
      const std::size_t y = static_cast<std::size_t>(width_) * static_cast<std::size_t>(height_);
      const std::size_t c = static_cast<std::size_t>(chroma_w_) * static_cast<std::size_t>(chroma_h_);
      if (buffer_.size() < y + 2 * c) return;
      cv::Mat bgr;
      const cv::Mat luma(height_, width_, CV_8UC1, buffer_.data());
      if (c == 0) {
        cv::cvtColor(luma, bgr, cv::COLOR_GRAY2BGR);
      } else {
        cv::Mat cb(chroma_h_, chroma_w_, CV_8UC1, buffer_.data() + y);
        cv::Mat cr(chroma_h_, chroma_w_, CV_8UC1, buffer_.data() + y + c);
        if (chroma_w_ != width_) {
          cv::resize(cv::Mat(cb), cb, luma.size(), 0, 0, cv::INTER_LINEAR);
          cv::resize(cv::Mat(cr), cr, luma.size(), 0, 0, cv::INTER_LINEAR);
        }
        cv::Mat ycrcb;
        cv::merge(std::vector<cv::Mat>{luma, cr, cb}, ycrcb);
        cv::cvtColor(ycrcb, bgr, cv::COLOR_YCrCb2BGR);
      }
      offset_ += y + 2 * c;
      buffer_.erase(buffer_.begin(), buffer_.begin() + static_cast<std::ptrdiff_t>(y + 2 * c));
      state_ = State::kFrameMarker;
      ++counters_.frames;
      on_frame(std::move(bgr));
      continue;
    }
    if (buffer_.size() < kMagicSize) return;
    if (starts_with(buffer_, kMagic, kMagicSize)) {
      const std::size_t end = line_end(buffer_, kMaxHeaderLine);
      if (end == std::string::npos) {
        if (buffer_.size() < kMaxHeaderLine) return;
        ++counters_.bad_headers;
        skip(kMagicSize, "a header line longer than 1024 bytes");
        state_ = State::kHeader;
        continue;
      }
      const std::string line(buffer_.begin(), buffer_.begin() + static_cast<std::ptrdiff_t>(end));
      skipping_ = false;
      const bool ok = parse_header(line);
      offset_ += end + 1;
      buffer_.erase(buffer_.begin(), buffer_.begin() + static_cast<std::ptrdiff_t>(end + 1));
      state_ = ok ? State::kFrameMarker : State::kHeader;
      continue;
    }
    if (state_ == State::kFrameMarker && starts_with(buffer_, kFrame, kFrameSize)) {
      const std::size_t end = line_end(buffer_, kMaxFrameLine);
      if (end == std::string::npos) {
        if (buffer_.size() < kMaxFrameLine) return;
        skip(kFrameSize, "a FRAME line longer than 256 bytes");
        continue;
      }
      skipping_ = false;
      offset_ += end + 1;
      buffer_.erase(buffer_.begin(), buffer_.begin() + static_cast<std::ptrdiff_t>(end + 1));
      state_ = State::kPlanes;
      continue;
    }
    // Neither a header nor (where one is due) a frame marker: skip to the next.
    std::size_t next = find_from_1(buffer_, kMagic, kMagicSize);
    if (state_ == State::kFrameMarker) next = std::min(next, find_from_1(buffer_, kFrame, kFrameSize));
    skip(next, state_ == State::kHeader ? "no YUV4MPEG2 stream header" : "no FRAME marker where a frame was due");
    if (buffer_.size() < kMagicSize) return;
  }
}

}  // namespace pixyslam::camera
