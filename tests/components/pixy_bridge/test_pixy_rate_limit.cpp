// The pixy bridge's frame-rate limit (pixy::FrameRateLimiter) behind the block
// parser, driven the way PixyNode drives it: bytes arrive in chunks stamped
// with their arrival time, each frame the parser completes is offered at the
// time of the chunk that completed it. A sync-word flood and valid frames at
// 10 kHz are cut down to the configured rates and counted; a real camera's
// 50 Hz (with read jitter and bunched reads) loses nothing. The stamps of
// frames read in one chunk (bunched_frame_end_ns, FrameClock). And the options.
#include <cstdint>
#include <limits>
#include <optional>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "pixyslam/config/yaml_reader.h"
#include "pixyslam/pixy/frame_rate_limiter.h"
#include "pixyslam/pixy/frame_stamp.h"
#include "pixyslam/pixy/pixy_block_parser.h"
#include "pixyslam/pixy/pixy_options.h"

namespace pixyslam::pixy {
namespace {

constexpr std::uint64_t kBaseNs = 1700000000000000000ull;
constexpr std::uint64_t kSecondNs = 1000000000ull;

// {signature, x, y, width, height, angle_deg, colour_code}.
PixyBlock landmark_block() { return {012, 160, 100, 20, 42, -3, true}; }

// A parser and a limiter wired like PixyNode: every completed frame is offered
// at the arrival time of the chunk that completed it; warnings are collected.
struct Bridge {
  explicit Bridge(const FrameRateOptions& options = {}) : limiter(options) {}

  void feed(const std::vector<std::uint8_t>& chunk, std::uint64_t at_ns) {
    parser.feed(chunk.data(), chunk.size(), [&](PixyFrame&& frame) {
      if (limiter.admit(at_ns, frame.blocks.empty())) {
        ++published;
        if (frame.blocks.empty()) ++published_empty;
      }
    });
    if (std::optional<FrameRateWarning> w = limiter.take_warning(at_ns)) warnings.push_back(*w);
  }

