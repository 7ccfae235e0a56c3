#include "pixyslam/app/process_main.h"

namespace pixyslam::app {

void print_effective_configuration(const char* name, const std::string& yaml) {
  std::printf("# %s: effective configuration\n%s", name, yaml.c_str());
  std::fflush(stdout);
}

}  // namespace pixyslam::app
