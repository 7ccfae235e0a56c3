// The estimator's time-ordered merge of odometry and camera frames.
#include <gtest/gtest.h>

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

}  // namespace
}  // namespace pixyslam::slam
