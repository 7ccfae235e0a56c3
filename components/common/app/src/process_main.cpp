#include "pixyslam/app/process_main.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

namespace pixyslam::app {

void check_input_file(const std::string& path) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC | O_NONBLOCK);  // a FIFO: no wait for a writer
  int error = fd < 0 ? errno : 0;
  struct stat st {};
  if (fd >= 0) {
    if (::fstat(fd, &st) != 0) {
      error = errno;
    } else if (S_ISDIR(st.st_mode)) {
      error = EISDIR;
    }
    ::close(fd);
  }
  if (error != 0) throw std::runtime_error(path + ": cannot open: " + std::strerror(error));
}

void print_effective_configuration(const char* name, const std::string& yaml) {
  std::printf("# %s: effective configuration\n%s", name, yaml.c_str());
  std::fflush(stdout);
}

}  // namespace pixyslam::app
