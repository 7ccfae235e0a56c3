#pragma once

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <string>
#include <system_error>

#include "pixyslam/serial/serial_port.h"

// Private helpers shared by SerialPort and PseudoTerminal.
namespace pixyslam::serial::detail {

// std::system_error whose message reads "<what>: <errno text>".
std::system_error os_error(int err, const std::string& what);

// A file descriptor closed on destruction.
class UniqueFd {
 public:
  explicit UniqueFd(int fd = -1) : fd_(fd) {}
  ~UniqueFd();
  UniqueFd(const UniqueFd&) = delete;
  UniqueFd& operator=(const UniqueFd&) = delete;
  int get() const { return fd_; }
  int release() {
    const int fd = fd_;
    fd_ = -1;
    return fd;
  }

 private:
  int fd_;
};

void close_fd(int fd) noexcept;

// Sets O_NONBLOCK and FD_CLOEXEC.
void make_nonblocking_cloexec(int fd, const std::string& name);

// Raw 8N1 without flow control, VMIN = VTIME = 0, at `speed` (a termios Bxxx
// constant) unless it is 0.
void make_raw(int fd, unsigned long speed, const std::string& name);

// poll() for input, then read(); see ReadStatus. `name` prefixes error messages.
ReadResult poll_read(int fd, std::uint8_t* buffer, std::size_t max, std::chrono::milliseconds timeout,
                     const std::string& name);

// Writes until every byte is written or `deadline` passes, waiting in poll()
// for room; returns the bytes written. Throws on write errors (EIO after a hang-up).
std::size_t write_until(int fd, const std::uint8_t* data, std::size_t size,
                        std::chrono::steady_clock::time_point deadline, const std::string& name);

}  // namespace pixyslam::serial::detail
