// Tests of the encoder-bridge odometry: ticks -> (v, w) with wrap-around,
// resets, sequence gaps and implausible deltas; the fixed-rate accumulator
// (10 Hz means, period-start stamps, distance conservation); the YAML options.

#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "pixyslam/config/yaml_reader.h"
#include "pixyslam/encoder/arduino_line_parser.h"
#include "pixyslam/encoder/encoder_options.h"
#include "pixyslam/encoder/wheel_odometry.h"

namespace pixyslam::encoder {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr std::int32_t kInt32Max = std::numeric_limits<std::int32_t>::max();
constexpr std::int32_t kInt32Min = std::numeric_limits<std::int32_t>::min();

// r = 5 cm, 1000 ticks per turn, 20 cm wheel base: 0.314159 mm per tick.
EncoderOptions test_options() {
  EncoderOptions o;
  o.wheel_radius_m = 0.05;
  o.ticks_per_revolution = 1000;
  o.wheel_base_m = 0.2;
  o.left_sign = 1;
  o.right_sign = 1;
  o.max_wheel_speed_mps = 2.0;
  o.max_sample_gap_s = 0.5;
  return o;
}

double metres(double ticks) { return 2.0 * kPi * 0.05 * ticks / 1000.0; }

template <class F>
std::string config_error_of(F&& f) {
  try {
    f();
  } catch (const config::ConfigError& e) {
    return e.what();
  }
  ADD_FAILURE() << "expected ConfigError";
  return "";
}

// ---------------------------------------------------------------------------
// Modular deltas

TEST(WrapAwareDelta, TickCounterWrapGivesTheSmallDelta) {
  EXPECT_EQ(tick_delta(kInt32Min + 2, kInt32Max - 2), 5);
  EXPECT_EQ(tick_delta(kInt32Max - 1, kInt32Min + 1), -3);
  EXPECT_EQ(tick_delta(kInt32Min, kInt32Max), 1);
  EXPECT_EQ(tick_delta(10, 25), -15);
  EXPECT_EQ(tick_delta(kInt32Max, kInt32Min), -1);
}

TEST(WrapAwareDelta, ArduinoClockWrapGivesTheSmallInterval) {
  EXPECT_EQ(time_delta_us(10000, 0xffffffffu - 9999u), 20000u);
  EXPECT_EQ(time_delta_us(0, 0xffffffffu), 1u);
  EXPECT_EQ(time_delta_us(20000, 0), 20000u);
}

// ---------------------------------------------------------------------------
// WheelOdometry

TEST(WheelOdometry, FirstSampleIsOnlyABaseline) {
  WheelOdometry odo(test_options());
  EXPECT_EQ(odo.update({0, 1000, 123, -456}).status, WheelStatus::kBaseline);
  EXPECT_EQ(odo.counters().steps, 0u);
}

TEST(WheelOdometry, StraightLineHasNoRotation) {
  // Given equal ticks on both wheels over 20 ms, v = 2 pi r ticks / (tpr dt), w = 0.
  WheelOdometry odo(test_options());
  odo.update({0, 5000, 1000, 1000});
  const WheelUpdate u = odo.update({1, 25000, 1100, 1100});
  ASSERT_EQ(u.status, WheelStatus::kStep);
  const double dt = 0.02;
  EXPECT_DOUBLE_EQ(u.step.dt_s, dt);
  EXPECT_NEAR(u.step.v_mps, 2.0 * kPi * 0.05 * 100 / (1000 * dt), 1e-12);
  EXPECT_NEAR(u.step.v_mps, 1.5707963267948966, 1e-12);
  EXPECT_EQ(u.step.w_radps, 0.0);
  EXPECT_NEAR(u.step.distance_m, metres(100), 1e-15);
  EXPECT_EQ(u.step.seq, 1u);
}

TEST(WheelOdometry, TurnInPlaceHasNoLinearVelocity) {
  // Left back 50 ticks, right forward 50 ticks: v = 0, w = (right - left) / base / dt > 0 (CCW).
  WheelOdometry odo(test_options());
  odo.update({0, 0, 0, 0});
  const WheelUpdate u = odo.update({1, 20000, -50, 50});
  ASSERT_EQ(u.status, WheelStatus::kStep);
  EXPECT_EQ(u.step.v_mps, 0.0);
  EXPECT_NEAR(u.step.w_radps, (metres(50) - metres(-50)) / 0.2 / 0.02, 1e-12);
  EXPECT_GT(u.step.w_radps, 0.0);
  EXPECT_NEAR(u.step.rotation_rad, 2.0 * metres(50) / 0.2, 1e-15);
}

TEST(WheelOdometry, SignsMakeForwardPositive) {
  // A mirror-mounted right motor counts down when rolling forward.
  EncoderOptions o = test_options();
  o.right_sign = -1;
  WheelOdometry odo(o);
  odo.update({0, 0, 0, 0});
  const WheelUpdate u = odo.update({1, 20000, 40, -40});
  ASSERT_EQ(u.status, WheelStatus::kStep);
  EXPECT_NEAR(u.step.v_mps, metres(40) / 0.02, 1e-12);
  EXPECT_NEAR(u.step.w_radps, 0.0, 1e-12);
}

TEST(WheelOdometry, CounterWrapAroundGivesTheSmallPositiveDelta) {
  WheelOdometry odo(test_options());
  odo.update({0, 0, kInt32Max - 2, kInt32Max - 4});
  const WheelUpdate u = odo.update({1, 20000, kInt32Min + 2, kInt32Min + 0});
  ASSERT_EQ(u.status, WheelStatus::kStep);
  EXPECT_NEAR(u.step.left_m, metres(5), 1e-15);
  EXPECT_NEAR(u.step.right_m, metres(5), 1e-15);
  EXPECT_NEAR(u.step.v_mps, metres(5) / 0.02, 1e-12);
}

TEST(WheelOdometry, ArduinoClockWrapGivesTheRightInterval) {
  WheelOdometry odo(test_options());
  odo.update({7, 0xffffffffu - 9999u, 0, 0});  // 2^32 - 10000 us
  const WheelUpdate u = odo.update({8, 10000u, 30, 30});
  ASSERT_EQ(u.status, WheelStatus::kStep);
  EXPECT_DOUBLE_EQ(u.step.dt_s, 0.02);
  EXPECT_NEAR(u.step.v_mps, metres(30) / 0.02, 1e-12);
  EXPECT_EQ(odo.counters().time_gaps, 0u);
}

TEST(WheelOdometry, ResetDropsTheDeltaAcrossIt) {
  // Given motion, then an RST line and counters/clock/seq restarting from 0,
  // when the next samples arrive, then the first is a baseline (no velocity from
  // 5000 ticks "backwards") and the second gives the true velocity.
  WheelOdometry odo(test_options());
  odo.update({500, 10000000, 5000, 5000});
  ASSERT_EQ(odo.update({501, 10020000, 5020, 5020}).status, WheelStatus::kStep);
  odo.reset(EncoderReset{"1.0.0", 1000});
  EXPECT_EQ(odo.update({0, 1200, 0, 0}).status, WheelStatus::kBaseline);
  const WheelUpdate u = odo.update({1, 21200, 10, 10});
  ASSERT_EQ(u.status, WheelStatus::kStep);
  EXPECT_NEAR(u.step.v_mps, metres(10) / 0.02, 1e-12);
  EXPECT_EQ(odo.counters().resets, 1u);
  EXPECT_EQ(odo.counters().ticks_per_revolution_mismatches, 0u);
  EXPECT_EQ(odo.counters().sequence_backwards, 0u);
  EXPECT_EQ(odo.counters().implausible, 0u);

  odo.reset(EncoderReset{"1.0.0", 1320});  // firmware built for another encoder
  EXPECT_EQ(odo.counters().ticks_per_revolution_mismatches, 1u);
  odo.reset(EncoderReset{"0.9", 0});  // 0 = unknown: no mismatch
  EXPECT_EQ(odo.counters().ticks_per_revolution_mismatches, 1u);
}

TEST(WheelOdometry, UnannouncedRestartIsDetectedBySeqGoingBack) {
  WheelOdometry odo(test_options());
  odo.update({900, 50000000, 8000, 8000});
  odo.update({901, 50020000, 8010, 8010});
  EXPECT_EQ(odo.update({0, 900, 0, 0}).status, WheelStatus::kBaseline);  // RST line lost
  EXPECT_EQ(odo.counters().sequence_backwards, 1u);
  const WheelUpdate u = odo.update({1, 20900, 10, 10});
  ASSERT_EQ(u.status, WheelStatus::kStep);
  EXPECT_NEAR(u.step.v_mps, metres(10) / 0.02, 1e-12);
}

TEST(WheelOdometry, SequenceGapIsCountedAndTheStepSpansIt) {
  // Lines 2 and 3 lost: the step from 1 to 4 uses the Arduino's 60 ms.
  WheelOdometry odo(test_options());
  odo.update({0, 0, 0, 0});
  odo.update({1, 20000, 10, 12});
  const WheelUpdate u = odo.update({4, 80000, 40, 48});
  ASSERT_EQ(u.status, WheelStatus::kStep);
  EXPECT_DOUBLE_EQ(u.step.dt_s, 0.06);
  EXPECT_NEAR(u.step.left_m, metres(30), 1e-15);
  EXPECT_NEAR(u.step.v_mps, metres(33) / 0.06, 1e-12);
  EXPECT_NEAR(u.step.w_radps, (metres(36) - metres(30)) / 0.2 / 0.06, 1e-12);
  EXPECT_EQ(odo.counters().sequence_gaps, 1u);
  EXPECT_EQ(odo.counters().lost_samples, 2u);
  // A gap across the seq wrap: 0xffffffff -> 1 loses one line.
  WheelOdometry wrap(test_options());
  wrap.update({0xffffffffu, 0, 0, 0});
  EXPECT_EQ(wrap.update({1, 40000, 20, 20}).status, WheelStatus::kStep);
  EXPECT_EQ(wrap.counters().lost_samples, 1u);
}

TEST(WheelOdometry, DuplicateSeqIsIgnored) {
  WheelOdometry odo(test_options());
  odo.update({3, 0, 0, 0});
  EXPECT_EQ(odo.update({3, 0, 0, 0}).status, WheelStatus::kDuplicate);
  EXPECT_EQ(odo.counters().duplicates, 1u);
  EXPECT_EQ(odo.update({4, 20000, 10, 10}).status, WheelStatus::kStep);
}

TEST(WheelOdometry, ImplausibleDeltaIsRejectedAndTheBaselineKept) {
  // 2 m/s at most: 20 ms allow 0.04 m = 127 ticks. A corrupted line reading
  // 5000 ticks is rejected; the next good sample spans both intervals.
  WheelOdometry odo(test_options());
  odo.update({0, 0, 0, 0});
  EXPECT_EQ(odo.update({1, 20000, 5000, 20}).status, WheelStatus::kRejected);
  EXPECT_EQ(odo.counters().implausible, 1u);
  const WheelUpdate u = odo.update({2, 40000, 40, 40});
  ASSERT_EQ(u.status, WheelStatus::kStep);
  EXPECT_DOUBLE_EQ(u.step.dt_s, 0.04);
  EXPECT_NEAR(u.step.v_mps, metres(40) / 0.04, 1e-12);
  // Just under the limit passes, just over is rejected.
  EXPECT_EQ(odo.update({3, 60000, 40 + 127, 40}).status, WheelStatus::kStep);
  EXPECT_EQ(odo.update({4, 80000, 40 + 127 + 128, 40}).status, WheelStatus::kRejected);
}

TEST(WheelOdometry, RunOfRejectionsRestartsFromTheLatestSample) {
  // The counters really jumped (e.g. a glitch): after three rejections in a row
  // the latest sample becomes the baseline instead of rejecting forever.
  WheelOdometry odo(test_options());
  odo.update({0, 0, 0, 0});
  EXPECT_EQ(odo.update({1, 20000, 90000, 90000}).status, WheelStatus::kRejected);
  EXPECT_EQ(odo.update({2, 40000, 90010, 90010}).status, WheelStatus::kRejected);
  EXPECT_EQ(odo.update({3, 60000, 90020, 90020}).status, WheelStatus::kBaseline);
  EXPECT_EQ(odo.counters().rejection_restarts, 1u);
  const WheelUpdate u = odo.update({4, 80000, 90030, 90030});
  ASSERT_EQ(u.status, WheelStatus::kStep);
  EXPECT_NEAR(u.step.v_mps, metres(10) / 0.02, 1e-12);
}

TEST(WheelOdometry, LongOrZeroIntervalRestarts) {
  WheelOdometry odo(test_options());
  odo.update({0, 0, 0, 0});
  EXPECT_EQ(odo.update({1, 600000, 10, 10}).status, WheelStatus::kBaseline);  // 0.6 s > 0.5 s
  EXPECT_EQ(odo.update({2, 600000, 12, 12}).status, WheelStatus::kBaseline);  // 0 us
  EXPECT_EQ(odo.counters().time_gaps, 2u);
  EXPECT_EQ(odo.update({3, 620000, 22, 22}).status, WheelStatus::kStep);
}

TEST(WheelOdometry, InvalidOptionsAreRefused) {
  EncoderOptions o = test_options();
  o.wheel_base_m = 0.0;
  EXPECT_THROW(WheelOdometry{o}, std::invalid_argument);
  o = test_options();
  o.left_sign = 0;
  EXPECT_THROW(WheelOdometry{o}, std::invalid_argument);
}

// ---------------------------------------------------------------------------
// OdometryAccumulator

WheelUpdate step_of(double dt_s, double v_mps, double w_radps) {
  WheelUpdate u;
  u.status = WheelStatus::kStep;
  u.step.dt_s = dt_s;
  u.step.distance_m = v_mps * dt_s;
  u.step.rotation_rad = w_radps * dt_s;
  u.step.v_mps = v_mps;
  u.step.w_radps = w_radps;
  return u;
}

WheelUpdate baseline() { return WheelUpdate{WheelStatus::kBaseline, {}}; }

TEST(OdometryAccumulator, OutputsAtTenHertzStampedAtThePeriodStart) {
  // Given 50 Hz steps at constant v = 0.5 m/s, w = 0.2 rad/s from host time 100 s,
  // then one output per 0.1 s, stamped 100.0, 100.1, ..., with the same means.
  OdometryAccumulator acc(10.0);
  std::vector<OdometryOutput> out;
  const auto keep = [&out](const OdometryOutput& o) { out.push_back(o); };
  acc.add(100.0, baseline(), keep);
  for (int k = 1; k <= 52; ++k) acc.add(100.0 + 0.02 * k, step_of(0.02, 0.5, 0.2), keep);
  ASSERT_EQ(out.size(), 10u);
  for (std::size_t i = 0; i < out.size(); ++i) {
    EXPECT_NEAR(out[i].t_s, 100.0 + 0.1 * static_cast<double>(i), 1e-9) << i;
    EXPECT_NEAR(out[i].duration_s, 0.1, 1e-15);
    EXPECT_NEAR(out[i].v_mps, 0.5, 1e-9) << i;
    EXPECT_NEAR(out[i].w_radps, 0.2, 1e-9) << i;
    EXPECT_NEAR(out[i].distance_m, 0.05, 1e-10) << i;
    EXPECT_NEAR(out[i].covered_s, 0.1, 1e-9) << i;
  }
  EXPECT_EQ(acc.counters().outputs, 10u);
}

TEST(OdometryAccumulator, EachOutputIsTheMeanOverItsOwnPeriod) {
  // 7 steps at 0.2 m/s (0 .. 0.14 s), then 0.6 m/s: the first period is 0.2, the
  // second holds 2 slow and 3 fast steps, (2 * 0.2 + 3 * 0.6) / 5 = 0.44, the third 0.6.
  OdometryAccumulator acc(10.0);
  std::vector<OdometryOutput> out;
  const auto keep = [&out](const OdometryOutput& o) { out.push_back(o); };
  acc.add(0.0, baseline(), keep);
  for (int k = 1; k <= 16; ++k) {
    const double v = k <= 7 ? 0.2 : 0.6;
    const double w = k <= 7 ? -1.0 : 1.0;
    acc.add(0.02 * k, step_of(0.02, v, w), keep);
  }
  ASSERT_EQ(out.size(), 3u);
  EXPECT_NEAR(out[0].v_mps, 0.2, 1e-9);
  EXPECT_NEAR(out[1].v_mps, 0.44, 1e-9);
  EXPECT_NEAR(out[2].v_mps, 0.6, 1e-9);
  EXPECT_NEAR(out[0].w_radps, -1.0, 1e-9);
  EXPECT_NEAR(out[1].w_radps, (2 * -1.0 + 3 * 1.0) / 5, 1e-9);
  EXPECT_NEAR(out[2].w_radps, 1.0, 1e-9);
}

TEST(OdometryAccumulator, StepsNotAlignedWithPeriodsAreSplitInProportion) {
  // 30 Hz and 7 Hz steps (a step may span several periods) at constant speed:
  // every output still has the step speed.
  for (const double rate_hz : {30.0, 7.0}) {
    OdometryAccumulator acc(10.0);
    std::vector<OdometryOutput> out;
    const auto keep = [&out](const OdometryOutput& o) { out.push_back(o); };
    acc.add(3.0, baseline(), keep);
    for (int k = 1; k <= 3 * static_cast<int>(rate_hz); ++k) {
      acc.add(3.0 + k / rate_hz, step_of(1.0 / rate_hz, 0.3, -0.4), keep);
    }
    ASSERT_GE(out.size(), 29u) << rate_hz;
    for (const OdometryOutput& o : out) {
      EXPECT_NEAR(o.v_mps, 0.3, 1e-9) << rate_hz;
      EXPECT_NEAR(o.w_radps, -0.4, 1e-9) << rate_hz;
    }
  }
}

TEST(OdometryAccumulator, UncoveredTimeCountsAsNoMotion) {
  // Steps cover 0 .. 0.06 s, a reset leaves 0.06 .. 0.08 s uncovered, a step
  // covers 0.08 .. 0.10 s: the period has 0.08 s covered and v = 0.04 m / 0.1 s.
  OdometryAccumulator acc(10.0);
  std::vector<OdometryOutput> out;
  const auto keep = [&out](const OdometryOutput& o) { out.push_back(o); };
  acc.add(0.0, baseline(), keep);
  for (int k = 1; k <= 3; ++k) acc.add(0.02 * k, step_of(0.02, 0.5, 0.0), keep);
  acc.add(0.08, baseline(), keep);
  acc.add(0.10, step_of(0.02, 0.5, 0.0), keep);
  ASSERT_EQ(out.size(), 1u);
  EXPECT_NEAR(out[0].covered_s, 0.08, 1e-12);
  EXPECT_NEAR(out[0].v_mps, 0.4, 1e-9);
  // Rejected and duplicate samples leave the interval to the next step.
  acc.add(0.12, WheelUpdate{WheelStatus::kRejected, {}}, keep);
  acc.add(0.14, step_of(0.04, 0.5, 0.0), keep);
  acc.add(0.20, step_of(0.06, 0.5, 0.0), keep);
  ASSERT_EQ(out.size(), 2u);
  EXPECT_NEAR(out[1].covered_s, 0.1, 1e-12);
  EXPECT_NEAR(out[1].v_mps, 0.5, 1e-9);
}

TEST(OdometryAccumulator, StalledStreamEmitsEmptyPeriodsOnMarkGap) {
  OdometryAccumulator acc(10.0);
  acc.add(0.0, baseline());
  acc.add(0.05, step_of(0.05, 1.0, 0.0));
  const auto out = acc.mark_gap(0.35);
  ASSERT_EQ(out.size(), 3u);
  // The period the stream stalled in: 1 m/s measured over its first half, the
  // rest unknown, so 1 m/s over the whole of it.
  EXPECT_NEAR(out[0].v_mps, 1.0, 1e-9);
  EXPECT_NEAR(out[0].covered_s, 0.05, 1e-12);
  EXPECT_EQ(acc.counters().stalled_periods_extrapolated, 1u);
  EXPECT_NEAR(out[1].v_mps, 0.0, 1e-15);
  EXPECT_NEAR(out[1].covered_s, 0.0, 1e-15);
  EXPECT_NEAR(out[2].t_s, 0.2, 1e-12);
}

TEST(OdometryAccumulator, ABacklogAfterAStallMarkIsNotCountedTwice) {
  // Given a robot at 0.2 m/s whose steps (50 Hz) stop arriving at t = 1 s (the
  // Arduino's writer stalled) and the bridge closing the periods up to 1.5 s as
  // "no data" (the filter holds the last command through them),
  OdometryAccumulator acc(10.0);
  std::vector<OdometryOutput> out;
  const auto keep = [&](const OdometryOutput& o) { out.push_back(o); };
  acc.add(0.0, baseline(), keep);
  for (int k = 1; k <= 50; ++k) acc.add(0.02 * k, step_of(0.02, 0.2, 0.1), keep);
  acc.mark_gap(1.5, keep);
  ASSERT_EQ(out.size(), 15u);
  // when the backlog of 1.0..2.0 s arrives,
  for (int k = 51; k <= 100; ++k) acc.add(0.02 * k, step_of(0.02, 0.2, 0.1), keep);
  // the steps before 1.5 s are dropped, not piled into the next period: every
  // period after the gap holds the true speed (a burst would show 0.2 m/s *
  // (1 + 0.5 s / 0.1 s) = 1.2 m/s in the first),
  ASSERT_EQ(out.size(), 20u);
  for (std::size_t k = 15; k < out.size(); ++k) {
    EXPECT_NEAR(out[k].v_mps, 0.2, 1e-9) << k;
    EXPECT_NEAR(out[k].w_radps, 0.1, 1e-9) << k;
  }
  EXPECT_EQ(acc.counters().steps_after_gap, 25u);
  // and a step that straddles the mark counts with its part after it.
  OdometryAccumulator straddle(10.0);
  straddle.add(0.0, baseline());
  straddle.mark_gap(0.31);
  const auto part = straddle.add(0.4, step_of(0.1, 0.5, 0.0));
  ASSERT_EQ(part.size(), 1u);  // period [0.3, 0.4)
  EXPECT_NEAR(part[0].distance_m, 0.5 * 0.09, 1e-12);
  EXPECT_EQ(straddle.counters().steps_after_gap, 0u);
}

TEST(OdometryAccumulator, FirstStepCoversItsOwnInterval) {
  // Without a baseline first, the grid starts at stamp - dt.
  OdometryAccumulator acc8(8.0);  // T = 0.125 s, exact in binary
  const auto out = acc8.add(5.125, step_of(0.125, 0.3, 0.0));
  ASSERT_EQ(out.size(), 1u);
  EXPECT_EQ(out[0].t_s, 5.0);
  EXPECT_NEAR(out[0].v_mps, 0.3, 1e-12);
  EXPECT_EQ(out[0].covered_s, 0.125);
}

TEST(OdometryAccumulator, OutputDistancesSumToTheStepsWithJitteryStamps) {
  // Host stamps jitter and sometimes arrive in bursts (same stamp) or go back a
  // little; the outputs still carry exactly the steps' motion.
  std::mt19937 prng(42);
  std::uniform_real_distribution<double> jitter(-0.008, 0.008);
  std::uniform_real_distribution<double> speed(-0.5, 1.0);
  OdometryAccumulator acc(10.0);
  double distance = 0.0, rotation = 0.0, sum_d = 0.0, sum_r = 0.0;
  const auto keep = [&](const OdometryOutput& o) {
    sum_d += o.distance_m;
    sum_r += o.rotation_rad;
    EXPECT_NEAR(o.v_mps * o.duration_s, o.distance_m, 1e-12);
  };
  acc.add(0.0, baseline(), keep);
  double host = 0.0;
  for (int k = 1; k <= 1000; ++k) {
    if (k % 5 == 0) {
      host -= 0.005;  // back in time
    } else if (k % 7 != 0) {  // k % 7 == 0: same stamp as the one before (a burst)
      host = 0.02 * k + jitter(prng);
    }
    const WheelUpdate u = step_of(0.02, speed(prng), speed(prng));
    distance += u.step.distance_m;
    rotation += u.step.rotation_rad;
    acc.add(host, u, keep);
  }
  acc.add(30.05, baseline(), keep);  // closes the last period uncovered (not a stall)
  EXPECT_NEAR(sum_d, distance, 1e-9);
  EXPECT_NEAR(sum_r, rotation, 1e-9);
  EXPECT_GT(acc.counters().host_time_backwards, 0u);
  EXPECT_EQ(acc.counters().outputs, 300u);
}

TEST(OdometryAccumulator, HugeJumpRestartsTheGridInsteadOfLooping) {
  OdometryAccumulator acc(10.0);
  acc.add(0.0, baseline());
  acc.add(0.02, step_of(0.02, 1.0, 0.0));
  const auto out = acc.add(1e7, step_of(0.02, 1.0, 0.0));
  ASSERT_EQ(out.size(), 1u);  // the open period, closed; not 10^8 empty ones
  EXPECT_NEAR(out[0].distance_m, 0.02, 1e-12);
  EXPECT_EQ(acc.counters().grid_restarts, 1u);
  const auto next = acc.add(1e7 + 0.1, step_of(0.1, 1.0, 0.0));
  ASSERT_EQ(next.size(), 1u);
  EXPECT_NEAR(next[0].t_s, 1e7, 1e-6);
  EXPECT_NEAR(next[0].distance_m, 0.12, 1e-9);  // the jump's step and the next one
  EXPECT_TRUE(acc.add(std::nan(""), baseline()).empty());
  EXPECT_EQ(acc.counters().invalid_host_times, 1u);
}

TEST(OdometryAccumulator, RejectsANonPositiveRate) {
  EXPECT_THROW(OdometryAccumulator{0.0}, std::invalid_argument);
  EXPECT_THROW(OdometryAccumulator{-10.0}, std::invalid_argument);
}

TEST(EncoderPipeline, SimulatedArduinoStreamGivesConstantVelocities) {
  // Given a 50 Hz Arduino stream (10 and 14 ticks per 20 ms) whose clock and
  // left counter wrap mid-run, read in odd-sized chunks, with one line lost,
  // when parsed, converted and accumulated, then every 10 Hz output has
  // v = (l + r) / 2 / dt and w = (r - l) / base / dt.
  const double left_mps = metres(10) / 0.02, right_mps = metres(14) / 0.02;
  std::string stream = format_line(EncoderReset{"1.0.0", 1000});
  std::uint32_t t_us = 0xffffffffu - 200000u;
  std::int32_t left = kInt32Max - 100, right = -5000;
  std::vector<double> host_of_line;
  for (std::uint32_t seq = 0; seq < 100; ++seq) {
    if (seq != 42) stream += format_line(EncoderSample{seq, t_us, left, right});
    t_us += 20000;
    left = static_cast<std::int32_t>(static_cast<std::uint32_t>(left) + 10u);
    right += 14;
  }
  ArduinoLineParser parser;
  WheelOdometry odo(test_options());
  OdometryAccumulator acc(10.0);
  std::vector<OdometryOutput> out;
  double host_s = 50.0;
  const auto on_message = [&](const ArduinoMessage& m) {
    if (const auto* r = std::get_if<EncoderReset>(&m)) {
      odo.reset(*r);
      return;
    }
    const EncoderSample& s = std::get<EncoderSample>(m);
    host_s = 50.0 + 0.02 * s.seq;  // stamped when its line ended
    acc.add(host_s, odo.update(s), [&out](const OdometryOutput& o) { out.push_back(o); });
  };
  for (std::size_t i = 0; i < stream.size(); i += 13) {
    parser.feed(stream.data() + i, std::min<std::size_t>(13, stream.size() - i), on_message);
  }
  EXPECT_EQ(parser.counters().samples, 99u);
  EXPECT_EQ(odo.counters().lost_samples, 1u);
  EXPECT_EQ(odo.counters().steps, 98u);
  ASSERT_EQ(out.size(), 19u);
  for (const OdometryOutput& o : out) {
    EXPECT_NEAR(o.v_mps, 0.5 * (left_mps + right_mps), 1e-9) << o.t_s;
    EXPECT_NEAR(o.w_radps, (right_mps - left_mps) / 0.2, 1e-9) << o.t_s;
  }
  EXPECT_NEAR(out.front().t_s, 50.0, 1e-12);
}

// ---------------------------------------------------------------------------
// Options

const char* kFullYaml =
    "encoder_bridge:\n"
    "  wheel_radius_m: 0.034\n"
    "  ticks_per_revolution: 960\n"
    "  wheel_base_m: 0.142\n"
    "  left_sign: 1\n"
    "  right_sign: -1\n"
    "  publish_rate_hz: 20\n"
    "  max_wheel_speed_mps: 1.2\n"
    "  max_sample_gap_s: 0.25\n";

EncoderOptions read_text(const std::string& text) {
  config::YamlReader root = config::YamlReader::from_string(text, "test.yaml");
  config::YamlReader bridge = root.child("encoder_bridge");
  EncoderOptions o = read_encoder_options(bridge);
  root.finish();
  return o;
}

// The required keys with valid values; `key` set to `value` (added if it is not
// one of them), or left out when `value` is empty.
std::string bridge_yaml(const std::string& key = "", const std::string& value = "") {
  const std::vector<std::pair<std::string, std::string>> required = {
      {"wheel_radius_m", "0.0325"}, {"ticks_per_revolution", "1320"}, {"wheel_base_m", "0.135"},
      {"left_sign", "1"},           {"right_sign", "1"}};
  std::string s = "encoder_bridge:\n";
  bool found = false;
  for (const auto& [k, v] : required) {
    if (k == key) {
      found = true;
      if (!value.empty()) s += "  " + k + ": " + value + "\n";
    } else {
      s += "  " + k + ": " + v + "\n";
    }
  }
  if (!found && !key.empty()) s += "  " + key + ": " + value + "\n";
  return s;
}

TEST(EncoderOptions, ReadsEveryKey) {
  const EncoderOptions o = read_text(kFullYaml);
  EXPECT_DOUBLE_EQ(o.wheel_radius_m, 0.034);
  EXPECT_EQ(o.ticks_per_revolution, 960);
  EXPECT_DOUBLE_EQ(o.wheel_base_m, 0.142);
  EXPECT_EQ(o.left_sign, 1);
  EXPECT_EQ(o.right_sign, -1);
  EXPECT_DOUBLE_EQ(o.publish_rate_hz, 20.0);
  EXPECT_DOUBLE_EQ(o.max_wheel_speed_mps, 1.2);
  EXPECT_DOUBLE_EQ(o.max_sample_gap_s, 0.25);
}

TEST(EncoderOptions, OptionalKeysDefault) {
  const EncoderOptions o = read_text(bridge_yaml());
  const EncoderOptions d;
  EXPECT_DOUBLE_EQ(o.publish_rate_hz, 10.0);
  EXPECT_DOUBLE_EQ(o.max_wheel_speed_mps, d.max_wheel_speed_mps);
}

TEST(EncoderOptions, ToYamlRoundTrips) {
  const EncoderOptions d;
  const EncoderOptions o = read_text(to_yaml(d));
  EXPECT_EQ(o.wheel_radius_m, d.wheel_radius_m);
  EXPECT_EQ(o.ticks_per_revolution, d.ticks_per_revolution);
  EXPECT_EQ(o.wheel_base_m, d.wheel_base_m);
  EXPECT_EQ(o.publish_rate_hz, d.publish_rate_hz);
  EXPECT_EQ(o.max_sample_gap_s, d.max_sample_gap_s);
  const EncoderOptions f = read_text(kFullYaml);
  EXPECT_EQ(read_text(to_yaml(f)).right_sign, -1);
  EXPECT_EQ(read_text(to_yaml(f)).wheel_radius_m, 0.034);
}

TEST(EncoderOptions, ErrorsNameTheKeyPath) {
  struct Case {
    std::string yaml;
    std::string expected;
  };
  const std::vector<Case> cases = {
      {bridge_yaml("left_sign", "0"), "key 'encoder_bridge.left_sign': value 0 is not a sign"},
      {bridge_yaml("right_sign", "2"), "key 'encoder_bridge.right_sign': value 2 is out of range"},
      {bridge_yaml("wheel_radius_m", ""), "key 'encoder_bridge.wheel_radius_m': missing"},
      {bridge_yaml("wheel_radius_m", "-0.03"), "key 'encoder_bridge.wheel_radius_m': value -0.03 is out of range"},
      {bridge_yaml("ticks_per_revolution", "0"), "key 'encoder_bridge.ticks_per_revolution': value 0 is out of range"},
      {bridge_yaml("ticks_per_revolution", "12.5"), "key 'encoder_bridge.ticks_per_revolution': expected an integer"},
      {bridge_yaml("wheel_base_m", "[0.1]"), "key 'encoder_bridge.wheel_base_m': expected a single value"},
      {bridge_yaml("wheel_radius_mm", "32.5"), "key 'encoder_bridge.wheel_radius_mm': unknown key"},
      {bridge_yaml("publish_rate_hz", "0"), "key 'encoder_bridge.publish_rate_hz': value 0 is out of range"},
      {bridge_yaml("max_wheel_speed_mps", "fast"), "key 'encoder_bridge.max_wheel_speed_mps': expected a finite number"},
      {bridge_yaml("max_sample_gap_s", "100"), "key 'encoder_bridge.max_sample_gap_s': value 100 is out of range"},
      {bridge_yaml() + "other: 1\n", "test.yaml: key 'other': unknown key"},
      {"encoder_bridge: 3\n", "key 'encoder_bridge': expected a mapping"},
  };
  for (const Case& c : cases) {
    const std::string e = config_error_of([&] { read_text(c.yaml); });
    EXPECT_NE(e.find("test.yaml: "), std::string::npos) << e;
    EXPECT_NE(e.find(c.expected), std::string::npos) << "got: " << e << "\nyaml:\n" << c.yaml;
  }
}

TEST(EncoderOptions, MissingFileIsAConfigError) {
  const std::string e = config_error_of([] { read_encoder_options_file("/nonexistent/encoder_bridge.yaml"); });
  EXPECT_NE(e.find("/nonexistent/encoder_bridge.yaml"), std::string::npos) << e;
}

TEST(EncoderOptions, ShippedConfigFileIsValidAndMatchesTheDefaults) {
  const EncoderOptions options =
      read_encoder_options_file(std::string(PIXYSLAM_CONFIG_DIR) + "/encoder_bridge.yaml");
  const EncoderOptions defaults;
  EXPECT_DOUBLE_EQ(options.wheel_radius_m, defaults.wheel_radius_m);
  EXPECT_EQ(options.ticks_per_revolution, defaults.ticks_per_revolution);
  EXPECT_DOUBLE_EQ(options.wheel_base_m, defaults.wheel_base_m);
  EXPECT_DOUBLE_EQ(options.publish_rate_hz, 10.0);
}

}  // namespace
}  // namespace pixyslam::encoder
