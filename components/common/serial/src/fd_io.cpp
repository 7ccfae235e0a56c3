#include "fd_io.h"

#include <fcntl.h>
#include <poll.h>
#include <termios.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <climits>
#include <stdexcept>

namespace pixyslam::serial::detail {
namespace {

using Clock = std::chrono::steady_clock;

// Milliseconds left until `deadline`, rounded up so that poll() never returns
// early with time still left; 0 once it has passed.
int poll_ms_until(Clock::time_point deadline) {
  const auto left = std::chrono::ceil<std::chrono::milliseconds>(deadline - Clock::now()).count();
  return static_cast<int>(std::clamp<long long>(left, 0, INT_MAX));
}

bool would_block(int err) { return err == EAGAIN || err == EWOULDBLOCK; }

}  // namespace

std::system_error os_error(int err, const std::string& what) {
  return std::system_error(err, std::generic_category(), what);
}

UniqueFd::~UniqueFd() { close_fd(fd_); }

void close_fd(int fd) noexcept {
  if (fd >= 0) ::close(fd);  // EINTR: Linux has closed the descriptor anyway
}

void make_nonblocking_cloexec(int fd, const std::string& name) {
  const int fl = ::fcntl(fd, F_GETFL);
  if (fl < 0 || ::fcntl(fd, F_SETFL, fl | O_NONBLOCK) != 0) throw os_error(errno, name + ": fcntl(O_NONBLOCK)");
  const int fd_flags = ::fcntl(fd, F_GETFD);
  if (fd_flags < 0 || ::fcntl(fd, F_SETFD, fd_flags | FD_CLOEXEC) != 0) {
    throw os_error(errno, name + ": fcntl(FD_CLOEXEC)");
  }
}

void make_raw(int fd, unsigned long speed, const std::string& name) {
  termios tio{};
  if (::tcgetattr(fd, &tio) != 0) throw os_error(errno, name + ": not a terminal device (tcgetattr)");
  ::cfmakeraw(&tio);
  tio.c_cflag &= ~static_cast<tcflag_t>(CSTOPB | PARENB | CSIZE);
#ifdef CRTSCTS
  tio.c_cflag &= ~static_cast<tcflag_t>(CRTSCTS);
#endif
  tio.c_cflag |= CS8 | CLOCAL | CREAD;
  tio.c_iflag &= ~static_cast<tcflag_t>(IXON | IXOFF | IXANY);
  tio.c_cc[VMIN] = 0;
  tio.c_cc[VTIME] = 0;
  if (speed != 0) {
    const auto s = static_cast<speed_t>(speed);
    if (::cfsetispeed(&tio, s) != 0 || ::cfsetospeed(&tio, s) != 0) throw os_error(errno, name + ": cfsetspeed");
  }
  if (::tcsetattr(fd, TCSANOW, &tio) != 0) throw os_error(errno, name + ": tcsetattr");
}

ReadResult poll_read(int fd, std::uint8_t* buffer, std::size_t max, std::chrono::milliseconds timeout,
                     const std::string& name) {
  if (max == 0) throw std::invalid_argument(name + ": read_some with a buffer of 0 bytes");
  const Clock::time_point deadline = Clock::now() + std::max(timeout, std::chrono::milliseconds(0));
  for (;;) {
    pollfd p{fd, POLLIN, 0};
    const int r = ::poll(&p, 1, poll_ms_until(deadline));
    if (r < 0) {
      if (errno == EINTR) continue;
      throw os_error(errno, name + ": poll");
    }
    if (r == 0) return {ReadStatus::kTimeout, 0};
    if (p.revents & POLLNVAL) throw os_error(EBADF, name + ": poll");
    if (p.revents & POLLIN) {
      // Data still queued is read before a hang-up is reported.
      const ssize_t n = ::read(fd, buffer, max);
      if (n > 0) return {ReadStatus::kData, static_cast<std::size_t>(n)};
      // poll() reported input, so 0 bytes means end of file (a hung-up tty).
      if (n == 0) return {ReadStatus::kHangup, 0};
      if (errno == EIO) return {ReadStatus::kHangup, 0};
      if (!would_block(errno) && errno != EINTR) throw os_error(errno, name + ": read");
    } else if (p.revents & (POLLHUP | POLLERR)) {
      return {ReadStatus::kHangup, 0};
    }
    if (Clock::now() >= deadline) return {ReadStatus::kTimeout, 0};
  }
}

std::size_t write_until(int fd, const std::uint8_t* data, std::size_t size, Clock::time_point deadline,
                        const std::string& name) {
  std::size_t done = 0;
  while (done < size) {
    const ssize_t n = ::write(fd, data + done, size - done);
    if (n > 0) {
      done += static_cast<std::size_t>(n);
      continue;
    }
    if (n < 0 && errno == EINTR) continue;
    if (n < 0 && !would_block(errno)) throw os_error(errno, name + ": write");
    // The driver's buffer is full: wait for room until the deadline.
    const int wait_ms = poll_ms_until(deadline);
    if (wait_ms == 0) break;
    pollfd p{fd, POLLOUT, 0};
    const int r = ::poll(&p, 1, wait_ms);
    if (r < 0) {
      if (errno == EINTR) continue;
      throw os_error(errno, name + ": poll");
    }
    if (r == 0) break;
    if (p.revents & POLLNVAL) throw os_error(EBADF, name + ": poll");
    if ((p.revents & (POLLHUP | POLLERR)) && !(p.revents & POLLOUT)) {
      throw os_error(EIO, name + ": write: the other end hung up");
    }
  }
  return done;
}

}  // namespace pixyslam::serial::detail
