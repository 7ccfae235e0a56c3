// The encoder bridge's pure path from parsed Arduino messages to fixed-rate
// odometry: the Arduino clock mapping (ArduinoClock) and OdometryStream
// (stamps, resampling, the "no data" periods of a stalled link), times passed in.
#include <cmath>
#include <cstdint>
#include <vector>

#include <gtest/gtest.h>

#include "pixyslam/encoder/arduino_clock.h"
#include "pixyslam/encoder/odometry_stream.h"

namespace pixyslam::encoder {
namespace {

constexpr std::int64_t kMs = 1000000;  // ns

// ---------------------------------------------------------------- ArduinoClock

TEST(ArduinoClock, TheLeastDelayedSampleSetsTheOffset) {
  ArduinoClock clock(1.0);
  const std::int64_t base = 5000 * kMs;  // host time of Arduino time 0
  // Delays 5, 2, 7, 3 ms: each sample maps to its Arduino time + base + the
  // smallest delay seen so far.
  EXPECT_EQ(clock.to_host_ns(0, base + 5 * kMs), base + 5 * kMs);
  EXPECT_EQ(clock.to_host_ns(20000, base + 20 * kMs + 2 * kMs), base + 22 * kMs);
  EXPECT_EQ(clock.to_host_ns(40000, base + 40 * kMs + 7 * kMs), base + 42 * kMs);
  EXPECT_EQ(clock.last_excess_delay_ns(), 5 * kMs);
  EXPECT_EQ(clock.to_host_ns(60000, base + 60 * kMs + 3 * kMs), base + 62 * kMs);
  EXPECT_EQ(clock.offset_ns(), base + 2 * kMs);
}

TEST(ArduinoClock, AnOldMinimumLeavesWithTheWindow) {
  ArduinoClock clock(0.1);  // 100 ms of Arduino time
  const std::int64_t base = 1000 * kMs;
  clock.to_host_ns(0, base + 1 * kMs);  // a lucky 1 ms sample
  for (std::uint32_t t_us = 20000; t_us <= 100000; t_us += 20000) {
    EXPECT_EQ(clock.to_host_ns(t_us, base + t_us * 1000 + 4 * kMs), base + t_us * 1000 + 1 * kMs);
  }
  // 120 ms: the 1 ms sample is older than the window; 4 ms is the new floor.
  EXPECT_EQ(clock.to_host_ns(120000, base + 124 * kMs), base + 124 * kMs);
}

TEST(ArduinoClock, MicrosWrapIsSeamless) {
  ArduinoClock clock(1.0);
  const std::uint32_t before_wrap = 0xffffffffu - 9999u;  // 10 ms before the wrap
  const std::int64_t host = 7000 * kMs;
  EXPECT_EQ(clock.to_host_ns(before_wrap, host), host);
  // 20 ms later the counter reads 10000 us after the wrap.
  EXPECT_EQ(clock.to_host_ns(10000u, host + 20 * kMs + 3 * kMs), host + 20 * kMs);
  EXPECT_EQ(clock.counters().jumps, 0u);
}

TEST(ArduinoClock, AResetWithoutRstStartsOver) {
  ArduinoClock clock(1.0);
  const std::int64_t host = 9000 * kMs;
  clock.to_host_ns(3000000, host);  // 3 s after boot
  clock.to_host_ns(3020000, host + 20 * kMs);
  // The Arduino rebooted: its clock reads 5 ms. A step back: history dropped,
  // the sample maps to its own receive time.
  EXPECT_EQ(clock.to_host_ns(5000, host + 900 * kMs), host + 900 * kMs);
  EXPECT_EQ(clock.counters().jumps, 1u);
  EXPECT_EQ(clock.to_host_ns(25000, host + 921 * kMs), host + 920 * kMs);
}

TEST(ArduinoClock, RestartForgetsTheHistory) {
  ArduinoClock clock(1.0);
  clock.to_host_ns(0, 100 * kMs);
  clock.restart();
  EXPECT_EQ(clock.to_host_ns(20000, 150 * kMs), 150 * kMs);  // not 120 ms
  EXPECT_EQ(clock.counters().restarts, 1u);
}


// ---------------------------------------------------------------- OdometryStream

constexpr std::uint64_t kEpoch = 1700000000000000000ull;  // a whole second, ns

// Samples every 20 ms at constant wheel speed (ticks per sample) from t = 0
// (Arduino micros from 1 s), read 2 ms after they were stamped.
struct Driver {
  OdometryStream stream{EncoderOptions{}, 1.0};
  std::vector<StreamOutput> out;
  std::uint32_t seq = 0;
  std::int32_t ticks = 0;

