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
  // The serial link (`node.serial_device`, `node.baud`); each bridge gives its
  // own defaults (the encoder bridge: the Arduino's USB device; the pixy
  // bridge: the Pi's GPIO UART).
  std::string serial_device;
  long baud = 115200;
  double reopen_period_s = 1.0;   // between attempts to open a missing or hung-up device
  double silence_warn_s = 5.0;    // an open device silent this long is logged and counted (0: never)
  double status_period_s = 10.0;  // counters to the log this often (0: only at exit)
  // Messages are held until this many readers matched (the writer is
  // volatile: a reader that matches later misses what went before), at most
  // wait_readers_timeout_s after start; then it publishes anyway, with a
  // warning. The device is read meanwhile (BridgeRuntime).
  int wait_readers = 1;
  double wait_readers_timeout_s = 3.0;
};

// `node.serial_device` (an absolute path) and `node.baud` (checked against
// the rates the platform supports by validate_serial_link(), bridge_options.h).
template <class Options>
parameters::Table<Options> serial_link_parameters(std::function<BridgeProcessOptions&(Options&)> member,
                                                  const std::string& device_help) {
  namespace P = parameters;
  return {
      P::text<Options>("serial_device", device_help + " (an absolute path)",
                       [member](Options& o) -> std::string& { return member(o).serial_device; },
                       [](const std::string& v) {
                         if (v.empty() || v.front() != '/') throw std::invalid_argument("not an absolute path");
                       }),
      P::integer<Options, long>("baud", 1, 4000000, "bit/s", "the link's rate: a standard serial rate (e.g. 115200)",
                                [member](Options& o) -> long& { return member(o).baud; }),
  };
}

// The `node:` parameters every bridge has (reopen_period_s, silence_warn_s, status_period_s, ...),
// for a bridge's own `node:` table; `member` finds them in its options.
template <class Options>
parameters::Table<Options> process_parameters(std::function<BridgeProcessOptions&(Options&)> member) {
  namespace P = parameters;
  return {
      P::real<Options>("reopen_period_s", 0.01, 3600.0, "s", "between attempts to open a missing or hung-up device",
                       [member](Options& o) -> double& { return member(o).reopen_period_s; }),
      P::real<Options>("silence_warn_s", 0.0, 86400.0, "s",
                       "an open device that sends nothing this long is logged and counted (device_silences; 0: never)",
                       [member](Options& o) -> double& { return member(o).silence_warn_s; }),
      P::real<Options>("status_period_s", 0.0, 86400.0, "s", "counters to the log this often (0: only at exit)",
                       [member](Options& o) -> double& { return member(o).status_period_s; }),
      P::integer<Options, int>("wait_readers", 0, 100, "", "readers to wait for before the first message is "
                               "written (all of them: a later one misses the start); the device is read meanwhile",
                               [member](Options& o) -> int& { return member(o).wait_readers; }),
      P::real<Options>("wait_readers_timeout_s", 0.0, 3600.0, "s", "... at most this long after start, then publish anyway",
                       [member](Options& o) -> double& { return member(o).wait_readers_timeout_s; }),
  };
}

// The YAML scalars of the bridges' to_yaml() (config/yaml_text.h).
using config::yaml_number;
using config::yaml_quoted;

}  // namespace pixyslam::bridge
