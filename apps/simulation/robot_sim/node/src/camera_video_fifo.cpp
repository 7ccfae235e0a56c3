#include "pixyslam/robot_sim/camera_video_fifo.h"

#include <fcntl.h>
#include <poll.h>
#include <sys/ioctl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <stdexcept>

#include "pixyslam/camera/y4m_stream.h"

namespace pixyslam::robot_sim {
namespace {

constexpr int kPipeBytes = 1 << 20;  // room for a few frames (Linux pipe-max-size default)

}  // namespace

CameraVideoFifo::CameraVideoFifo(std::string path, int width, int height, int fps)
    : path_(std::move(path)), header_(camera::y4m_header(width, height, fps, 1)) {
  ::unlink(path_.c_str());
  if (::mkfifo(path_.c_str(), 0660) != 0) {
    throw std::runtime_error("camera video: cannot create FIFO '" + path_ + "': " + std::strerror(errno));
  }
}

CameraVideoFifo::~CameraVideoFifo() {
  if (fd_ >= 0) ::close(fd_);
  ::unlink(path_.c_str());
}

bool CameraVideoFifo::try_open() {
  if (fd_ >= 0) return true;
  fd_ = ::open(path_.c_str(), O_WRONLY | O_NONBLOCK | O_CLOEXEC);
  if (fd_ < 0) return false;  // ENXIO: no reader yet
  pipe_bytes_ = ::fcntl(fd_, F_SETPIPE_SZ, kPipeBytes);
  if (pipe_bytes_ < 0) pipe_bytes_ = ::fcntl(fd_, F_GETPIPE_SZ);
  if (!write_all(reinterpret_cast<const std::uint8_t*>(header_.data()), header_.size())) return false;
  return true;
}

bool CameraVideoFifo::write_all(const std::uint8_t* data, std::size_t size) {
  while (size > 0) {
    const ssize_t n = ::write(fd_, data, size);
    if (n > 0) {
      data += n;
      size -= static_cast<std::size_t>(n);
      continue;
    }
    if (n < 0 && errno == EAGAIN) {
      // Only the rest of a frame that was checked to fit: wait for the reader.
      pollfd p{fd_, POLLOUT, 0};
      if (::poll(&p, 1, 100) > 0) continue;
    }
    // EPIPE (the reader left; SIGPIPE is ignored) or a reader stuck for 100 ms.
    ::close(fd_);
    fd_ = -1;
    return false;
  }
  return true;
}

void CameraVideoFifo::write_frame(const cv::Mat& bgr) {
  if (!try_open()) {
    ++counters_.dropped_no_reader;
    return;
  }
  const std::vector<std::uint8_t> frame = camera::encode_y4m_frame(bgr);
  int unread = 0;
  if (::ioctl(fd_, FIONREAD, &unread) == 0 && pipe_bytes_ > 0 &&
      static_cast<long>(frame.size()) > static_cast<long>(pipe_bytes_) - unread) {
    ++counters_.dropped_pipe_full;
    return;
  }
  if (write_all(frame.data(), frame.size())) {
    ++counters_.frames_written;
  } else {
    ++counters_.dropped_no_reader;
  }
}

}  // namespace pixyslam::robot_sim
