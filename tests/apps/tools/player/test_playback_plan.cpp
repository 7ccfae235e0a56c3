// The player's timing plan: which messages a pass plays and when.
#include <gtest/gtest.h>

#include <cstdint>
#include <limits>
#include <stdexcept>
#include <vector>

#include "pixyslam/player/playback_plan.h"

namespace {

using pixyslam::player::PlaybackOptions;
using pixyslam::player::plan_pass;

constexpr std::uint64_t kStart = 1700000000000000000ull;  // a realistic epoch stamp
constexpr std::uint64_t kMs = 1000000;

// Messages every 100 ms for 1 s (11 of them), all selected.
std::vector<std::uint64_t> ten_hz() {
  std::vector<std::uint64_t> t;
  for (int i = 0; i <= 10; ++i) t.push_back(kStart + static_cast<std::uint64_t>(i) * 100 * kMs);
  return t;
}

std::vector<std::int64_t> due_ms(const pixyslam::player::PlaybackPass& pass) {
  std::vector<std::int64_t> out;
  for (const auto& m : pass.messages) out.push_back(m.due_ns / static_cast<std::int64_t>(kMs));
  return out;
}

TEST(PlaybackPlan, KeepsTheRecordedTimingAtRateOne) {
  const auto times = ten_hz();
  const auto pass = plan_pass(times, std::vector<bool>(times.size(), true), kStart, {});
  ASSERT_EQ(pass.messages.size(), 11u);
  EXPECT_EQ(due_ms(pass), (std::vector<std::int64_t>{0, 100, 200, 300, 400, 500, 600, 700, 800, 900, 1000}));
  EXPECT_EQ(pass.origin_log_ns, kStart);
  EXPECT_EQ(pass.span_ns, 1000 * static_cast<std::int64_t>(kMs));
  for (std::size_t i = 0; i < pass.messages.size(); ++i) EXPECT_EQ(pass.messages[i].index, i);
}

TEST(PlaybackPlan, RateScalesTheGaps) {
  const auto times = ten_hz();
  PlaybackOptions fast;
  fast.rate = 4.0;
  const auto pass = plan_pass(times, std::vector<bool>(times.size(), true), kStart, fast);
  EXPECT_EQ(pass.messages[1].due_ns, 25 * static_cast<std::int64_t>(kMs));
  EXPECT_EQ(pass.span_ns, 250 * static_cast<std::int64_t>(kMs));
  PlaybackOptions slow;
  slow.rate = 0.5;
  EXPECT_EQ(plan_pass(times, std::vector<bool>(times.size(), true), kStart, slow).span_ns,
            2000 * static_cast<std::int64_t>(kMs));
}

TEST(PlaybackPlan, StartOffsetAndDurationCutAWindow) {
  const auto times = ten_hz();
  PlaybackOptions o;
  o.start_offset_s = 0.25;
  o.duration_s = 0.5;  // log time [0.25, 0.75]
  const auto pass = plan_pass(times, std::vector<bool>(times.size(), true), kStart, o);
  ASSERT_EQ(pass.messages.size(), 5u);  // 0.3 .. 0.7
  EXPECT_EQ(pass.messages.front().index, 3u);
  EXPECT_EQ(pass.messages.back().index, 7u);
  // The window's start maps to the pass start: the first message waits 50 ms, as recorded.
  EXPECT_EQ(due_ms(pass).front(), 50);
  EXPECT_EQ(pass.origin_log_ns, kStart + 250 * kMs);
  EXPECT_EQ(pass.span_ns, 500 * static_cast<std::int64_t>(kMs));
}

TEST(PlaybackPlan, UnselectedTopicsAreSkippedButKeepTheClock) {
  const auto times = ten_hz();
  std::vector<bool> selected(times.size(), false);
  selected[4] = selected[9] = true;
  const auto pass = plan_pass(times, selected, kStart, {});
  EXPECT_EQ(due_ms(pass), (std::vector<std::int64_t>{400, 900}));
  EXPECT_EQ(pass.messages[1].index, 9u);
}

TEST(PlaybackPlan, RejectsBadOptionsAndAStartPastTheEnd) {
  const auto times = ten_hz();
  const std::vector<bool> all(times.size(), true);
  for (double rate : {0.0, -1.0, std::numeric_limits<double>::infinity(), std::numeric_limits<double>::quiet_NaN()}) {
    PlaybackOptions o;
    o.rate = rate;
    EXPECT_THROW(plan_pass(times, all, kStart, o), std::invalid_argument) << rate;
  }
  PlaybackOptions negative;
  negative.start_offset_s = -1.0;
  EXPECT_THROW(plan_pass(times, all, kStart, negative), std::invalid_argument);
  PlaybackOptions late;
  late.start_offset_s = 1.5;
  try {
    plan_pass(times, all, kStart, late);
    FAIL() << "no exception";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("past the end"), std::string::npos) << e.what();
  }
  std::vector<std::uint64_t> backwards = times;
  std::swap(backwards[2], backwards[3]);
  EXPECT_THROW(plan_pass(backwards, all, kStart, {}), std::invalid_argument);
}

TEST(Restamp, OffsetMovesTheOriginToNowAndBack) {
  using pixyslam::player::restamp_offset_ns;
  using pixyslam::player::shift_stamp;
  const std::uint64_t now = kStart + 3600ull * 1000 * kMs + 123;
  const std::int64_t offset = restamp_offset_ns(kStart, now);
  EXPECT_EQ(shift_stamp(kStart, offset), now);
  EXPECT_EQ(shift_stamp(kStart + 7, offset), now + 7);  // gaps and sub-ns detail kept
  // A log from the future (clock set back) gives a negative offset.
  EXPECT_LT(restamp_offset_ns(now, kStart), 0);
  EXPECT_EQ(shift_stamp(now, restamp_offset_ns(now, kStart)), kStart);
  EXPECT_THROW(shift_stamp(5, -6), std::out_of_range);
  EXPECT_THROW(shift_stamp(std::numeric_limits<std::uint64_t>::max() - 1, 2), std::out_of_range);
  EXPECT_THROW(shift_stamp(5, std::numeric_limits<std::int64_t>::min()), std::out_of_range);
  EXPECT_EQ(shift_stamp(std::numeric_limits<std::uint64_t>::max(), std::numeric_limits<std::int64_t>::min()),
            std::numeric_limits<std::uint64_t>::max() - (1ull << 63));
}

}  // namespace
