// The estimator's time-ordered merge of odometry and camera frames.
#include <gtest/gtest.h>

#include <algorithm>
#include <limits>
#include <random>
#include <variant>
#include <vector>

#include "pixyslam/slam/sensor_queue.h"

namespace pixyslam::slam {
namespace {

OdometryInput odometry(double t, double period = 0.1) {
  OdometryInput o;
  o.sample.t_s = t;
  o.period_s = period;
  return o;
}

ObservationInput frame(double t) {
  ObservationInput o;
  o.frame.t_s = t;
  return o;
}

double stamp_of(const SensorInput& input) {
  return std::holds_alternative<OdometryInput>(input)
             ? std::get<OdometryInput>(input).sample.t_s
             : std::get<ObservationInput>(input).frame.t_s;
}

TEST(SensorQueue, FrameWaitsForTheOdometryThatCoversIt) {
  SensorQueue queue(SensorQueueOptions{});
  queue.push(odometry(10.0));      // covers [10.0, 10.1)
  queue.push(frame(10.15));
  auto out = queue.pop_ready(10.16);
  ASSERT_EQ(out.size(), 1u);       // the odometry only: nothing newer from the camera can be older
  EXPECT_TRUE(std::holds_alternative<OdometryInput>(out[0]));
  EXPECT_TRUE(queue.pop_ready(10.17).empty());  // frame at 10.15 needs odometry up to 10.15
  queue.push(odometry(10.1));      // covers [10.1, 10.2)
  out = queue.pop_ready(10.21);
  ASSERT_EQ(out.size(), 2u);
  EXPECT_DOUBLE_EQ(stamp_of(out[0]), 10.1);
  EXPECT_DOUBLE_EQ(stamp_of(out[1]), 10.15);
}

// A period from the wire that is infinite or absurd does not make the
// odometry known far ahead: a frame still waits for the odometry covering it.
TEST(SensorQueue, AnInfiniteOrHugeOdometryPeriodDoesNotReleaseFramesEarly) {
  for (const double period : {std::numeric_limits<double>::infinity(), 1e300,
                              std::numeric_limits<double>::quiet_NaN(), -1.0}) {
    SensorQueue queue(SensorQueueOptions{});
    queue.push(odometry(10.0, period), 10.0);
    queue.push(frame(30.0), 10.01);  // 20 s on: beyond max_stamp_jump_s (10 s) of odometry
    const std::vector<SensorInput> out = queue.pop_ready(10.02);
    ASSERT_EQ(out.size(), 1u) << period;
    EXPECT_TRUE(std::holds_alternative<OdometryInput>(out[0])) << period;
  }
}

// One stamp a year ahead (a hostile sender, a clock set wrong) is held and
// dropped when its stream goes on at the old time; a jump its stream's next
// sample confirms (a restart, a clock step) goes on; the first samples wait
// for their stream's second.
TEST(StampGate, AJumpGoesOnOnlyWhenItsStreamsNextSampleConfirmsIt) {
  const std::uint64_t s = 1'000'000'000ull;
  const std::uint64_t year = 365ull * 86400ull * s;
  StampGate<int> gate(2, 10.0, 1.0);
  EXPECT_TRUE(gate.offer(1, 0, 100 * s, 0).empty());  // the first one waits
  EXPECT_TRUE(gate.offer(2, 1, 100 * s, 1).empty());  // another stream does not confirm it
  EXPECT_EQ(gate.offer(3, 0, 100 * s + s / 10, 2), (std::vector<int>{1, 3, 2}));
  EXPECT_TRUE(gate.offer(4, 0, 100 * s + year, 3).empty());
  EXPECT_TRUE(gate.offer(5, 1, 100 * s + year, 4).empty());  // nor does it confirm another's jump
  EXPECT_EQ(gate.offer(6, 0, 100 * s + 2 * s / 10, 5), (std::vector<int>{6}));  // the old time goes on
  EXPECT_EQ(gate.dropped(), 1u);
  EXPECT_EQ(gate.offer(7, 1, 100 * s + 3 * s / 10, 6), (std::vector<int>{7}));
  EXPECT_EQ(gate.dropped(), 2u);
  // A held jump also goes after max_hold.
  EXPECT_TRUE(gate.offer(8, 1, 100 * s + year, 7).empty());
  EXPECT_EQ(gate.offer(9, 0, 100 * s + 4 * s / 10, 2 * s), (std::vector<int>{9}));
  EXPECT_EQ(gate.dropped(), 3u);
  // A restart 5 min on, confirmed by the next sample: the time moves, the other stream follows.
  EXPECT_TRUE(gate.offer(10, 0, 400 * s, 3 * s).empty());
  EXPECT_EQ(gate.offer(11, 0, 400 * s + s / 10, 3 * s + 1), (std::vector<int>{10, 11}));
  EXPECT_EQ(gate.offer(12, 1, 400 * s + s / 20, 3 * s + 2), (std::vector<int>{12}));
  // At the end a held jump is dropped.
  EXPECT_TRUE(gate.offer(13, 1, 400 * s + year, 3 * s + 3).empty());
  EXPECT_TRUE(gate.flush().empty());
  EXPECT_EQ(gate.dropped(), 4u);
}

// Two consistent samples a year ahead (a hostile pair, or a clock that then
// steps back) move the time; the samples that follow at the real time do not
// stop it for good: after max_hold of nothing but such samples (three at
// least) the time goes back to theirs. A backlog older than the jump while
// current samples still come does not.
TEST(StampGate, TheTimeGoesBackWhenOnlySamplesFarBehindItKeepComing) {
  const std::uint64_t s = 1'000'000'000ull;
  const std::uint64_t year = 365ull * 86400ull * s;
  StampGate<int> gate(2, 10.0, 1.0);
  EXPECT_TRUE(gate.offer(1, 0, 100 * s, 0).empty());
  EXPECT_EQ(gate.offer(2, 0, 100 * s + s / 10, s / 10), (std::vector<int>{1, 2}));
  EXPECT_TRUE(gate.offer(3, 1, 100 * s + year, s / 5).empty());
  EXPECT_EQ(gate.offer(4, 1, 100 * s + year + s / 10, s / 5 + 1), (std::vector<int>{3, 4}));  // the pair moves it
  // A backlog from long ago, with current samples between: no rebase.
  for (int i = 0; i < 30; ++i) {
    const std::uint64_t arrival = s + static_cast<std::uint64_t>(i) * s / 10;
    gate.offer(100 + i, 0, 50 * s + static_cast<std::uint64_t>(i) * s / 10, arrival);
    if (i % 5 == 0 || i == 29) gate.offer(200 + i, 1, 100 * s + year + s + static_cast<std::uint64_t>(i) * s / 10, arrival + 1);
  }
  EXPECT_FALSE(gate.take_rebased());
  // Now only the real time comes (the pair's sender has stopped).
  bool rebased = false;
  std::uint64_t arrival = 5 * s;
  for (int i = 0; i < 15 && !rebased; ++i) {
    arrival += s / 10;
    const std::vector<int> out = gate.offer(300 + i, i % 2, 103 * s + static_cast<std::uint64_t>(i) * s / 10, arrival);
    rebased = gate.take_rebased();
    if (rebased) {
      EXPECT_EQ(out, (std::vector<int>{300 + i}));
      EXPECT_GE(arrival - 5 * s, s);  // after max_hold of them
    }
  }
  ASSERT_TRUE(rebased);
  EXPECT_EQ(gate.rebases(), 1u);
  // At the real time again: its samples go on, a stamp a year ahead is held again.
  EXPECT_EQ(gate.offer(400, 0, 105 * s, arrival + 1), (std::vector<int>{400}));
  EXPECT_TRUE(gate.offer(401, 1, 105 * s + year, arrival + 2).empty());
  EXPECT_FALSE(gate.take_rebased());
}

TEST(StampGate, AFirstSampleFromAWrongClockDoesNotSetTheTime) {
  const std::uint64_t s = 1'000'000'000ull;
  StampGate<int> gate(2, 10.0);
  EXPECT_TRUE(gate.offer(1, 0, 1'000'000 * s, 0).empty());
  EXPECT_TRUE(gate.offer(2, 1, 1'000'000 * s, 1).empty());
  EXPECT_TRUE(gate.offer(3, 0, 100 * s, 2).empty());  // no agreement: the first is dropped, this one waits
  EXPECT_EQ(gate.offer(4, 0, 100 * s + s / 10, 3), (std::vector<int>{3, 4}));
  EXPECT_EQ(gate.offer(5, 1, 100 * s + s / 10, 4), (std::vector<int>{5}));
  EXPECT_EQ(gate.dropped(), 2u);  // the other stream's far one: its stream went on at the real time
  StampGate<int> lone(2, 10.0);
  EXPECT_TRUE(lone.offer(1, 0, 5 * s, 0).empty());
  EXPECT_EQ(lone.flush(), (std::vector<int>{1}));  // a lone first sample goes at the end
}

TEST(SensorQueue, AFloodBeyondMaxHeldIsDroppedAndCounted) {
  SensorQueueOptions options;
  options.max_held = 4;
  SensorQueue queue(options);
  queue.push(frame(9.0), 9.0);
  for (int i = 0; i < 10; ++i) queue.push(frame(10.0 + 0.01 * i), 10.0);
  EXPECT_EQ(queue.size(), 4u);
  EXPECT_EQ(queue.counters().overflow, 7u);
  EXPECT_EQ(queue.counters().observations_in, 4u);
  EXPECT_EQ(queue.pop_all().size(), 4u);
  EXPECT_TRUE(queue.push(frame(11.0), 11.0));  // room again
}

TEST(SensorQueue, OdometryIsReleasedWithoutWaitingForASlowCamera) {
  SensorQueue queue(SensorQueueOptions{});
  queue.push(frame(9.95));
  EXPECT_TRUE(queue.pop_ready(9.96).empty());
  queue.push(odometry(10.0));  // arrives at 10.1, when it was sent
  const auto out = queue.pop_ready(10.1);
  ASSERT_EQ(out.size(), 2u);  // the camera is known up to 9.95 and may lag 0.05 s: done
  EXPECT_DOUBLE_EQ(stamp_of(out[0]), 9.95);
  EXPECT_DOUBLE_EQ(stamp_of(out[1]), 10.0);
}

TEST(SensorQueue, SilentOdometryStopsHoldingFramesAfterItsMaxDelay) {
  SensorQueueOptions options;
  options.odometry_max_delay_s = 0.3;
  SensorQueue queue(options);
  queue.push(frame(5.0));
  EXPECT_TRUE(queue.pop_ready(5.29).empty());
  EXPECT_DOUBLE_EQ(queue.next_release_s(), 5.3);
  EXPECT_EQ(queue.pop_ready(5.3).size(), 1u);
}

TEST(SensorQueue, OdometryGoesFirstAtEqualStamps) {
  SensorQueue queue(SensorQueueOptions{});
  queue.push(frame(1.0));
  queue.push(odometry(1.0));
  queue.push(odometry(1.1));
  const auto out = queue.pop_ready(1.5);
  ASSERT_EQ(out.size(), 3u);
  EXPECT_TRUE(std::holds_alternative<OdometryInput>(out[0]));
  EXPECT_TRUE(std::holds_alternative<ObservationInput>(out[1]));
}

TEST(SensorQueue, ShuffledArrivalsComeOutSortedAndCounted) {
  std::mt19937 prng(42);
  std::vector<SensorInput> inputs;
  for (int i = 0; i < 100; ++i) {
    inputs.emplace_back(odometry(0.1 * i));
    inputs.emplace_back(frame(0.1 * i + 0.05));
  }
  // Swap neighbours of one stream now and then: reordering within a stream.
  for (std::size_t i = 0; i + 2 < inputs.size(); i += 6) {
    if (prng() % 2 == 0) std::swap(inputs[i], inputs[i + 2]);
  }
  SensorQueue queue(SensorQueueOptions{});
  std::vector<double> released;
  for (const SensorInput& input : inputs) {
    std::visit([&](const auto& x) { queue.push(x); }, input);
  }
  for (const SensorInput& input : queue.pop_all()) released.push_back(stamp_of(input));
  ASSERT_EQ(released.size(), inputs.size());
  EXPECT_TRUE(std::is_sorted(released.begin(), released.end()));
  EXPECT_GT(queue.counters().reordered, 0u);
  EXPECT_EQ(queue.counters().late, 0u);
  EXPECT_EQ(queue.size(), 0u);
}

TEST(SensorQueue, LateSampleIsReleasedAtOnceAndCounted) {
  SensorQueue queue(SensorQueueOptions{});
  queue.push(odometry(2.0));
  queue.push(odometry(2.1));
  ASSERT_EQ(queue.pop_ready(2.2).size(), 2u);
  queue.push(frame(1.5));  // older than the filter already is
  const auto out = queue.pop_ready(2.2);
  ASSERT_EQ(out.size(), 1u);
  EXPECT_EQ(queue.counters().late, 1u);
}

// A network outage: both streams' backlogs arrive at once, long after their
// stamps, odometry first. While they keep arriving they hold each other back,
// so the burst is merged in stamp order and nothing is late.
TEST(SensorQueue, BacklogAfterAnOutageIsMergedInStampOrder) {
  SensorQueue queue(SensorQueueOptions{});
  std::vector<double> released;
  auto drain = [&](double now) {
    for (const SensorInput& input : queue.pop_ready(now)) released.push_back(stamp_of(input));
  };
  queue.push(odometry(0.0), 0.1);
  queue.push(frame(0.05), 0.1);
  drain(0.1);
  double now = 5.0;  // the link is back: 5 s of data arrives within 50 ms
  for (int i = 1; i < 50; ++i) {
    queue.push(odometry(0.1 * i), now);
    drain(now);
    now += 0.0005;
  }
  for (int i = 1; i < 50; ++i) {
    queue.push(frame(0.1 * i + 0.05), now);
    drain(now);
    now += 0.0005;
  }
  drain(now + 1.1);  // both silent again, recovery wait over: everything goes
  EXPECT_EQ(released.size(), 100u);
  EXPECT_TRUE(std::is_sorted(released.begin(), released.end()));
  EXPECT_EQ(queue.counters().late, 0u);
}

// Both bridges held their first messages until every reader matched: the
// odometry backlog arrives first, the camera's 0.3 s later; still merged.
TEST(SensorQueue, BacklogAtTheStartWaitsForTheStreamNotSeenYet) {
  SensorQueue queue(SensorQueueOptions{});
  std::vector<double> released;
  auto drain = [&](double now) {
    for (const SensorInput& input : queue.pop_ready(now)) released.push_back(stamp_of(input));
  };
  double now = 6.0;
  for (int i = 0; i < 50; ++i) {
    queue.push(odometry(0.1 * i), now);
    drain(now);
  }
  EXPECT_TRUE(released.empty()) << "odometry went ahead of the camera's backlog";
  EXPECT_DOUBLE_EQ(queue.next_release_s(), 7.0);
  now = 6.3;
  for (int i = 0; i < 50; ++i) {
    queue.push(frame(0.1 * i + 0.05), now);
    drain(now);
  }
  drain(now + 1.0);
  EXPECT_EQ(released.size(), 100u);
  EXPECT_TRUE(std::is_sorted(released.begin(), released.end()));
  EXPECT_EQ(queue.counters().late, 0u);
}

// A robot without a camera: its odometry backlog goes after the recovery wait.
TEST(SensorQueue, BacklogAtTheStartWithoutACameraGoesAfterTheRecoveryWait) {
  SensorQueue queue(SensorQueueOptions{});
  for (int i = 0; i < 50; ++i) queue.push(odometry(0.1 * i), 6.0);
  EXPECT_TRUE(queue.pop_ready(6.99).empty());
  EXPECT_EQ(queue.pop_ready(7.0).size(), 50u);
}

// Without arrival times the same burst is released as it comes: late frames.
TEST(SensorQueue, BacklogWithoutArrivalTimesGoesOutAsItComes) {
  SensorQueue queue(SensorQueueOptions{});
  queue.push(odometry(0.0));
  for (int i = 1; i < 50; ++i) queue.push(odometry(0.1 * i));
  EXPECT_EQ(queue.pop_ready(5.0).size(), 50u);
  for (int i = 1; i < 50; ++i) queue.push(frame(0.1 * i + 0.05));
  queue.pop_ready(5.0);
  EXPECT_GT(queue.counters().late, 40u);
}

TEST(SensorQueue, AnArrivingStreamHoldsTheOtherUntilSilentForItsMaxDelay) {
  SensorQueueOptions options;
  options.odometry_max_delay_s = 0.3;
  SensorQueue queue(options);
  queue.push(odometry(1.0), 10.0);  // stamps lag the clock by 9 s, but it is arriving
  queue.push(frame(1.5), 10.0);
  EXPECT_EQ(queue.pop_ready(10.0).size(), 1u);  // the odometry; the frame waits for odometry up to 1.5
  // The odometry came 8.9 s late: an outage; held through the recovery wait (1 s).
  EXPECT_TRUE(queue.pop_ready(10.99).empty());
  EXPECT_DOUBLE_EQ(queue.next_release_s(), 11.0);
  EXPECT_EQ(queue.pop_ready(11.0).size(), 1u);
}

TEST(SensorQueue, WithoutAnOutageASilentStreamHoldsOnlyForItsMaxDelay) {
  SensorQueueOptions options;
  options.odometry_max_delay_s = 0.3;
  SensorQueue queue(options);
  queue.push(odometry(9.8), 9.95);  // on time (stamped at the start of its 0.1 s period)
  queue.push(frame(10.0), 10.01);
  EXPECT_EQ(queue.pop_ready(10.01).size(), 1u);
  EXPECT_TRUE(queue.pop_ready(10.29).empty());
  EXPECT_DOUBLE_EQ(queue.next_release_s(), 10.3);  // stamp 10.0 + 0.3
  EXPECT_EQ(queue.pop_ready(10.3).size(), 1u);      // odometry silent for 0.3 s: it stops holding
}

}  // namespace
}  // namespace pixyslam::slam
