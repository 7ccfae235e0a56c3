#include "pixyslam/map_view/image_output.h"

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <system_error>
#include <vector>

#include <opencv2/imgcodecs.hpp>

#include "pixyslam/map_view/map_log.h"

namespace pixyslam::map_view {

void write_png(const std::string& path, const cv::Mat& image) {
  std::vector<unsigned char> bytes;
  try {
    // Level 9: maps are mostly flat colour; a third smaller than the default.
    if (!cv::imencode(".png", image, bytes, {cv::IMWRITE_PNG_COMPRESSION, 9})) {
      throw std::runtime_error("PNG encoding failed");
    }
  } catch (const cv::Exception& e) {
    throw std::runtime_error(path + ": cannot encode PNG: " + e.what());
  }
  const std::filesystem::path target(path);
  std::error_code ec;
  if (target.has_parent_path()) std::filesystem::create_directories(target.parent_path(), ec);
  const std::filesystem::path temp = target.string() + ".tmp";
  {
    std::ofstream file(temp, std::ios::binary | std::ios::trunc);
    file.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
    file.close();
    if (!file) {
      std::filesystem::remove(temp, ec);
      throw std::runtime_error(path + ": cannot write the file");
    }
  }
  std::filesystem::rename(temp, target, ec);
  if (ec) {
    std::filesystem::remove(temp, ec);
    throw std::runtime_error(path + ": cannot write the file (rename failed)");
  }
}

bool is_video_path(const std::string& out) {
  if (out.size() < 4) return false;
  std::string ext = out.substr(out.size() - 4);
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
  return ext == ".avi";
}

FrameSink::FrameSink(const std::string& out, double fps, cv::Size size) : out_(out), size_(size) {
  video_ = is_video_path(out);
  std::error_code ec;
  if (video_) {
    const std::filesystem::path parent = std::filesystem::path(out).parent_path();
    if (!parent.empty()) std::filesystem::create_directories(parent, ec);
    if (!parent.empty() && !std::filesystem::is_directory(parent)) {
      throw InputError(out + ": cannot create the folder " + parent.string());
    }
    bool opened = false;
    try {
      // OpenCV's own AVI/MJPG writer: no GStreamer or FFmpeg needed.
      opened = writer_.open(out, cv::CAP_OPENCV_MJPEG, cv::VideoWriter::fourcc('M', 'J', 'P', 'G'), fps, size, true);
    } catch (const cv::Exception&) {
      opened = false;
    }
    if (!opened) throw InputError(out + ": cannot open an MJPG video writer (is the folder writable?)");
  } else {
    std::filesystem::create_directories(out, ec);
    if (ec || !std::filesystem::is_directory(out)) {
      throw InputError(out + ": cannot create the frame folder" + (ec ? " (" + ec.message() + ")" : std::string()));
    }
  }
}

void FrameSink::write(const cv::Mat& frame) {
  if (frame.size() != size_ || frame.type() != CV_8UC3) {
    throw std::invalid_argument(out_ + ": frame of a different size or type");
  }
  if (video_) {
    writer_.write(frame);
  } else {
    char name[32];
    std::snprintf(name, sizeof name, "frame_%05zu.png", frames_);
    write_png((std::filesystem::path(out_) / name).string(), frame);
  }
  ++frames_;
}

void FrameSink::close() {
  if (writer_.isOpened()) writer_.release();
}

}  // namespace pixyslam::map_view
