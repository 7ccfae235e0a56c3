// link_emulator: an Ethernet link with packet loss and delay between two
// network namespaces, for tests on kernels without sch_netem (tc netem).
// It creates a TAP device in each namespace and forwards every frame from one
// to the other, dropping each with probability `loss` and holding the rest for
// `delay_ms` (FIFO per direction), by a schedule of phases:
//   link_emulator --a NETNS:DEV --b NETNS:DEV [--seed S] [--schedule T:LOSS:DELAY_MS,...]
// e.g. --schedule 0:0:0,10:0.1:0,20:0.3:0,30:0:100 (from 10 s 10 % loss, ...).
// NETNS is a name under /run/netns. Prints "ready" once both devices exist
// (they are down: the caller configures them), and per phase and direction the
// frames forwarded and dropped when stopped (SIGINT/SIGTERM). Needs root.
#include <fcntl.h>
#include <linux/if.h>
#include <linux/if_tun.h>
#include <poll.h>
#include <sched.h>
#include <sys/ioctl.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <deque>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "pixyslam/app/cli.h"

namespace {

using Clock = std::chrono::steady_clock;

struct Phase {
  double start_s = 0.0;
  double loss = 0.0;
  double delay_ms = 0.0;
  std::uint64_t forwarded[2] = {0, 0};
  std::uint64_t dropped[2] = {0, 0};
};

struct Frame {
  Clock::time_point release;
  std::vector<std::uint8_t> bytes;
};

std::atomic<bool> g_stop{false};

[[noreturn]] void fail(const std::string& what) {
  throw std::runtime_error(what + (errno ? std::string(": ") + std::strerror(errno) : ""));
}

// A TAP device `dev` created in network namespace `netns` (/run/netns/NAME).
int open_tap(const std::string& netns, const std::string& dev) {
  const int here = ::open("/proc/self/ns/net", O_RDONLY | O_CLOEXEC);
  const int there = ::open(("/run/netns/" + netns).c_str(), O_RDONLY | O_CLOEXEC);
  if (here < 0 || there < 0) fail("cannot open network namespace '" + netns + "'");
  if (::setns(there, CLONE_NEWNET) != 0) fail("setns to '" + netns + "'");
  const int fd = ::open("/dev/net/tun", O_RDWR | O_CLOEXEC | O_NONBLOCK);
  if (fd < 0) fail("/dev/net/tun");
  ifreq request{};
  request.ifr_flags = IFF_TAP | IFF_NO_PI;
  std::strncpy(request.ifr_name, dev.c_str(), IFNAMSIZ - 1);
  if (::ioctl(fd, TUNSETIFF, &request) != 0) fail("TUNSETIFF '" + dev + "' in '" + netns + "'");
  if (::setns(here, CLONE_NEWNET) != 0) fail("setns back");
  ::close(here);
  ::close(there);
  return fd;
}

std::pair<std::string, std::string> split_endpoint(const std::string& text) {
  const std::size_t colon = text.find(':');
  if (colon == std::string::npos || colon == 0 || colon + 1 == text.size()) {
    throw std::invalid_argument("'" + text + "': want NETNS:DEV");
  }
  return {text.substr(0, colon), text.substr(colon + 1)};
}

std::vector<Phase> parse_schedule(const std::string& text) {
  std::vector<Phase> phases;
  std::size_t begin = 0;
  while (begin <= text.size()) {
    const std::size_t end = std::min(text.find(',', begin), text.size());
    Phase p;
    char extra = 0;
    if (std::sscanf(text.substr(begin, end - begin).c_str(), "%lf:%lf:%lf%c", &p.start_s, &p.loss, &p.delay_ms,
                    &extra) != 3 ||
        p.loss < 0.0 || p.loss > 1.0 || p.delay_ms < 0.0 || p.delay_ms > 10000.0 ||
        (!phases.empty() && p.start_s <= phases.back().start_s)) {
      throw std::invalid_argument("--schedule: '" + text.substr(begin, end - begin) +
                                  "': want T:LOSS:DELAY_MS, T increasing, LOSS in [0, 1]");
    }
    phases.push_back(p);
    begin = end + 1;
  }
  if (phases.empty() || phases.front().start_s != 0.0) throw std::invalid_argument("--schedule must start at 0");
  return phases;
}

}  // namespace