  PixyBlockParser parser;
  FrameRateLimiter limiter;
  std::uint64_t published = 0;
  std::uint64_t published_empty = 0;
  std::vector<FrameRateWarning> warnings;
};

TEST(PixyRateLimit, SyncWordFloodPublishesAtMostTheCameraRate) {
  // Given "aa55 aa55 ..." at 1 MB/s for 5 s, read in 1 KiB chunks (every sync
  // word followed by another opens a frame: a frame without blocks per 2 bytes),
  const FrameRateOptions options;  // 50 Hz camera, at most 60 frames/s
  Bridge bridge(options);
  constexpr std::size_t kChunk = 1024;
  constexpr double kBytesPerS = 1e6;
  constexpr double kSeconds = 5.0;
  std::vector<std::uint8_t> chunk;
  for (std::size_t i = 0; i < kChunk / 2; ++i) {
    chunk.push_back(0x55);
    chunk.push_back(0xaa);
  }
  const auto chunks = static_cast<std::size_t>(kBytesPerS * kSeconds / kChunk);
  for (std::size_t i = 1; i <= chunks; ++i) {
    bridge.feed(chunk, kBaseNs + static_cast<std::uint64_t>(1e9 * static_cast<double>(i * kChunk) / kBytesPerS));
  }

  // then every byte was parsed into frames without blocks, and at most
  // frame_rate_hz * 5 s of them (plus the tolerance's burst) were published;
  // every other one was dropped and counted,
  const FrameRateCounters& c = bridge.limiter.counters();
  const std::uint64_t frames = bridge.parser.counters().frames;
  EXPECT_EQ(bridge.parser.counters().bytes_in, chunks * kChunk);
  EXPECT_GE(frames, chunks * kChunk / 2 - 2);
  EXPECT_EQ(c.frames, frames);
  EXPECT_EQ(c.empty_frames, frames);
  const auto most = static_cast<std::uint64_t>(options.frame_rate_hz * (kSeconds + options.tolerance_s)) + 1;
  EXPECT_LE(bridge.published, most);
  EXPECT_GE(bridge.published, static_cast<std::uint64_t>(options.frame_rate_hz * kSeconds) - 1);
  EXPECT_EQ(c.published, bridge.published);
  EXPECT_EQ(c.rate_limited, frames - bridge.published);
  EXPECT_EQ(c.empty_rate_limited, c.rate_limited);

  // and one warning (the flood's first second; the next is due 5 s later)
  // named the offered rate and the limits.
  ASSERT_EQ(bridge.warnings.size(), 1u);
  const FrameRateWarning& w = bridge.warnings[0];
  EXPECT_NEAR(w.frames_per_s, kBytesPerS / 2, kBytesPerS / 100);
  EXPECT_DOUBLE_EQ(w.empty_frames_per_s, w.frames_per_s);
  EXPECT_GT(w.dropped, 400000u);
  EXPECT_EQ(w.empty_dropped, w.dropped);
  const std::string text = w.text();
  EXPECT_NE(text.find("frames/s offered"), std::string::npos) << text;
  EXPECT_NE(text.find("50 Hz for frames without blocks (pixy.frame_rate_hz)"), std::string::npos) << text;
  EXPECT_NE(text.find("60 Hz for all frames (pixy.max_frame_rate_hz)"), std::string::npos) << text;
}

TEST(PixyRateLimit, ValidFramesAt10kHzAreLimitedToTheMaximumRate) {
  // Given valid one-block frames at 10 kHz for 5 s, each read on its own,
  const FrameRateOptions options;
  Bridge bridge(options);
  const std::vector<std::uint8_t> frame = encode_frame({landmark_block()});
  constexpr std::size_t kFrames = 50000;
  constexpr std::uint64_t kPeriodNs = kSecondNs / 10000;
  for (std::size_t i = 0; i < kFrames; ++i) bridge.feed(frame, kBaseNs + kPeriodNs * i);

  // then at most max_frame_rate_hz * 5 s were published (each frame is
  // complete when the next starts: the last one is still open),
  const FrameRateCounters& c = bridge.limiter.counters();
  EXPECT_EQ(bridge.parser.counters().frames, kFrames - 1);
  EXPECT_EQ(bridge.parser.counters().blocks_ok, kFrames);
  const double seconds = 1e-9 * static_cast<double>(kPeriodNs * (kFrames - 1));
  EXPECT_LE(bridge.published,
            static_cast<std::uint64_t>(options.max_frame_rate_hz * (seconds + options.tolerance_s)) + 1);
  EXPECT_GE(bridge.published, static_cast<std::uint64_t>(options.max_frame_rate_hz * seconds) - 1);
  EXPECT_EQ(bridge.published_empty, 0u);
  // the rest were dropped and counted,
  EXPECT_EQ(c.rate_limited, kFrames - 1 - bridge.published);
  EXPECT_EQ(c.empty_rate_limited, 0u);
  // and the warning named 10000 frames/s, none without blocks.
  ASSERT_EQ(bridge.warnings.size(), 1u);
  EXPECT_NEAR(bridge.warnings[0].frames_per_s, 10000.0, 1.0);
  EXPECT_EQ(bridge.warnings[0].empty_frames_per_s, 0.0);
  EXPECT_EQ(bridge.warnings[0].empty_dropped, 0u);
}

TEST(PixyRateLimit, WarnsAtMostOncePerPeriodWhileTheFloodLasts) {
  // Frames without blocks at 1 kHz for 60 s, one per read.
  FrameRateOptions options;
  Bridge bridge(options);
  const std::vector<std::uint8_t> empty_frame = {0x55, 0xaa};  // a lone frame-start sync
  std::uint64_t t = kBaseNs;
  for (int i = 0; i < 60000; ++i, t += kSecondNs / 1000) bridge.feed(empty_frame, t);
  // The first warning after the first second, then one every 5 s: 1 + 11.
  ASSERT_EQ(bridge.warnings.size(), 12u);
  EXPECT_EQ(bridge.limiter.counters().warnings, 12u);
  std::uint64_t dropped = 0;
  for (const FrameRateWarning& w : bridge.warnings) {
    EXPECT_NEAR(w.empty_frames_per_s, 1000.0, 1.0);
    dropped += w.dropped;
  }
  // The drops of the last 4 s are not reported yet: when the flood ends, they
  // are once the period is over, then nothing more.
  EXPECT_LT(dropped, bridge.limiter.counters().rate_limited);
  EXPECT_FALSE(bridge.limiter.take_warning(t + kSecondNs).has_value());
  const std::optional<FrameRateWarning> last = bridge.limiter.take_warning(t + 5 * kSecondNs);
  ASSERT_TRUE(last.has_value());
  EXPECT_EQ(dropped + last->dropped, bridge.limiter.counters().rate_limited);
  EXPECT_FALSE(bridge.limiter.take_warning(t + 60 * kSecondNs).has_value());
}

TEST(PixyRateLimit, NormalCameraInputIsUntouched) {
  // A 50 Hz camera for 10 min: a third of the frames without blocks, arrival
  // jitter of +-8 ms, and every 50th read late, so that two frames are parsed
  // from one chunk at the same time.
  Bridge bridge;
  std::mt19937 prng(7);
  std::uniform_int_distribution<int> jitter_us(-8000, 8000);
  constexpr std::size_t kFrames = 50 * 600;
  std::vector<std::uint8_t> pending;
  for (std::size_t i = 0; i < kFrames; ++i) {
    const std::vector<std::uint8_t> frame =
        encode_frame(i % 3 == 0 ? std::vector<PixyBlock>{} : std::vector<PixyBlock>{landmark_block()});
    pending.insert(pending.end(), frame.begin(), frame.end());
    if (i % 50 == 48) continue;  // read together with the next frame
    const auto at = static_cast<std::int64_t>(kBaseNs + i * (kSecondNs / 50)) + 1000 * jitter_us(prng);
    bridge.feed(pending, static_cast<std::uint64_t>(at));
    pending.clear();
  }
  const FrameRateCounters& c = bridge.limiter.counters();
  EXPECT_EQ(c.frames, kFrames - 1);  // the last frame is still open
  EXPECT_EQ(c.rate_limited, 0u);
  EXPECT_EQ(bridge.published, kFrames - 1);
  EXPECT_TRUE(bridge.warnings.empty());

  // Only frames without blocks at exactly the camera rate: all published too.
  Bridge empty_only;
  const std::vector<std::uint8_t> empty_frame = {0x55, 0xaa};
  for (std::size_t i = 0; i < kFrames; ++i) {
    const auto at = static_cast<std::int64_t>(kBaseNs + i * (kSecondNs / 50)) + 1000 * jitter_us(prng);
    empty_only.feed(empty_frame, static_cast<std::uint64_t>(at));
  }
  // (a lone sync opens a frame only once the next word is read: the last two are not delivered)
  EXPECT_EQ(empty_only.limiter.counters().frames, kFrames - 2);
  EXPECT_EQ(empty_only.limiter.counters().rate_limited, 0u);
  EXPECT_EQ(empty_only.published, kFrames - 2);
  EXPECT_TRUE(empty_only.warnings.empty());
}

TEST(PixyRateLimit, EmptyFramesUseUpBothLimitsAndAClockStepRestartsThem) {
  // A frame without blocks uses up room in both limits; frames with blocks
  // may still come up to max_frame_rate_hz.
  FrameRateOptions options;
  options.frame_rate_hz = 10.0;
  options.max_frame_rate_hz = 20.0;
  options.tolerance_s = 0.0;
  FrameRateLimiter limiter(options);
  std::uint64_t t = kBaseNs;
  EXPECT_TRUE(limiter.admit(t, true));
  EXPECT_FALSE(limiter.admit(t + kSecondNs / 20, true));  // 20 Hz of empty frames: over 10 Hz
  EXPECT_TRUE(limiter.admit(t + kSecondNs / 20, false));  // but a frame with blocks passes
  EXPECT_FALSE(limiter.admit(t + kSecondNs / 20 + 1, false));
  t += kSecondNs / 10;
  EXPECT_TRUE(limiter.admit(t, true));
  // The host clock steps back an hour: the schedule restarts there.
  EXPECT_TRUE(limiter.admit(t - 3600 * kSecondNs, false));
  EXPECT_EQ(limiter.counters().clock_steps_back, 1u);
  EXPECT_EQ(limiter.counters().rate_limited, 2u);
  EXPECT_EQ(limiter.counters().empty_rate_limited, 1u);
}

// ---------------------------------------------------------------- options

PixyOptions read(const std::string& extra) {
  auto root = config::YamlReader::from_string(
      "pixy:\n  landmark_height_m: 0.08\n" + extra + "  landmarks:\n    \"12\": 1\n", "test.yaml");
  config::YamlReader pixy = root.child("pixy");
  return read_pixy_options(pixy);
}

std::string error_of(const std::string& extra) {
  try {
    read(extra);
  } catch (const config::ConfigError& e) {
    return e.what();
  }
  return "(no error)";
}

TEST(PixyRateLimitOptions, DefaultsFollowTheCameraRate) {
  const PixyOptions d = read("");
  EXPECT_DOUBLE_EQ(d.rate.frame_rate_hz, 50.0);
  EXPECT_DOUBLE_EQ(d.rate.max_frame_rate_hz, 60.0);
  EXPECT_DOUBLE_EQ(d.rate.tolerance_s, 0.5);
  const PixyOptions sixty = read("  frame_rate_hz: 60\n");
  EXPECT_DOUBLE_EQ(sixty.rate.max_frame_rate_hz, 72.0);  // 1.2 x the camera's rate unless set
  const PixyOptions set = read("  frame_rate_hz: 30\n  max_frame_rate_hz: 31\n  frame_rate_tolerance_s: 0\n");
  EXPECT_DOUBLE_EQ(set.rate.frame_rate_hz, 30.0);
  EXPECT_DOUBLE_EQ(set.rate.max_frame_rate_hz, 31.0);
  EXPECT_DOUBLE_EQ(set.rate.tolerance_s, 0.0);
}

TEST(PixyRateLimitOptions, BadRatesAreNamed) {
  EXPECT_NE(error_of("  frame_rate_hz: 0\n").find("test.yaml: key 'pixy.frame_rate_hz': value 0"),
            std::string::npos);
  EXPECT_NE(error_of("  frame_rate_hz: 5000\n").find("key 'pixy.frame_rate_hz'"), std::string::npos);
  EXPECT_NE(error_of("  max_frame_rate_hz: fast\n").find("key 'pixy.max_frame_rate_hz'"), std::string::npos);
  const std::string below = error_of("  frame_rate_hz: 50\n  max_frame_rate_hz: 40\n");
  EXPECT_NE(below.find("test.yaml: key 'pixy.max_frame_rate_hz': value 40 is below frame_rate_hz (50)"),
            std::string::npos)
      << below;
  EXPECT_NE(error_of("  frame_rate_tolerance_s: -1\n").find("key 'pixy.frame_rate_tolerance_s'"),
            std::string::npos);

  // The limiter checks options built in code the same way.
  FrameRateOptions bad;
  bad.frame_rate_hz = 0.0;
  EXPECT_THROW(FrameRateLimiter{bad}, std::invalid_argument);
  try {
    bad = FrameRateOptions{};
    bad.max_frame_rate_hz = 10.0;
    validate(bad);
    ADD_FAILURE() << "expected invalid_argument";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("pixy.max_frame_rate_hz: value 10 is below frame_rate_hz (50)"),
              std::string::npos)
        << e.what();
  }
  bad = FrameRateOptions{};
  bad.tolerance_s = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(validate(bad), std::invalid_argument);
}

// ---------------------------------------------------------------- frames read in one chunk

constexpr std::uint64_t kPeriodNs = 20000000ull;  // 50 Hz

TEST(BunchedFrameEnd, FramesReadTogetherAreSpreadBackByTheFramePeriod) {
  // Given a chunk read 0.2 s after the previous one (the reader was unscheduled),
  const std::uint64_t previous = kBaseNs, read = kBaseNs + 10 * kPeriodNs;
  // the frame still open at its end ended at the read, and each earlier one a
  // frame period before the next.
  EXPECT_EQ(bunched_frame_end_ns(read, previous, 0, kPeriodNs), read);
  for (std::uint64_t k = 1; k < 10; ++k) {
    EXPECT_EQ(bunched_frame_end_ns(read, previous, k, kPeriodNs), read - k * kPeriodNs);
  }
  // More frames than periods since the previous read (a flood, or a camera
  // faster than the period): they ended after the previous read (the earliest
  // time), so they pile up there, never earlier, and nothing overflows.
  EXPECT_EQ(bunched_frame_end_ns(read, previous, 10, kPeriodNs), previous);
  EXPECT_EQ(bunched_frame_end_ns(read, previous, 1000000, kPeriodNs), previous);
  EXPECT_EQ(bunched_frame_end_ns(read, previous, ~0ull, ~0ull), previous);
}

TEST(BunchedFrameEnd, ChunksReadPromptlyKeepTheirReadTimes) {
  // Read every 2 ms, a frame completed by the next one's start ended within
  // the last read interval: the stamp moves by at most that interval.
  const std::uint64_t previous = kBaseNs, read = kBaseNs + 2000000ull;
  EXPECT_EQ(bunched_frame_end_ns(read, previous, 1, kPeriodNs), previous);
  EXPECT_EQ(bunched_frame_end_ns(read, previous, 0, kPeriodNs), read);
  // A host clock that stepped back (the earliest time after the read).
  EXPECT_EQ(bunched_frame_end_ns(previous, read, 3, kPeriodNs), previous);
}

TEST(FramePeriodEstimate, MeasuresASlowerCameraAndIgnoresSkippedFrames) {
  // A camera at 10 Hz behind a 50 Hz limit: the fastest period until 8
  // intervals are in,
  FramePeriodEstimate period(50.0);
  EXPECT_EQ(period.period_ns(), kPeriodNs);
  std::mt19937 rng(7);
  std::uniform_int_distribution<std::uint64_t> jitter(0, 4000000);  // read jitter up to 4 ms
  for (int i = 0; i < 7; ++i) period.add_interval_ns(100000000ull + jitter(rng));
  EXPECT_EQ(period.period_ns(), kPeriodNs);
  // then the camera's period within the read jitter, also when one frame in
  // five was not sent (an interval of two periods) and after silences (left out),
  for (int i = 0; i < 100; ++i) {
    period.add_interval_ns((i % 5 == 4 ? 200000000ull : 100000000ull) + jitter(rng));
    if (i % 20 == 0) period.add_interval_ns(30000000000ull);
  }
  EXPECT_GE(period.period_ns(), 100000000ull);
  EXPECT_LE(period.period_ns(), 104000000ull);
  // and never faster than the camera can go.
  for (int i = 0; i < 40; ++i) period.add_interval_ns(1000000ull);
  EXPECT_EQ(period.period_ns(), kPeriodNs);
}

// A FrameClock fed frames 0..9 at 10 Hz, each read alone (measured).
constexpr std::uint64_t kCameraNs = 100000000ull;  // 10 Hz
std::uint64_t sent_ns(std::uint64_t i) { return kBaseNs + kCameraNs * i; }
FrameClock clock_after_ten_frames() {
  FrameClock clock(50.0);
  for (std::uint64_t i = 0; i < 10; ++i) EXPECT_EQ(clock.measured(i, sent_ns(i)), sent_ns(i));
  return clock;
}

TEST(FrameClock, PlacesBunchedFramesInTheCamerasPhase) {
  // Given the camera's period measured on frames read alone,
  FrameClock clock = clock_after_ten_frames();
  EXPECT_EQ(clock.period_ns(), kCameraNs);
  // frames 10..14 read in one chunk 70 ms after frame 14 was sent (the
  // previous read was frame 9's) are placed where the camera sent them, not a
  // period apart back from the read (70 ms late each),
  const std::uint64_t read = sent_ns(14) + 70000000ull;
  for (std::uint64_t i = 10; i < 14; ++i) EXPECT_EQ(clock.bunched(i, read, sent_ns(9), 14 - i), sent_ns(i)) << i;
  // and so is the frame the chunk left open.
  EXPECT_EQ(clock.bunched(14, read, sent_ns(9), 0), sent_ns(14));
}

TEST(FrameClock, AFrameTheCameraDidNotSendFallsBackToTheReadAndStaysWithinAPeriod) {
  // Given the camera's period measured, then frames 10..14 sent at periods
  // 10, 11, 13, 14, 15 (it saw nothing at 12) and read in one chunk at the
  // last one's time,
  FrameClock clock = clock_after_ten_frames();
  const std::uint64_t truth[] = {sent_ns(10), sent_ns(11), sent_ns(13), sent_ns(14), sent_ns(15)};
  const std::uint64_t read = sent_ns(15);
  std::uint64_t previous = sent_ns(9);
  for (std::uint64_t k = 0; k < 5; ++k) {
    const std::uint64_t t = clock.bunched(10 + k, read, sent_ns(9), 4 - k);
    // each stamp is at most a period after the truth (the forward guess would
    // put the frames after the gap a period early), in order.
    EXPECT_GE(t, truth[k]) << k;
    EXPECT_LE(t, truth[k] + kCameraNs) << k;
    EXPECT_GT(t, previous) << k;
    previous = t;
  }
}

TEST(FrameClock, AfterASilenceTheLastMeasurementDoesNotPullFramesBack) {
  // Given a camera silent for 5 s after frame 9 (it saw nothing), whose next
  // three frames come in one chunk,
  FrameClock clock = clock_after_ten_frames();
  const std::uint64_t read = sent_ns(60);
  // they are placed back from the read, not after frame 9.
  EXPECT_EQ(clock.bunched(10, read, sent_ns(9), 2), sent_ns(58));
  EXPECT_EQ(clock.bunched(11, read, sent_ns(9), 1), sent_ns(59));
  EXPECT_EQ(clock.bunched(12, read, sent_ns(9), 0), sent_ns(60));
  // Estimated frames do not measure the period: it stays 100 ms.
  EXPECT_EQ(clock.estimated(sent_ns(61) + 1), sent_ns(61) + 1);
  clock.measured(14, sent_ns(61) + 2);  // 1 ns after frame 13: no interval measured
  EXPECT_EQ(clock.period_ns(), kCameraNs);
}

}  // namespace
}  // namespace pixyslam::pixy
