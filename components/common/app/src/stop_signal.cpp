#include "pixyslam/app/stop_signal.h"

#include <pthread.h>
#include <signal.h>

#include <atomic>
#include <condition_variable>
#include <mutex>
#include <thread>

namespace pixyslam::app {

namespace {

// Never destroyed: the detached signal thread may still be notifying when the
// process exits and runs static destructors (TSan: cond destroyed while in use).
std::mutex& g_mutex = *new std::mutex;
std::condition_variable& g_cv = *new std::condition_variable;
std::atomic<bool> g_requested{false};
std::atomic<int> g_signal{0};
std::atomic<int> g_count{0};

void set_requested(int signal_number) {
  {
    std::lock_guard<std::mutex> lock(g_mutex);
    if (!g_requested) g_signal = signal_number;
    g_requested = true;
    if (signal_number != 0) ++g_count;
  }
  g_cv.notify_all();
}

}  // namespace

void StopSignal::install() {
  static std::once_flag once;
  std::call_once(once, [] {
    sigset_t set;
    sigemptyset(&set);
    sigaddset(&set, SIGINT);
    sigaddset(&set, SIGTERM);
    // A closed terminal or SSH session (SIGHUP) stops like Ctrl-C, unless the
    // process was started to ignore it (nohup): a blocked signal is never
    // discarded, so sigwait would see it.
    struct sigaction hup {};
    if (sigaction(SIGHUP, nullptr, &hup) != 0 || hup.sa_handler != SIG_IGN) sigaddset(&set, SIGHUP);
    pthread_sigmask(SIG_BLOCK, &set, nullptr);
    std::thread([set] {
      for (;;) {
        int number = 0;
        if (sigwait(&set, &number) == 0) set_requested(number);
      }
    }).detach();
  });
}

bool StopSignal::requested() { return g_requested.load(); }

bool StopSignal::wait_for(std::chrono::milliseconds timeout) {
  std::unique_lock<std::mutex> lock(g_mutex);
  return g_cv.wait_for(lock, timeout, [] { return g_requested.load(); });
}

void StopSignal::request() { set_requested(0); }

int StopSignal::signal_number() { return g_signal.load(); }

int StopSignal::signal_count() { return g_count.load(); }

}  // namespace pixyslam::app
