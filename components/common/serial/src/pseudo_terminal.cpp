#include "pixyslam/serial/pseudo_terminal.h"

#include <fcntl.h>
#include <sys/ioctl.h>
#include <sys/stat.h>
#include <termios.h>
#include <unistd.h>

#include <array>
#include <cerrno>
#include <cstdlib>
#include <stdexcept>

#include "fd_io.h"

namespace pixyslam::serial {
namespace {

const std::string kName = "pseudo-terminal";

std::string read_link(const std::string& path) {
  std::array<char, 4096> buf{};
  const ssize_t n = ::readlink(path.c_str(), buf.data(), buf.size() - 1);
  return n < 0 ? std::string() : std::string(buf.data(), static_cast<std::size_t>(n));
}

// Points `link` at `target`, replacing a symbolic link already there (stale or
// not); any other kind of file there is an error.
void make_link(const std::string& link, const std::string& target) {
  struct stat st {};
  if (::lstat(link.c_str(), &st) == 0) {
    if (!S_ISLNK(st.st_mode)) {
      throw std::runtime_error(kName + ": link path " + link +
                               " exists and is not a symbolic link; refusing to replace it");
    }
    if (::unlink(link.c_str()) != 0 && errno != ENOENT) {
      throw detail::os_error(errno, kName + ": cannot remove the old link " + link);
    }
  } else if (errno != ENOENT) {
    throw detail::os_error(errno, kName + ": link path " + link);
  }
  if (::symlink(target.c_str(), link.c_str()) != 0) {
    throw detail::os_error(errno, kName + ": cannot create the link " + link + " -> " + target);
  }
}

}  // namespace

PseudoTerminal::PseudoTerminal(const std::string& link_path, std::chrono::milliseconds write_timeout)
    : write_timeout_(write_timeout) {
  if (write_timeout.count() < 0) throw std::invalid_argument(kName + ": write timeout must be >= 0");
  detail::UniqueFd master(::posix_openpt(O_RDWR | O_NOCTTY));
  if (master.get() < 0) throw detail::os_error(errno, kName + ": posix_openpt");
  detail::make_nonblocking_cloexec(master.get(), kName + " master");
  if (::grantpt(master.get()) != 0) throw detail::os_error(errno, kName + ": grantpt");
  if (::unlockpt(master.get()) != 0) throw detail::os_error(errno, kName + ": unlockpt");
  std::array<char, 256> name{};
  if (const int err = ::ptsname_r(master.get(), name.data(), name.size()); err != 0) {
    throw detail::os_error(err, kName + ": ptsname_r");
  }
  const std::string slave_path(name.data());

  detail::UniqueFd slave(::open(slave_path.c_str(), O_RDWR | O_NOCTTY | O_CLOEXEC | O_NONBLOCK));
  if (slave.get() < 0) throw detail::os_error(errno, kName + ": open " + slave_path);
  // Raw before any byte passes: no echo back to the master, no CR/LF rewriting.
  // (On Linux termios set through the master act on the slave too; both are set.)
  detail::make_raw(slave.get(), 0, kName + " slave " + slave_path);
  detail::make_raw(master.get(), 0, kName + " master");

  if (!link_path.empty()) make_link(link_path, slave_path);
  master_fd_ = master.release();
  slave_fd_ = slave.release();
  slave_path_ = slave_path;
  link_path_ = link_path;
}

PseudoTerminal::~PseudoTerminal() {
  // Remove the link only if nobody has re-pointed it since.
  if (!link_path_.empty() && read_link(link_path_) == slave_path_) ::unlink(link_path_.c_str());
  detail::close_fd(slave_fd_);
  detail::close_fd(master_fd_);
}

std::size_t PseudoTerminal::write_all(const std::uint8_t* data, std::size_t size) {
  const auto now = std::chrono::steady_clock::now();
  const auto deadline = stalled_ ? now : now + write_timeout_;
  const std::size_t done = detail::write_until(master_fd_, data, size, deadline, kName + " " + slave_path_);
  counters_.written_bytes += done;
  if (done < size) {
    counters_.dropped_bytes += size - done;
    if (!stalled_) ++counters_.stalls;
    stalled_ = true;
  } else {
    stalled_ = false;
  }
  return done;
}

std::size_t PseudoTerminal::write_all(std::string_view bytes) {
  return write_all(reinterpret_cast<const std::uint8_t*>(bytes.data()), bytes.size());
}

ReadResult PseudoTerminal::read_some(std::uint8_t* buffer, std::size_t max, std::chrono::milliseconds timeout) {
  return detail::poll_read(master_fd_, buffer, max, timeout, kName + " " + slave_path_);
}

std::size_t PseudoTerminal::queued_bytes() const {
  int n = 0;
  if (::ioctl(slave_fd_, TIOCINQ, &n) != 0) throw detail::os_error(errno, kName + " " + slave_path_ + ": TIOCINQ");
  return static_cast<std::size_t>(n);
}

}  // namespace pixyslam::serial