int main(int argc, char** argv) {
  std::string a, b, schedule = "0:0:0";
  std::uint64_t seed = 1;
  pixyslam::app::Cli cli{"link_emulator", "Forwards frames between two TAP devices with scheduled loss and delay."};
  cli.option("--a", a, "one end").required().type("NETNS:DEV");
  cli.option("--b", b, "the other end").required().type("NETNS:DEV");
  cli.option("--schedule", schedule, "from T seconds on, drop LOSS of the frames and delay them DELAY_MS")
      .type("T:LOSS:DELAY_MS,...");
  cli.option("--seed", seed, "random seed of the losses").seed().type("S");
  if (const auto done = cli.parse(argc, argv)) return *done;
  try {
    std::vector<Phase> phases = parse_schedule(schedule);
    const auto [netns_a, dev_a] = split_endpoint(a);
    const auto [netns_b, dev_b] = split_endpoint(b);
    const int fds[2] = {open_tap(netns_a, dev_a), open_tap(netns_b, dev_b)};
    std::signal(SIGINT, [](int) { g_stop = true; });
    std::signal(SIGTERM, [](int) { g_stop = true; });
    std::printf("ready\n");
    std::fflush(stdout);

    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> uniform(0.0, 1.0);
    std::deque<Frame> queues[2];  // queues[d]: frames read from fds[d], to write to fds[1 - d]
    std::vector<std::uint8_t> buffer(65536);
    const Clock::time_point start = Clock::now();
    std::size_t phase = 0;
    while (!g_stop) {
      const Clock::time_point now = Clock::now();
      const double t = std::chrono::duration<double>(now - start).count();
      while (phase + 1 < phases.size() && t >= phases[phase + 1].start_s) ++phase;
      Phase& p = phases[phase];
      for (int d = 0; d < 2; ++d) {
        while (!queues[d].empty() && queues[d].front().release <= now) {
          // A device that is down refuses the write: the frame is lost, as on a cut cable.
          const Frame& f = queues[d].front();
          if (::write(fds[1 - d], f.bytes.data(), f.bytes.size()) < 0) ++p.dropped[d];
          queues[d].pop_front();
        }
      }
      int timeout_ms = 50;
      for (const auto& q : queues) {
        if (q.empty()) continue;
        const auto wait = std::chrono::duration_cast<std::chrono::milliseconds>(q.front().release - now).count();
        timeout_ms = std::max(0, std::min<int>(timeout_ms, static_cast<int>(wait)));
      }
      pollfd polls[2] = {{fds[0], POLLIN, 0}, {fds[1], POLLIN, 0}};
      if (::poll(polls, 2, timeout_ms) < 0) {
        if (errno == EINTR) continue;
        fail("poll");
      }
      for (int d = 0; d < 2; ++d) {
        if (!(polls[d].revents & POLLIN)) continue;
        const ssize_t n = ::read(fds[d], buffer.data(), buffer.size());
        if (n <= 0) continue;
        if (uniform(rng) < p.loss) {
          ++p.dropped[d];
          continue;
        }
        ++p.forwarded[d];
        const auto delay = std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(p.delay_ms * 1e-3));
        queues[d].push_back({Clock::now() + delay, std::vector<std::uint8_t>(buffer.begin(), buffer.begin() + n)});
      }
    }
    for (const Phase& p : phases) {
      std::printf("phase from %.0f s (loss %.0f %%, delay %.0f ms): a->b forwarded %llu dropped %llu, "
                  "b->a forwarded %llu dropped %llu\n",
                  p.start_s, p.loss * 100.0, p.delay_ms, static_cast<unsigned long long>(p.forwarded[0]),
                  static_cast<unsigned long long>(p.dropped[0]), static_cast<unsigned long long>(p.forwarded[1]),
                  static_cast<unsigned long long>(p.dropped[1]));
    }
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "link_emulator: %s\n", e.what());
    return 2;
  }
}
