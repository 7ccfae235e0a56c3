#pragma once

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace pixyslam::serial {

// What a read found.
enum class ReadStatus {
  kData,     // `bytes` (> 0) bytes were read
  kTimeout,  // nothing arrived within the timeout; bytes == 0
  kHangup,   // the other end is gone (USB device unplugged, pty master closed, end of
             // file); bytes == 0. Close the port and open it again (the device may
             // come back under the same path).
};

struct ReadResult {
  ReadStatus status = ReadStatus::kTimeout;
  std::size_t bytes = 0;
};

// The rates SerialPort accepts: the termios B50 ... B4000000 constants the
// platform defines, ascending.
const std::vector<long>& supported_bauds();
bool is_supported_baud(long baud);

// A serial device (USB CDC/ACM Arduino, USB-UART, a pty slave) in raw mode:
// cfmakeraw, 8 data bits, no parity, 1 stop bit, CLOCAL | CREAD, no hardware or
// software flow control, VMIN = VTIME = 0, opened O_NOCTTY | O_CLOEXEC |
// O_NONBLOCK. Input already queued when the port opens is discarded (it is
// stale). The device is held exclusively while open (flock): a second
// SerialPort or bridge cannot open it (EBUSY). Reads wait in poll() with a timeout; a hang-up is reported as
// ReadStatus::kHangup, not thrown, so a node can reopen the device. Errors throw
// std::system_error (open, termios, read and write failures; the message names
// the device path and the errno text) or std::invalid_argument (a rate not in
// supported_bauds(), listing them). Movable, not copyable; thread-compatible.
class SerialPort {
 public:
  SerialPort() = default;
  // Same as open(path, baud).
  SerialPort(const std::string& path, long baud);
  ~SerialPort();
  SerialPort(SerialPort&& other) noexcept;
  SerialPort& operator=(SerialPort&& other) noexcept;
  SerialPort(const SerialPort&) = delete;
  SerialPort& operator=(const SerialPort&) = delete;

  // Opens `path` (closing any device open before) and configures it as above.
  void open(const std::string& path, long baud);
  void close() noexcept;
  bool is_open() const { return fd_ >= 0; }
  const std::string& path() const { return path_; }
  long baud() const { return baud_; }
  int native_handle() const { return fd_; }

  // Waits up to `timeout` for input and reads at most `max` (> 0) bytes of it.
  ReadResult read_some(std::uint8_t* buffer, std::size_t max, std::chrono::milliseconds timeout);
  // Writes every byte, waiting for room in the driver's buffer for at most
  // `timeout` overall; throws std::system_error (ETIMEDOUT) if the bytes could
  // not all be written by then, or on a write error (EIO after a hang-up).
  void write_all(const std::uint8_t* data, std::size_t size,
                 std::chrono::milliseconds timeout = std::chrono::milliseconds(1000));
  void write_all(std::string_view bytes, std::chrono::milliseconds timeout = std::chrono::milliseconds(1000));

 private:
  void require_open(const char* operation) const;

  int fd_ = -1;
  std::string path_;
  long baud_ = 0;
};

}  // namespace pixyslam::serial
