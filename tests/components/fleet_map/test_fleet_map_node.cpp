// The fleet_map process's node: every robot's MapState in over DDS, one
// FleetMap out; its options and message conversions.
#include <chrono>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

#include "dds_test_support.h"
#include "pixyslam/config/yaml_reader.h"
#include "pixyslam/dds/endpoints.h"
#include "pixyslam/dds/participant.h"
#include "pixyslam/fleet_map_node/fleet_map_node.h"

namespace pixyslam::fleet_map_node {
namespace {

dds::DdsOptions loopback_options() { return test_support::loopback_options(200, 30, "fleet_test_"); }

msg::MapState map_state(std::uint64_t stamp_ns, double dx) {
  msg::MapState m;
  m.header().stamp_ns(stamp_ns);
  for (int i = 0; i < 6; ++i) {
    msg::LandmarkEstimate l;
    l.landmark_id(10 + i);
    l.x_m((i % 3) * 1.5 + dx);
    l.y_m((i / 3) * 2.0 + 0.01 * i);
    l.cov_xx_m2(0.01);
    l.cov_xy_m2(0.0);
    l.cov_yy_m2(0.01);
    m.landmarks().push_back(l);
  }
  return m;
}

// Publishes `m` and waits until every reader has it.
bool deliver(dds::Writer<msg::MapState>& writer, msg::MapState& m) {
  return writer.publish(m) && writer.wait_for_acknowledgments(std::chrono::seconds(10));
}

// A FleetMapNode on the loopback domain and a reader of what it publishes.
struct FleetBench {
  explicit FleetBench(int max_robots = 64, double robot_timeout_s = 60.0)
      : node(options(max_robots, robot_timeout_s)), robots(loopback_options(), "test_estimators") {
    node.start();
  }
  static FleetMapOptions options(int max_robots, double robot_timeout_s) {
    FleetMapOptions o;
    o.period_s = 0.1;
    o.max_robots = max_robots;
    o.robot_timeout_s = robot_timeout_s;
    o.dds = loopback_options();
    o.dds.robot_id = "fleet";
    return o;
  }
  // Waits up to 6 s for a fleet map of `robots_in_map` robots stamped `stamp_ns`.
  void wait_for(std::size_t robots_in_map, std::uint64_t stamp_ns) {
    for (int i = 0; i < 300; ++i) {
      {
        std::lock_guard<std::mutex> lock(mutex);
        if (!got.empty() && got.back().robots().size() == robots_in_map && got.back().header().stamp_ns() == stamp_ns) {
          return;
        }
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
  }
  FleetMapNode node;
  dds::Participant robots;
  std::mutex mutex;
  std::vector<msg::FleetMap> got;
  dds::Reader<msg::FleetMap> fleet{robots, [this](const msg::FleetMap& m) {
                                     std::lock_guard<std::mutex> lock(mutex);
                                     got.push_back(m);
                                   }};
};

TEST(FleetMapOptions, ShippedConfigLoadsAndBadKeysAreNamed) {
  const FleetMapOptions o = read_fleet_map_options_file(std::string(PIXYSLAM_CONFIG_DIR) + "/fleet_map.yaml");
  EXPECT_DOUBLE_EQ(o.period_s, 1.0);
  EXPECT_EQ(o.fusion.min_common_landmarks, 4);
  EXPECT_EQ(o.fusion.disagreement, fleet_map::FusionOptions::Disagreement::kAlign);
  EXPECT_EQ(o.dds.robot_id, "fleet");
  FleetMapOptions changed = o;
  apply_overrides(changed, {"fleet_map.disagreement=set_aside", "dds.domain_id=7"});
  EXPECT_EQ(changed.fusion.disagreement, fleet_map::FusionOptions::Disagreement::kSetAside);
  EXPECT_EQ(changed.dds.domain_id, 7);
  EXPECT_NE(to_yaml(changed).find("disagreement: set_aside"), std::string::npos) << to_yaml(changed);
  try {
    apply_overrides(changed, {"fleet_map.min_common_landmarks=2"});
    ADD_FAILURE() << "no error";
  } catch (const std::exception& e) {
    EXPECT_NE(std::string(e.what()).find("fleet_map.min_common_landmarks"), std::string::npos) << e.what();
  }
}

TEST(FleetMapConversions, MessageCarriesLandmarksAndVerdicts) {
  fleet_map::RobotMap a = to_robot_map(map_state(5, 0.0));
  a.robot_id = "robot1";
  ASSERT_EQ(a.landmarks.size(), 6u);
  EXPECT_EQ(a.stamp_ns, 5u);
  EXPECT_DOUBLE_EQ(a.landmarks[4].mean.x(), 1.5);
  fleet_map::RobotMap b = a;
  b.robot_id = "robot2";
  const fleet_map::FleetMap fused = fleet_map::fuse_maps({a, b});
  const msg::FleetMap m = to_fleet_map_msg(fused, {a, b}, 99);
  EXPECT_EQ(m.header().stamp_ns(), 99u);
  EXPECT_EQ(m.header().frame_id(), "map");
  ASSERT_EQ(m.landmarks().size(), 6u);
  EXPECT_EQ(m.landmarks()[0].robots(), 2u);
  EXPECT_NEAR(m.landmarks()[0].cov_xx_m2(), 0.005, 1e-12);
  ASSERT_EQ(m.robots().size(), 2u);
  EXPECT_EQ(m.robots()[1].robot_id(), "robot2");
  EXPECT_EQ(m.robots()[1].verdict(), "agrees");
  EXPECT_EQ(m.robots()[1].map_stamp_ns(), 5u);
}

TEST(FleetMapNode, FusesEveryRobotsMapFromDds) {
  // Given the node and two robots' estimators on one domain,
  FleetBench bench;
  FleetMapNode& node = bench.node;
  dds::Writer<msg::MapState> robot1(bench.robots, "robot1"), robot2(bench.robots, "robot2");
  ASSERT_TRUE(robot1.wait_for_readers(1, std::chrono::seconds(10)));
  ASSERT_TRUE(robot2.wait_for_readers(1, std::chrono::seconds(10)));
  // when both publish their maps (robot2's twice, the newest 2 cm to the right),
  msg::MapState one = map_state(1000, 0.0), two = map_state(1000, 0.0), newer = map_state(2000, 0.02);
  ASSERT_TRUE(robot1.publish(one));
  ASSERT_TRUE(robot2.publish(two));
  ASSERT_TRUE(robot2.publish(newer));
  // then a fleet map arrives with both robots' landmarks fused.
  bench.wait_for(2, 2000);
  node.stop();
  std::lock_guard<std::mutex> lock(bench.mutex);
  ASSERT_FALSE(bench.got.empty());
  const msg::FleetMap& last = bench.got.back();
  EXPECT_EQ(last.header().robot_id(), "fleet");
  ASSERT_EQ(last.robots().size(), 2u);
  EXPECT_EQ(last.robots()[0].robot_id(), "robot1");
  EXPECT_EQ(last.robots()[1].map_stamp_ns(), 2000u);
  ASSERT_EQ(last.landmarks().size(), 6u);
  EXPECT_EQ(last.landmarks()[0].robots(), 2u);
  EXPECT_NEAR(last.landmarks()[0].x_m(), 0.01, 0.011);  // between the two
  const FleetMapCounters c = node.counters();
  EXPECT_EQ(c.map_states, 3u);
  EXPECT_EQ(c.robots, 2u);
  EXPECT_GE(c.fleet_maps, 1u);
}

// Hostile but well-formed MapStates: one stamped 2^64 - 1 does not freeze the
// robot's map (the next real one, far older, is a restart and is taken), and
// robot ids beyond max_robots are dropped and counted.
TEST(FleetMapNode, AFarFutureStampAndInventedRobotsAreBounded) {
  FleetBench bench(2);
  FleetMapNode& node = bench.node;
  dds::Writer<msg::MapState> robot1(bench.robots, "robot1"), robot2(bench.robots, "robot2"),
      robot3(bench.robots, "robot3");
  ASSERT_TRUE(robot1.wait_for_readers(1, std::chrono::seconds(10)));
  ASSERT_TRUE(robot2.wait_for_readers(1, std::chrono::seconds(10)));
  ASSERT_TRUE(robot3.wait_for_readers(1, std::chrono::seconds(10)));
  const std::uint64_t t = 1'000'000'000'000ull;
  msg::MapState hostile = map_state(~0ull, 5.0), real = map_state(t, 0.0), two = map_state(t, 0.0),
                three = map_state(t, 0.0);
  ASSERT_TRUE(deliver(robot1, hostile));
  ASSERT_TRUE(deliver(robot1, real));
  ASSERT_TRUE(deliver(robot2, two));
  ASSERT_TRUE(deliver(robot3, three));
  bench.wait_for(2, t);
  node.stop();
  const FleetMapCounters c = node.counters();
  EXPECT_EQ(c.restarts, 1u);
  EXPECT_EQ(c.robots_over_limit, 1u);
  EXPECT_EQ(c.robots, 2u);
  std::lock_guard<std::mutex> lock(bench.mutex);
  ASSERT_FALSE(bench.got.empty());
  EXPECT_EQ(bench.got.back().header().stamp_ns(), t);
  ASSERT_EQ(bench.got.back().landmarks().size(), 6u);
  EXPECT_NEAR(bench.got.back().landmarks()[0].x_m(), 0.0, 1e-9);  // the real map, not the hostile one
}

// Robot ids invented once (or robots that left) fill max_robots; once silent
// for robot_timeout_s they leave the fusion, and a real robot takes their place.
TEST(FleetMapNode, SilentRobotsTimeOutAndFreeTheirPlaces) {
  FleetBench bench(2, 2.0);
  FleetMapNode& node = bench.node;
  dds::Writer<msg::MapState> ghost1(bench.robots, "ghost1"), ghost2(bench.robots, "ghost2"),
      robot(bench.robots, "robot3");
  for (dds::Writer<msg::MapState>* w : {&ghost1, &ghost2, &robot}) {
    ASSERT_TRUE(w->wait_for_readers(1, std::chrono::seconds(10)));
  }
  const std::uint64_t t = 1'000'000'000'000ull;
  msg::MapState ghost = map_state(t, 0.0), first = map_state(t + 1, 0.0), second = map_state(t + 2, 0.0);
  ASSERT_TRUE(deliver(ghost1, ghost));
  ASSERT_TRUE(deliver(ghost2, ghost));
  ASSERT_TRUE(deliver(robot, first));  // no place: dropped
  EXPECT_EQ(node.counters().robots_over_limit, 1u);
  std::this_thread::sleep_for(std::chrono::milliseconds(2500));
  ASSERT_TRUE(deliver(robot, second));
  bench.wait_for(1, t + 2);
  node.stop();
  const FleetMapCounters c = node.counters();
  EXPECT_EQ(c.robots_timed_out, 2u);
  EXPECT_EQ(c.robots_over_limit, 1u);
  EXPECT_EQ(c.robots, 1u);
  std::lock_guard<std::mutex> lock(bench.mutex);
  ASSERT_FALSE(bench.got.empty());
  ASSERT_EQ(bench.got.back().robots().size(), 1u);
  EXPECT_EQ(bench.got.back().robots()[0].robot_id(), "robot3");
  EXPECT_EQ(bench.got.back().header().stamp_ns(), t + 2);
}

}  // namespace
}  // namespace pixyslam::fleet_map_node
