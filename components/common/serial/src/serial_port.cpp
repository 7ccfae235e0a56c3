#include "pixyslam/serial/serial_port.h"

#include <fcntl.h>
#include <sys/file.h>
#include <termios.h>
#include <unistd.h>

#include <cerrno>
#include <stdexcept>
#include <utility>

#include "fd_io.h"

namespace pixyslam::serial {
namespace {

struct BaudConstant {
  long baud;
  speed_t constant;
};

// Rates Linux termios names (the higher ones are not POSIX: only where defined).
const std::vector<BaudConstant>& baud_table() {
  static const std::vector<BaudConstant> table = {
      {50, B50},         {75, B75},         {110, B110},       {134, B134},       {150, B150},
      {200, B200},       {300, B300},       {600, B600},       {1200, B1200},     {1800, B1800},
      {2400, B2400},     {4800, B4800},     {9600, B9600},     {19200, B19200},   {38400, B38400},
#ifdef B57600
      {57600, B57600},
#endif
#ifdef B115200
      {115200, B115200},
#endif
#ifdef B230400
      {230400, B230400},
#endif
#ifdef B460800
      {460800, B460800},
#endif
#ifdef B500000
      {500000, B500000},
#endif
#ifdef B576000
      {576000, B576000},
#endif
#ifdef B921600
      {921600, B921600},
#endif
#ifdef B1000000
      {1000000, B1000000},
#endif
#ifdef B1152000
      {1152000, B1152000},
#endif
#ifdef B1500000
      {1500000, B1500000},
#endif
#ifdef B2000000
      {2000000, B2000000},
#endif
#ifdef B2500000
      {2500000, B2500000},
#endif
#ifdef B3000000
      {3000000, B3000000},
#endif
#ifdef B3500000
      {3500000, B3500000},
#endif
#ifdef B4000000
      {4000000, B4000000},
#endif
  };
  return table;
}

std::string device_name(const std::string& path) { return "serial port " + path; }

speed_t speed_constant(long baud, const std::string& path) {
  for (const BaudConstant& b : baud_table()) {
    if (b.baud == baud) return b.constant;
  }
  std::string allowed;
  for (const long b : supported_bauds()) allowed += (allowed.empty() ? "" : ", ") + std::to_string(b);
  throw std::invalid_argument(device_name(path) + ": baud rate " + std::to_string(baud) +
                              " is not supported (supported: " + allowed + ")");
}

}  // namespace

const std::vector<long>& supported_bauds() {
  static const std::vector<long> bauds = [] {
    std::vector<long> v;
    for (const BaudConstant& b : baud_table()) v.push_back(b.baud);
    return v;
  }();
  return bauds;
}

bool is_supported_baud(long baud) {
  for (const BaudConstant& b : baud_table()) {
    if (b.baud == baud) return true;
  }
  return false;
}

SerialPort::SerialPort(const std::string& path, long baud) { open(path, baud); }

SerialPort::~SerialPort() { close(); }

SerialPort::SerialPort(SerialPort&& other) noexcept
    : fd_(std::exchange(other.fd_, -1)), path_(std::move(other.path_)), baud_(other.baud_) {}

SerialPort& SerialPort::operator=(SerialPort&& other) noexcept {
  if (this != &other) {
    close();
    fd_ = std::exchange(other.fd_, -1);
    path_ = std::move(other.path_);
    baud_ = other.baud_;
  }
  return *this;
}

void SerialPort::open(const std::string& path, long baud) {
  close();
  const std::string name = device_name(path);
  const speed_t speed = speed_constant(baud, path);  // before touching the device
  detail::UniqueFd fd(::open(path.c_str(), O_RDWR | O_NOCTTY | O_CLOEXEC | O_NONBLOCK));
  if (fd.get() < 0) {
    const int err = errno;
    std::string hint;
    if (err == EACCES || err == EPERM) hint = " (serial devices belong to the group 'dialout': is this user in it?)";
    if (err == EBUSY) hint = " (in use by another process: another bridge, or a terminal program)";
    throw detail::os_error(err, name + ": open failed" + hint);
  }
  // One reader per device: two would each get part of the bytes. flock() holds
  // against another bridge (root too) and ends with the descriptor, also when
  // the process is killed. (Not TIOCEXCL: on a pty whose other side stays open,
  // a killed bridge would leave it set and lock its own restart out.)
  if (::flock(fd.get(), LOCK_EX | LOCK_NB) != 0) {
    const int err = errno;
    if (err == EWOULDBLOCK) {
      throw detail::os_error(EBUSY, name + ": in use by another process (another bridge?)");
    }
    throw detail::os_error(err, name + ": flock");
  }
  detail::make_raw(fd.get(), speed, name);
  // Bytes that arrived before this open are stale.
  if (::tcflush(fd.get(), TCIFLUSH) != 0) throw detail::os_error(errno, name + ": tcflush");
  fd_ = fd.release();
  path_ = path;
  baud_ = baud;
}

void SerialPort::close() noexcept {
  detail::close_fd(fd_);
  fd_ = -1;
}

void SerialPort::require_open(const char* operation) const {
  if (fd_ < 0) {
    throw std::logic_error("serial port" + (path_.empty() ? std::string() : " " + path_) + ": " + operation +
                           " on a closed port");
  }
}

ReadResult SerialPort::read_some(std::uint8_t* buffer, std::size_t max, std::chrono::milliseconds timeout) {
  require_open("read_some");
  return detail::poll_read(fd_, buffer, max, timeout, device_name(path_));
}

void SerialPort::write_all(const std::uint8_t* data, std::size_t size, std::chrono::milliseconds timeout) {
  require_open("write_all");
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  const std::size_t done = detail::write_until(fd_, data, size, deadline, device_name(path_));
  if (done < size) {
    throw detail::os_error(ETIMEDOUT, device_name(path_) + ": write: only " + std::to_string(done) + " of " +
                                          std::to_string(size) + " bytes written within " +
                                          std::to_string(timeout.count()) + " ms");
  }
}

void SerialPort::write_all(std::string_view bytes, std::chrono::milliseconds timeout) {
  write_all(reinterpret_cast<const std::uint8_t*>(bytes.data()), bytes.size(), timeout);
}

}  // namespace pixyslam::serial
