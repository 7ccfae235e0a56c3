// The printers of pixyslam_spy echo: every field, nested structs and
// sequences, in IDL order, as YAML documents and JSON lines; and hz's gap statistics.
#include <cmath>
#include <limits>
#include <string>

#include <gtest/gtest.h>

#include "pixyslam/log_tool/message_format.h"

namespace pixyslam::log_tool {
namespace {

msg::Odometry odometry() {
  msg::Odometry m;
  m.header().stamp_ns(1700000000123456789ull);
  m.header().seq(7);
  m.header().robot_id("robot1");
  m.header().frame_id("base_link");
  m.v_mps(0.1);
  m.w_radps(-0.25);
  m.period_s(0.1);
  m.distance_m(0.01);
  m.rotation_rad(-0.025);
  m.encoder_samples(5);
  return m;
}

msg::LandmarkObservation observation() {
  msg::LandmarkObservation m;
  m.header().seq(3);
  m.header().frame_id("camera");
  m.camera_frame(42);
  m.blocks_in_frame(2);
  m.blocks_rejected(1);
  msg::LandmarkDetection d;
  d.landmark_id(12);
  d.range_m(1.5);
  d.bearing_rad(-0.125);
  d.range_sigma_m(0.07);
  d.bearing_sigma_rad(0.027);
  d.block().signature(10);
  d.block().x_px(160);
  d.block().y_px(100);
  d.block().width_px(20);
  d.block().height_px(40);
  d.block().angle_deg(-3);
  m.detections().push_back(d);
  return m;
}

// The map optimiser's solution: two keyframes, a landmark with its marginal
// covariance and one without (NaN before the first whole-problem solve).
msg::OptimisedMap optimised_map() {
  msg::OptimisedMap m;
  m.header().stamp_ns(2000);
  m.header().seq(4);
  m.header().robot_id("robot1");
  m.header().frame_id("map");
  m.current_pose().x_m(1.5);
  m.current_pose().theta_rad(0.25);
  m.keyframe_count(9);
  for (int i = 0; i < 2; ++i) {
    msg::OptimisedKeyframe k;
    k.stamp_ns(1000u + 500u * static_cast<unsigned>(i));
    k.pose().x_m(0.5 * i);
    k.pose().y_m(0.125 - 0.25 * i);
    k.pose().theta_rad(0.0625 * i);
    m.keyframes().push_back(k);
  }
  msg::OptimisedLandmark l;
  l.landmark_id(12);
  l.x_m(2.5);
  l.y_m(-1.25);
  l.cov_xx_m2(0.01);
  l.cov_xy_m2(-0.002);
  l.cov_yy_m2(0.04);
  l.observations(17);
  m.landmarks().push_back(l);
  l.landmark_id(13);
  l.cov_xx_m2(std::numeric_limits<double>::quiet_NaN());
  l.cov_xy_m2(std::numeric_limits<double>::quiet_NaN());
  l.cov_yy_m2(std::numeric_limits<double>::quiet_NaN());
  l.observations(1);
  m.landmarks().push_back(l);
  m.whole_problem(true);
  m.converged(false);
  m.iterations(23);
  m.initial_cost(812.5);
  m.final_cost(3.75);
  m.solve_time_s(0.125);
  m.cpu_time_s(7.5);
  m.keyframes_free(6);
  m.residuals(140);
  m.odometry_sequence(88);
  m.observation_sequence(41);
  return m;
}

TEST(SpyFormat, OdometryAsJsonLineHasEveryFieldInIdlOrder) {
  EXPECT_EQ(to_json_line(to_value(odometry())),
            "{\"header\":{\"stamp_ns\":1700000000123456789,\"seq\":7,\"robot_id\":\"robot1\","
            "\"frame_id\":\"base_link\"},\"v_mps\":0.1,\"w_radps\":-0.25,\"period_s\":0.1,"
            "\"distance_m\":0.01,\"rotation_rad\":-0.025,\"encoder_samples\":5}");
}

TEST(SpyFormat, OdometryAsYamlDocument) {
  EXPECT_EQ(to_yaml_document(to_value(odometry())),
            "---\n"
            "header:\n"
            "  stamp_ns: 1700000000123456789\n"
            "  seq: 7\n"
            "  robot_id: \"robot1\"\n"
            "  frame_id: \"base_link\"\n"
            "v_mps: 0.1\n"
            "w_radps: -0.25\n"
            "period_s: 0.1\n"
            "distance_m: 0.01\n"
            "rotation_rad: -0.025\n"
            "encoder_samples: 5\n");
}

TEST(SpyFormat, NestedSequenceOfStructsInYaml) {
  EXPECT_EQ(to_yaml_document(to_value(observation())),
            "---\n"
            "header:\n"
            "  stamp_ns: 0\n"
            "  seq: 3\n"
            "  robot_id: \"\"\n"
            "  frame_id: \"camera\"\n"
            "camera_frame: 42\n"
            "blocks_in_frame: 2\n"
            "blocks_rejected: 1\n"
            "detections:\n"
            "  - landmark_id: 12\n"
            "    range_m: 1.5\n"
            "    bearing_rad: -0.125\n"
            "    range_sigma_m: 0.07\n"
            "    bearing_sigma_rad: 0.027\n"
            "    block:\n"
            "      signature: 10\n"
            "      x_px: 160\n"
            "      y_px: 100\n"
            "      width_px: 20\n"
            "      height_px: 40\n"
            "      angle_deg: -3\n");
}

TEST(SpyFormat, NestedSequenceOfStructsInJson) {
  EXPECT_EQ(to_json_line(to_value(observation())),
            "{\"header\":{\"stamp_ns\":0,\"seq\":3,\"robot_id\":\"\",\"frame_id\":\"camera\"},"
            "\"camera_frame\":42,\"blocks_in_frame\":2,\"blocks_rejected\":1,\"detections\":[{\"landmark_id\":12,"
            "\"range_m\":1.5,\"bearing_rad\":-0.125,\"range_sigma_m\":0.07,\"bearing_sigma_rad\":0.027,"
            "\"block\":{\"signature\":10,\"x_px\":160,\"y_px\":100,\"width_px\":20,\"height_px\":40,"
            "\"angle_deg\":-3}}]}");
}

TEST(SpyFormat, EmptySequenceAndFixedArrayInMapState) {
  msg::MapState m;
  m.pose_covariance()[0] = 0.5;
  m.pose_covariance()[8] = 1e-9;
  msg::LandmarkEstimate l;
  l.landmark_id(3);
  l.times_observed(9);
  m.landmarks().push_back(l);
  const std::string yaml = to_yaml_document(to_value(m));
  EXPECT_NE(yaml.find("\npose_covariance: [0.5, 0, 0, 0, 0, 0, 0, 0, 1e-09]\n"), std::string::npos) << yaml;
  EXPECT_NE(yaml.find("\nparticle_poses: []\n"), std::string::npos) << yaml;
  EXPECT_NE(yaml.find("\nlandmarks:\n  - landmark_id: 3\n    x_m: 0\n"), std::string::npos) << yaml;
  EXPECT_NE(yaml.find("\n    times_observed: 9\nupdate_time_s: 0\n"), std::string::npos) << yaml;
  EXPECT_NE(yaml.find("\nsamples_late: 0\n"), std::string::npos) << yaml;
  const std::string json = to_json_line(to_value(m));
  EXPECT_NE(json.find("\"pose_covariance\":[0.5,0,0,0,0,0,0,0,1e-09],\"best_pose\":{\"x_m\":0,"), std::string::npos)
      << json;
  EXPECT_NE(json.find("\"particle_poses\":[],\"landmarks\":[{\"landmark_id\":3,"), std::string::npos) << json;
}

TEST(SpyFormat, GroundTruthFieldsCanBeFoundByPath) {
  msg::GroundTruth m;
  m.pose().theta_rad(1.25);
  m.landmarks().resize(2);
  const Value v = to_value(m);
  ASSERT_NE(v.find("pose.theta_rad"), nullptr);
  EXPECT_EQ(v.find("pose.theta_rad")->float_value(), 1.25);
  ASSERT_NE(v.find("landmarks"), nullptr);
  EXPECT_EQ(v.find("landmarks")->items().size(), 2u);
  EXPECT_EQ(v.find("pose.nothing"), nullptr);
}

// compare --ignore / --match: a misspelt field is refused, not silently unused.
TEST(CompareFields, FieldPathsAreCheckedAgainstAMessage) {
  msg::MapState m;
  m.landmarks().resize(2);
  const Value v = to_value(m);
  for (const char* good : {"header.stamp_ns", "mean_pose.x_m", "odometry_sequence", "landmarks", "landmarks.x_m",
                           "landmarks[1].cov_xy_m2", "pose_covariance", "particle_poses.theta_rad"}) {
    EXPECT_TRUE(field_path_exists(v, good)) << good;  // particle_poses is empty: not checkable below it
  }
  for (const char* bad : {"nosuchfield", "mean_pose.z_m", "landmarks.z", "mean_pose.x_m.below", "header.", ""}) {
    EXPECT_FALSE(field_path_exists(v, bad)) << bad;
  }
}

TEST(SpyFormat, OptimisedMapAsYamlDocumentHasEveryFieldInIdlOrder) {
  EXPECT_EQ(to_yaml_document(to_value(optimised_map())),
            "---\n"
            "header:\n"
            "  stamp_ns: 2000\n"
            "  seq: 4\n"
            "  robot_id: \"robot1\"\n"
            "  frame_id: \"map\"\n"
            "current_pose:\n"
            "  x_m: 1.5\n"
            "  y_m: 0\n"
            "  theta_rad: 0.25\n"
            "keyframe_count: 9\n"
            "keyframes:\n"
            "  - stamp_ns: 1000\n"
            "    pose:\n"
            "      x_m: 0\n"
            "      y_m: 0.125\n"
            "      theta_rad: 0\n"
            "  - stamp_ns: 1500\n"
            "    pose:\n"
            "      x_m: 0.5\n"
            "      y_m: -0.125\n"
            "      theta_rad: 0.0625\n"
            "landmarks:\n"
            "  - landmark_id: 12\n"
            "    x_m: 2.5\n"
            "    y_m: -1.25\n"
            "    cov_xx_m2: 0.01\n"
            "    cov_xy_m2: -0.002\n"
            "    cov_yy_m2: 0.04\n"
            "    observations: 17\n"
            "  - landmark_id: 13\n"
            "    x_m: 2.5\n"
            "    y_m: -1.25\n"
            "    cov_xx_m2: .nan\n"
            "    cov_xy_m2: .nan\n"
            "    cov_yy_m2: .nan\n"
            "    observations: 1\n"
            "whole_problem: true\n"
            "converged: false\n"
            "iterations: 23\n"
            "initial_cost: 812.5\n"
            "final_cost: 3.75\n"
            "solve_time_s: 0.125\n"
            "cpu_time_s: 7.5\n"
            "keyframes_free: 6\n"
            "residuals: 140\n"
            "odometry_sequence: 88\n"
            "observation_sequence: 41\n");
}

TEST(SpyFormat, OptimisedMapAsJsonLine) {
  const std::string json = to_json_line(to_value(optimised_map()));
  EXPECT_EQ(json.rfind("{\"header\":{\"stamp_ns\":2000,\"seq\":4,\"robot_id\":\"robot1\",\"frame_id\":\"map\"},"
                      "\"current_pose\":{\"x_m\":1.5,\"y_m\":0,\"theta_rad\":0.25},\"keyframe_count\":9,"
                      "\"keyframes\":[{\"stamp_ns\":1000,",
                      0),
            0u)
      << json;
  // Booleans as JSON booleans, a NaN covariance as null, the statistics last.
  EXPECT_NE(json.find("{\"landmark_id\":13,\"x_m\":2.5,\"y_m\":-1.25,\"cov_xx_m2\":null,\"cov_xy_m2\":null,"
                      "\"cov_yy_m2\":null,\"observations\":1}],\"whole_problem\":true,\"converged\":false,"
                      "\"iterations\":23,"),
            std::string::npos)
      << json;
  EXPECT_NE(json.find(",\"residuals\":140,\"odometry_sequence\":88,\"observation_sequence\":41}"), std::string::npos)
      << json;
  const Value v = to_value(optimised_map());
  ASSERT_NE(v.find("keyframes"), nullptr);
  EXPECT_EQ(v.find("keyframes")->items().size(), 2u);
  ASSERT_NE(v.find("converged"), nullptr);
  EXPECT_EQ(v.find("converged")->kind(), Value::Kind::kBool);
  EXPECT_FALSE(v.find("converged")->bool_value());
  EXPECT_TRUE(v.find("whole_problem")->bool_value());
}

TEST(CompareValues, OptimisedMapBooleansAndLandmarksDiffer) {
  msg::OptimisedMap changed = optimised_map();
  EXPECT_TRUE(compare_values(to_value(optimised_map()), to_value(changed), {}, 0.0, 10).empty());
  changed.converged(true);
  changed.landmarks()[1].cov_yy_m2(0.5);
  const auto lines = compare_values(to_value(optimised_map()), to_value(changed), {}, 0.0, 10);
  ASSERT_EQ(lines.size(), 2u);
  EXPECT_EQ(lines[0], "landmarks[1].cov_yy_m2: .nan != 0.5");
  EXPECT_EQ(lines[1], "converged: false != true");
}

// pixyslam_log compare --match: MapStates paired by the inputs they include.
// A replay that got frame 2 after odometry 3 (applied at its stamp) publishes
// the state after odometry 3 without frame 2, then the one with both: the
// states with the same inputs pair up, the two intermediate ones do not.
TEST(PairMessages, ByKeyFieldsInOrderAndByPositionWithout) {
  auto state = [](std::uint64_t odometry, std::uint64_t observation) {
    msg::MapState m;
    m.odometry_sequence(odometry);
    m.observation_sequence(observation);
    return to_value(m);
  };
  const std::vector<Value> live = {state(1, 0), state(2, 0), state(2, 1), state(2, 2), state(3, 2), state(3, 3)};
  const std::vector<Value> replay = {state(1, 0), state(2, 0), state(2, 1), state(3, 1), state(3, 2), state(3, 3)};
  const MessagePairs p = pair_messages(live, replay, {"odometry_sequence", "observation_sequence"});
  const std::vector<std::pair<std::size_t, std::size_t>> expected = {{0, 0}, {1, 1}, {2, 2}, {4, 4}, {5, 5}};
  EXPECT_EQ(p.pairs, expected);
  EXPECT_EQ(p.only_first, std::vector<std::size_t>{3});
  EXPECT_EQ(p.only_second, std::vector<std::size_t>{3});
  EXPECT_EQ(pairs_before_first_unmatched(p), 3u);  // (0, 0), (1, 1), (2, 2)
  // Repeated keys pair in order; by position without key fields.
  const MessagePairs twice = pair_messages({state(1, 0), state(1, 0)}, {state(1, 0)}, {"odometry_sequence"});
  EXPECT_EQ(twice.pairs.size(), 1u);
  EXPECT_EQ(twice.only_first, std::vector<std::size_t>{1});
  const MessagePairs by_position = pair_messages(live, {state(9, 9)}, {});
  ASSERT_EQ(by_position.pairs.size(), 1u);
  EXPECT_EQ(by_position.pairs[0], std::make_pair(std::size_t{0}, std::size_t{0}));
  EXPECT_EQ(by_position.only_first.size(), 5u);
  EXPECT_EQ(pairs_before_first_unmatched(by_position), 1u);
  EXPECT_EQ(pairs_before_first_unmatched(pair_messages(live, live, {"odometry_sequence"})), live.size());
  // --until-unmatched: nothing before the first unmatched message may differ,
  // and at least half of all pairs must agree, wherever that message is (a CI
  // replay of 2026-11-27: 346 of 839 pairs before it, none after it differing).
  EXPECT_TRUE(until_unmatched_passes(839, 0, 0));
  EXPECT_TRUE(until_unmatched_passes(838, 0, 144));
  EXPECT_TRUE(until_unmatched_passes(10, 0, 5));
  EXPECT_FALSE(until_unmatched_passes(10, 0, 6));
  EXPECT_FALSE(until_unmatched_passes(839, 1, 0));
  EXPECT_TRUE(until_unmatched_passes(0, 0, 0));
}

TEST(SpyFormat, StringsAreEscapedAndNonFiniteNumbersStayValid) {
  Value v = Value::structure();
  v.add("text", Value::string("a\"b\\c\nd\x01"))
      .add("nan", Value::number(std::numeric_limits<double>::quiet_NaN()))
      .add("inf", Value::number(-std::numeric_limits<double>::infinity()));
  EXPECT_EQ(to_json_line(v), "{\"text\":\"a\\\"b\\\\c\\nd\\u0001\",\"nan\":null,\"inf\":null}");
  EXPECT_EQ(to_yaml_document(v), "---\ntext: \"a\\\"b\\\\c\\nd\\u0001\"\nnan: .nan\ninf: -.inf\n");
}

TEST(SpyFormat, DoublesReadBackExactly) {
  for (const double d : {0.1, 1.0 / 3.0, -2.5e-300, 6.02214076e23, 0.0, 17.5}) {
    EXPECT_EQ(std::stod(format_double(d)), d) << format_double(d);
  }
  EXPECT_EQ(format_double(0.1), "0.1");
  EXPECT_EQ(format_double(3.0), "3");
}

TEST(SpyFormat, GapStatistics) {
  const GapStats s = gap_stats({0.0, 0.1, 0.3, 0.4});  // gaps 0.1, 0.2, 0.1
  EXPECT_EQ(s.messages, 4u);
  EXPECT_NEAR(s.mean_s, 0.4 / 3.0, 1e-12);
  EXPECT_NEAR(s.rate_hz, 7.5, 1e-9);
  EXPECT_NEAR(s.min_s, 0.1, 1e-12);
  EXPECT_NEAR(s.max_s, 0.2, 1e-12);
  EXPECT_NEAR(s.std_s, std::sqrt(2.0) / 30.0, 1e-12);  // population std of {0.1, 0.2, 0.1}
  EXPECT_EQ(gap_stats({1.0}).rate_hz, 0.0);
  EXPECT_EQ(gap_stats({}).messages, 0u);
}

// pixyslam_log compare: field-by-field differences of two messages.
TEST(CompareValues, IdenticalMessagesHaveNoDifferences) {
  EXPECT_TRUE(compare_values(to_value(observation()), to_value(observation()), {}, 0.0, 10).empty());
}

TEST(CompareValues, NamesEveryDifferingFieldByPath) {
  msg::LandmarkObservation changed = observation();
  changed.header().stamp_ns(5);
  changed.detections()[0].range_m(1.5000001);
  changed.detections()[0].block().x_px(161);
  const auto lines = compare_values(to_value(observation()), to_value(changed), {}, 0.0, 10);
  ASSERT_EQ(lines.size(), 3u);
  EXPECT_EQ(lines[0].rfind("header.stamp_ns: ", 0), 0u) << lines[0];
  EXPECT_EQ(lines[1].rfind("detections[0].range_m: 1.5 != 1.5000001", 0), 0u) << lines[1];
  EXPECT_EQ(lines[2].rfind("detections[0].block.x_px: 160 != 161", 0), 0u) << lines[2];
  // At most max_lines.
  EXPECT_EQ(compare_values(to_value(observation()), to_value(changed), {}, 0.0, 2).size(), 2u);
}

TEST(CompareValues, IgnoredPathsWithOrWithoutIndicesAndTolerance) {
  msg::LandmarkObservation changed = observation();
  changed.header().stamp_ns(5);
  changed.detections()[0].range_m(1.5 * (1 + 1e-12));
  EXPECT_EQ(compare_values(to_value(observation()), to_value(changed), {"header.stamp_ns"}, 0.0, 10).size(), 1u);
  EXPECT_TRUE(
      compare_values(to_value(observation()), to_value(changed), {"header.stamp_ns", "detections.range_m"}, 0.0, 10)
          .empty());
  EXPECT_TRUE(
      compare_values(to_value(observation()), to_value(changed), {"header.stamp_ns", "detections[0].range_m"}, 0.0, 10)
          .empty());
  EXPECT_TRUE(compare_values(to_value(observation()), to_value(changed), {"header"}, 1e-9, 10).empty());
  // A tolerance does not hide a real difference.
  changed.detections()[0].range_m(1.6);
  EXPECT_EQ(compare_values(to_value(observation()), to_value(changed), {"header"}, 1e-9, 10).size(), 1u);
}

TEST(CompareValues, ListLengthsAndNaN) {
  msg::LandmarkObservation more = observation();
  more.detections().push_back(more.detections()[0]);
  const auto lines = compare_values(to_value(observation()), to_value(more), {}, 0.0, 10);
  ASSERT_EQ(lines.size(), 1u);
  EXPECT_EQ(lines[0], "detections: 1 items != 2");
  msg::Odometry a = odometry();
  a.v_mps(std::numeric_limits<double>::quiet_NaN());
  msg::Odometry b = a;
  EXPECT_TRUE(compare_values(to_value(a), to_value(b), {}, 0.0, 10).empty());
  b.v_mps(0.0);
  EXPECT_EQ(compare_values(to_value(a), to_value(b), {}, 0.0, 10).size(), 1u);
}

TEST(SpyFormat, DiagnosticsTableOneReportPerProcessSortedAndWrapped) {
  auto report = [](const std::string& robot, const std::string& process, std::uint32_t pid, std::uint8_t level,
                   const std::string& status, int counters) {
    msg::Diagnostics d;
    d.header().robot_id(robot);
    d.process(process);
    d.pid(pid);
    d.level(level);
    d.status(status);
    d.uptime_s(12.4);
    for (int i = 0; i < counters; ++i) {
      msg::DiagnosticCounter c;
      c.name("counter_number_" + std::to_string(i));
      c.value(static_cast<std::uint64_t>(i) * 1000);
      d.counters().push_back(c);
    }
    return d;
  };
  const std::string table = diagnostics_table({report("robot1", "slam_estimator", 40, 1, "observations_gated +2", 2),
                                               report("robot1", "encoder_bridge", 7, 0, "", 8),
                                               report("robot1", "pixy_bridge", 9, 2, "device '/dev/ttyUSB0' is not open", 0)});
  const std::string expected =
      "robot1 encoder_bridge (pid 7): OK, up 12 s\n"
      "    counter_number_0 0 counter_number_1 1000 counter_number_2 2000 counter_number_3 3000\n"
      "    counter_number_4 4000 counter_number_5 5000 counter_number_6 6000 counter_number_7 7000\n"
      "robot1 pixy_bridge (pid 9): ERROR, up 12 s: device '/dev/ttyUSB0' is not open\n"
      "robot1 slam_estimator (pid 40): WARN, up 12 s: observations_gated +2\n"
      "    counter_number_0 0 counter_number_1 1000\n";
  EXPECT_EQ(table, expected);
  // Any participant can publish a report: its texts cannot drive the terminal.
  const std::string hostile = diagnostics_table({report("robot\x1b[2J", "slam\xc2\x9b" "2J", 1, 0, "ok\r\x07", 0)});
  EXPECT_EQ(hostile, "robot?[2J slam?2J (pid 1): OK, up 12 s: ok??\n");
}

// Strings from the network in echo's YAML and JSON: every control character
// (C0, DEL, C1) escaped, bytes that are not UTF-8 as U+FFFD: valid JSON that
// cannot drive a terminal; other UTF-8 as sent.
TEST(SpyFormat, StringsFromTheNetworkAreEscapedAndStayValidUtf8) {
  msg::Odometry m = odometry();
  m.header().robot_id("r\x1b\x7f\xc2\x9b\xff\xc3\xa9\"");
  const std::string json = to_json_line(to_value(m));
  EXPECT_NE(json.find("\"robot_id\":\"r\\u001b\\u007f\\u009b\\ufffd\xc3\xa9\\\"\""), std::string::npos) << json;
  // Line and paragraph separators (YAML 1.1 breaks lines there) and the non-characters.
  m.header().robot_id("a\xe2\x80\xa8" "b\xe2\x80\xa9" "c\xef\xbf\xbf");
  EXPECT_NE(to_json_line(to_value(m)).find("\"robot_id\":\"a\\u2028b\\u2029c\\uffff\""), std::string::npos);
}

}  // namespace
}  // namespace pixyslam::log_tool
