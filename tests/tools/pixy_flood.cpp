// pixy_flood: plays a hostile Pixy on a pseudo-terminal, for measuring what the
// pixy bridge does with a flood (tests/pixy_flood_measure.sh, docs/robustness.md).
//   pixy_flood LINK sync|frames RATE SECONDS [START_DELAY_S]
// Creates a pty with a symbolic link at LINK (open it with pixy_bridge --device
// LINK), waits START_DELAY_S (default 0), then for SECONDS writes
//   sync:   the sync word 0xaa55 over and over (a frame without blocks every
//           2 bytes), RATE bytes per second;
//   frames: valid one-block frames of colour code "12" (landmark 1 in
//           config/pixy_bridge.yaml), RATE frames per second;
// in slices every 10 ms (one frame per write below 100 frames/s). Bytes the
// reader does not take within 1 ms are dropped (PseudoTerminal's drop policy),
// as a UART overwrites what nobody reads. Then keeps the pty open for 1 s (the
// reader takes what is queued) and prints the bytes offered, written and
// dropped; exit status 2 for a usage error.
#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <exception>
#include <string>
#include <thread>
#include <vector>

#include "pixyslam/app/cli.h"
#include "pixyslam/pixy/pixy_block_parser.h"
#include "pixyslam/serial/pseudo_terminal.h"

int main(int argc, char** argv) {
  using namespace pixyslam;
  using Clock = std::chrono::steady_clock;
  std::string link, pattern;
  double rate = 0.0, seconds = 0.0, delay_s = 0.0;
  app::Cli cli{"pixy_flood", "Plays a hostile Pixy on a pty linked at LINK: the sync word at RATE bytes/s (sync) or "
                             "valid one-block frames at RATE frames/s (frames) for SECONDS."};
  cli.option("link", link, "the pty's symbolic link").required().type("LINK");
  cli.option("pattern", pattern, "what to write").required().choices({"sync", "frames"});
  cli.option("rate", rate, "bytes/s (sync) or frames/s (frames)").required().positive().type("RATE");
  cli.option("seconds", seconds, "how long").required().positive().type("SECONDS");
  cli.option("start_delay", delay_s, "seconds before the first byte (default 0)").non_negative().type("START_DELAY_S");
  if (const auto done = cli.parse(argc, argv)) return *done;
  try {
    // One write's bytes and how many of them a second.
    std::vector<std::uint8_t> unit;
    double units_per_s = 0.0;
    if (pattern == "sync") {
      const std::size_t words = std::max<std::size_t>(1, static_cast<std::size_t>(rate / 200.0));  // 10 ms
      for (std::size_t i = 0; i < words; ++i) {
        unit.push_back(0x55);
        unit.push_back(0xaa);
      }
      units_per_s = rate / static_cast<double>(unit.size());
    } else {
      // {signature, x, y, width, height, angle_deg, colour_code}: a landmark of the shipped map.
      const pixy::PixyBlock b{012, 160, 100, 20, 42, -3, true};
      const std::vector<std::uint8_t> frame = pixy::encode_frame({b});
      const std::size_t per_write = rate < 100.0 ? 1 : static_cast<std::size_t>(rate / 100.0);
      for (std::size_t i = 0; i < per_write; ++i) unit.insert(unit.end(), frame.begin(), frame.end());
      units_per_s = rate / static_cast<double>(per_write);
    }

    serial::PseudoTerminal pty(link, std::chrono::milliseconds(1));
    std::printf("pixy_flood: %s -> %s\n", link.c_str(), pty.slave_path().c_str());
    std::fflush(stdout);
    std::this_thread::sleep_for(std::chrono::duration<double>(delay_s));

    const Clock::time_point start = Clock::now();
    const auto period = std::chrono::duration<double>(1.0 / units_per_s);
    std::uint64_t offered = 0;
    for (std::uint64_t n = 0;; ++n) {
      const Clock::time_point due =
          start + std::chrono::duration_cast<Clock::duration>(period * static_cast<double>(n));
      if (due - start >= std::chrono::duration<double>(seconds)) break;
      std::this_thread::sleep_until(due);
      pty.write_all(unit);
      offered += unit.size();
    }
    const double elapsed = std::chrono::duration<double>(Clock::now() - start).count();
    std::this_thread::sleep_for(std::chrono::seconds(1));
    const serial::PseudoTerminalCounters& c = pty.counters();
    std::printf("pixy_flood: %s for %.2f s: offered %llu bytes (%.1f kB/s), written %llu (%.1f kB/s), dropped %llu\n",
                pattern.c_str(), elapsed, static_cast<unsigned long long>(offered), 1e-3 * offered / elapsed,
                static_cast<unsigned long long>(c.written_bytes), 1e-3 * c.written_bytes / elapsed,
                static_cast<unsigned long long>(c.dropped_bytes));
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "pixy_flood: %s\n", e.what());
    return 1;
  }
}
