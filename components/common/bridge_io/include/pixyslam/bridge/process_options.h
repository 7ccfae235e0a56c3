#pragma once

#include <chrono>
#include <cstdio>
#include <functional>
#include <string>

#include "pixyslam/config/yaml_text.h"
#include "pixyslam/parameters/parameters.h"

namespace pixyslam::bridge {

// Process settings every bridge has, in its config file's `node:` mapping.
struct BridgeProcessOptions {
  double reopen_period_s = 1.0;   // between attempts to open a missing or hung-up device
  double status_period_s = 10.0;  // counters to the log this often (0: only at exit)
  // The first sample waits until this many readers matched (its writer is
  // volatile: a reader that matches later misses what went before), at most
  // wait_readers_timeout_s; then it publishes anyway, with a warning.
  int wait_readers = 1;
  double wait_readers_timeout_s = 3.0;
};

// The `node:` parameters every bridge has (reopen_period_s, status_period_s),
// for a bridge's own `node:` table; `member` finds them in its options.
template <class Options>
parameters::Table<Options> process_parameters(std::function<BridgeProcessOptions&(Options&)> member) {
  namespace P = parameters;
  return {
      P::real<Options>("reopen_period_s", 0.01, 3600.0, "s", "between attempts to open a missing or hung-up device",
                       [member](Options& o) -> double& { return member(o).reopen_period_s; }),
      P::real<Options>("status_period_s", 0.0, 86400.0, "s", "counters to the log this often (0: only at exit)",
                       [member](Options& o) -> double& { return member(o).status_period_s; }),
      P::integer<Options, int>("wait_readers", 0, 100, "", "readers to wait for before the first sample (all of them: "
                               "a later one misses the start)",
                               [member](Options& o) -> int& { return member(o).wait_readers; }),
      P::real<Options>("wait_readers_timeout_s", 0.0, 3600.0, "s", "... at most this long, then publish anyway",
                       [member](Options& o) -> double& { return member(o).wait_readers_timeout_s; }),
  };
}

// Waits for options.wait_readers readers of `node`'s writer (node.wait_for_subscribers),
// and says so on stderr when they did not all come in time.
template <class Node>
void wait_for_readers(Node& node, const BridgeProcessOptions& options, const char* process) {
  if (options.wait_readers <= 0) return;
  if (!node.wait_for_subscribers(options.wait_readers,
                                 std::chrono::duration_cast<std::chrono::milliseconds>(
                                     std::chrono::duration<double>(options.wait_readers_timeout_s)))) {
    std::fprintf(stderr, "%s: fewer than %d readers matched after %g s (node.wait_readers); publishing anyway\n",
                 process, options.wait_readers, options.wait_readers_timeout_s);
  }
}

// The YAML scalars of the bridges' to_yaml() (config/yaml_text.h).
using config::yaml_number;
using config::yaml_quoted;

}  // namespace pixyslam::bridge
