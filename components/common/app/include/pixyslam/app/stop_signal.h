#pragma once

#include <chrono>

namespace pixyslam::app {

// SIGINT/SIGTERM/SIGHUP as a flag a process can wait on (SIGHUP only when it
// is not ignored at install(), as under nohup). install() blocks the
// signals in the calling thread (call it first in main, before any thread
// starts, so every thread inherits the mask) and starts a watcher thread that
// sigwait()s for them. Process-wide; thread-safe after install().
class StopSignal {
 public:
  static void install();
  static bool requested();
  // Sleeps until a stop is requested or `timeout` passes; true if requested.
  static bool wait_for(std::chrono::milliseconds timeout);
  // Requests a stop as if a signal had come (e.g. a run that ends by itself).
  static void request();
  // The signal that requested the stop (0 if none or request()).
  static int signal_number();
  // How many stop signals arrived so far (a second one can mean "really stop").
  static int signal_count();
};

}  // namespace pixyslam::app
