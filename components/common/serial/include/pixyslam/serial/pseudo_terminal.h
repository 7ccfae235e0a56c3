#pragma once

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "pixyslam/serial/serial_port.h"

namespace pixyslam::serial {

// Running totals of a PseudoTerminal's writes.
struct PseudoTerminalCounters {
  std::uint64_t written_bytes = 0;  // accepted by the pty
  std::uint64_t dropped_bytes = 0;  // discarded by the drop policy (see PseudoTerminal)
  std::uint64_t stalls = 0;         // times a write timed out and the pty became stalled
};

// A pseudo-terminal pair through which a simulator plays a serial device: the
// simulator writes the device's bytes to the master, a bridge opens the slave
// (slave_path(), or the symlink at link_path()) with SerialPort as if it were
// the real device. Master and slave are in raw mode (no echo, no CR/LF
// translation), the master non-blocking.
//
// The pair keeps its own descriptor of the slave open for its whole life, so a
// client opening and closing the slave (a bridge restarting) never hangs the
// master up: writes keep working and the master never reads EIO. Bytes written
// while no client reads queue in the kernel (14 kB on Linux 6.x, up to 64 kB
// elsewhere; about 8 s of Arduino lines); SerialPort discards that stale input
// when it opens.
//
// Drop policy: write_all() never blocks for more than the write timeout. If the
// queue is full it waits up to that timeout for room; what is still unwritten
// then is dropped and counted, and the pty becomes "stalled": later writes wait
// no more and drop at once whatever does not fit, until one write fits
// completely. So a simulator writing into a pty nobody reads loses bytes but
// keeps its pace (one timeout per stall). A dropped tail can cut a line or a
// frame in two; the protocol parsers resynchronise.
//
// With a link path, a symbolic link to the slave is created there (a stale
// symbolic link is replaced; any other existing file is an error) and removed
// by the destructor if it still points to this slave. Errors throw
// std::system_error naming the path and the errno text, or std::runtime_error.
// Not copyable or movable; thread-compatible (one thread may write while
// another uses a SerialPort on the slave).
class PseudoTerminal {
 public:
  explicit PseudoTerminal(const std::string& link_path = "",
                          std::chrono::milliseconds write_timeout = std::chrono::milliseconds(100));
  ~PseudoTerminal();
  PseudoTerminal(const PseudoTerminal&) = delete;
  PseudoTerminal& operator=(const PseudoTerminal&) = delete;

  // The slave device, e.g. "/dev/pts/3".
  const std::string& slave_path() const { return slave_path_; }
  // The symbolic link to the slave, empty if none was asked for.
  const std::string& link_path() const { return link_path_; }
  // The path a client should open: the link if there is one, else the slave.
  const std::string& device_path() const { return link_path_.empty() ? slave_path_ : link_path_; }
  int master_handle() const { return master_fd_; }

  // Writes to the master with the drop policy above; returns the bytes written
  // (the rest of `size` was dropped).
  std::size_t write_all(const std::uint8_t* data, std::size_t size);
  std::size_t write_all(std::string_view bytes);
  std::size_t write_all(const std::vector<std::uint8_t>& bytes) { return write_all(bytes.data(), bytes.size()); }

  // Reads what a client wrote to the slave: waits up to `timeout`, reads at
  // most `max` (> 0) bytes.
  ReadResult read_some(std::uint8_t* buffer, std::size_t max, std::chrono::milliseconds timeout);

  // Bytes written to the master that no client has read yet (the slave's
  // input queue, as TIOCINQ reports it). The kernel moves written bytes into
  // that queue asynchronously: a write shows up a moment later.
  std::size_t queued_bytes() const;
  bool stalled() const { return stalled_; }
  std::chrono::milliseconds write_timeout() const { return write_timeout_; }
  const PseudoTerminalCounters& counters() const { return counters_; }

 private:
  int master_fd_ = -1;
  int slave_fd_ = -1;  // held open so that clients come and go without a hang-up
  std::string slave_path_;
  std::string link_path_;
  std::chrono::milliseconds write_timeout_;
  bool stalled_ = false;
  PseudoTerminalCounters counters_;
};

}  // namespace pixyslam::serial