  void sample_at(double t_s, std::int32_t ticks_per_sample) {
    ticks += ticks_per_sample;
    const auto arduino_us = static_cast<std::uint32_t>(1000000 + t_s * 1e6);
    const auto receive = kEpoch + static_cast<std::uint64_t>(t_s * 1e9) + 2 * kMs;
    stream.add_sample({seq++, arduino_us, ticks, ticks}, receive, [&](const StreamOutput& o) { out.push_back(o); });
  }
  void poll_at(double t_s) {
    stream.poll(kEpoch + static_cast<std::uint64_t>(t_s * 1e9), [&](const StreamOutput& o) { out.push_back(o); });
  }
};

TEST(OdometryStream, PeriodsAtThePublishRateStampedFromTheFirstWholeSecond) {
  Driver d;
  for (int i = 0; i <= 50; ++i) d.sample_at(0.02 * i, 10);  // 1 s of samples
  ASSERT_GE(d.out.size(), 9u);
  for (std::size_t i = 0; i < d.out.size(); ++i) {
    EXPECT_EQ(d.out[i].epoch_ns, kEpoch);
    EXPECT_NEAR(d.out[i].odometry.duration_s, 0.1, 1e-9);
    if (i > 0) {
      EXPECT_NEAR(d.out[i].odometry.t_s - d.out[i - 1].odometry.t_s, 0.1, 1e-9);
    }
    EXPECT_GT(d.out[i].odometry.v_mps, 0.0);
  }
  // Every sample before the last period's end is counted once: five per period.
  EXPECT_EQ(d.out[3].samples, 5u);
  EXPECT_EQ(d.stream.empty_periods(), 0u);
}

TEST(OdometryStream, AStalledLinkKeepsTheRateWithNoDataPeriods) {
  Driver d;
  for (int i = 0; i <= 25; ++i) d.sample_at(0.02 * i, 10);  // samples up to 0.5 s
  const std::size_t before = d.out.size();
  // Within max_sample_gap_s (0.5 s) of the last sample: nothing is closed.
  d.poll_at(0.9);
  EXPECT_EQ(d.out.size(), before);
  // Later: one period per poll at most, up to max_sample_gap_s ago.
  d.poll_at(1.3);
  d.poll_at(1.4);
  d.poll_at(1.5);
  ASSERT_GT(d.out.size(), before);
  EXPECT_LE(d.out.size() - before, 3u + 1u);
  for (std::size_t i = before + 1; i < d.out.size(); ++i) {
    EXPECT_EQ(d.out[i].samples, 0u);
    EXPECT_EQ(d.out[i].odometry.v_mps, 0.0);
    EXPECT_LE(d.out[i].odometry.t_s + d.out[i].odometry.duration_s, 1.5 - 0.5 + 1e-9);
  }
  EXPECT_GT(d.stream.empty_periods(), 0u);
  // Samples again: the periods go on from where the stall left them.
  const double last_end = d.out.back().odometry.t_s + d.out.back().odometry.duration_s;
  for (int i = 0; i <= 20; ++i) d.sample_at(1.6 + 0.02 * i, 10);
  EXPECT_NEAR(d.out.back().odometry.t_s - last_end, 0.1 * std::round((d.out.back().odometry.t_s - last_end) / 0.1), 1e-6);
  EXPECT_GT(d.out.back().odometry.v_mps, 0.0);
}

// An Arduino that repeats one line (same seq) has stalled: the repeats hold
// off neither the "no data" periods nor pile up as sample times.
TEST(OdometryStream, ARepeatedLineIsAStallNotAStreamOfSamples) {
  Driver d;
  for (int i = 0; i <= 25; ++i) d.sample_at(0.02 * i, 10);  // samples up to 0.5 s
  const std::size_t before = d.out.size();
  const std::uint32_t repeated_seq = d.seq - 1;
  for (int k = 1; k <= 100; ++k) {  // the last line again, read every 20 ms up to 2.5 s
    const auto receive = kEpoch + static_cast<std::uint64_t>((0.5 + 0.02 * k) * 1e9) + 2 * kMs;
    d.stream.add_sample({repeated_seq, 1500000, d.ticks, d.ticks}, receive,
                        [&](const StreamOutput& o) { d.out.push_back(o); });
    if (k % 5 == 0) d.poll_at(0.5 + 0.02 * k);
  }
  ASSERT_GT(d.out.size(), before + 10);  // the periods went on as "no data"
  for (std::size_t i = before + 1; i < d.out.size(); ++i) EXPECT_EQ(d.out[i].samples, 0u) << i;
  EXPECT_EQ(d.stream.wheel_counters().duplicates, 100u);
}

TEST(OdometryStream, NoPollOutputBeforeTheFirstSample) {
  Driver d;
  d.poll_at(10.0);
  EXPECT_TRUE(d.out.empty());
}

TEST(OdometryStream, AResetRestartsTheClockEstimate) {
  Driver d;
  d.sample_at(0.0, 10);
  d.sample_at(0.02, 10);
  d.stream.reset({"sim-1", 1320});
  EXPECT_EQ(d.stream.clock().counters().restarts, 1u);
  d.stream.restart_clock();
  EXPECT_EQ(d.stream.clock().counters().restarts, 2u);
}

}  // namespace
}  // namespace pixyslam::encoder
