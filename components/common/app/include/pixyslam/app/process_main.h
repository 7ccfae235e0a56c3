#pragma once

#include <cstdio>
#include <exception>
#include <optional>
#include <set>
#include <stdexcept>
#include <string>

#include "pixyslam/app/cli.h"
#include "pixyslam/config/yaml_reader.h"

namespace pixyslam::app {

// Runs a process's `body` (which returns the exit status) and turns an
// exception escaping it into an exit status and one line on stderr:
//   app::UsageError     -> 2, "<name>: <what> (see --help)"
//   config::ConfigError -> 2, "<name>: config error: <what>"
//   std::exception      -> 1, "<name>: <what>"
template <class Body>
int run_main(const char* name, const Body& body) {
  try {
    return body();
  } catch (const UsageError& e) {
    std::fprintf(stderr, "%s: %s (see --help)\n", name, e.what());
    return 2;
  } catch (const config::ConfigError& e) {
    std::fprintf(stderr, "%s: config error: %s\n", name, e.what());
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s: %s\n", name, e.what());
    return 1;
  }
}

// The configuration stage of a process (reading its files, applying its
// flags): a config::ConfigError ("<name>: config error: <what>") or a
// std::invalid_argument ("<name>: <what> (see --help)") escaping `body` is a
// configuration or usage error: one line on stderr, returns 2. Returns
// nothing when the process is to go on.
template <class Body>
std::optional<int> configure(const char* name, const Body& body) {
  try {
    body();
  } catch (const config::ConfigError& e) {
    std::fprintf(stderr, "%s: config error: %s\n", name, e.what());
    return 2;
  } catch (const std::invalid_argument& e) {
    std::fprintf(stderr, "%s: %s (see --help)\n", name, e.what());
    return 2;
  }
  return std::nullopt;
}

// A data file (not a config) the process reads: throws std::runtime_error
// "PATH: cannot open: REASON" (exit 1 in run_main) unless it is a readable
// regular file.
void check_input_file(const std::string& path);

// Prints "# <name>: effective configuration" and `yaml` to stdout, flushed.
void print_effective_configuration(const char* name, const std::string& yaml);

}  // namespace pixyslam::app
