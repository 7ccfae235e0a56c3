#pragma once

#include <functional>
#include <string>

#include "pixyslam/config/yaml_text.h"
#include "pixyslam/parameters/parameters.h"

namespace pixyslam::bridge {

// Process settings every bridge has, in its config file's `node:` mapping.
struct BridgeProcessOptions {
  double reopen_period_s = 1.0;   // between attempts to open a missing or hung-up device
  double status_period_s = 10.0;  // counters to the log this often (0: only at exit)
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
  };
}

// The YAML scalars of the bridges' to_yaml() (config/yaml_text.h).
using config::yaml_number;
using config::yaml_quoted;

}  // namespace pixyslam::bridge
