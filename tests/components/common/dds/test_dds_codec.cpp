// The topics' CDR payloads (to_cdr / from_cdr, strict header decoding, the
// topic catalogue) and topic-name patterns (select_topics): pure, no DDS.
#include <cstdint>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "pixyslam/dds/cdr_payload.h"
#include "pixyslam/dds/newest_stamp.h"
#include "pixyslam/dds/topic_selection.h"
#include "pixyslam/dds/topics.h"
#include "pixyslam/dds/wire_text.h"
#include "sample_messages.h"

namespace pixyslam::dds {
namespace {

using test::sample_odometry;

// ---------------------------------------------------------------- CDR payloads

TEST(CdrPayload, CarriesTheEncapsulationHeaderAndRoundTrips) {
  msg::Odometry m = sample_odometry(3);
  m.header().seq(42);
  m.header().robot_id("r1");
  const std::vector<std::uint8_t> bytes = to_cdr(m);
  ASSERT_GE(bytes.size(), 4u);
  EXPECT_EQ(bytes[0], 0x00);  // CDR_LE, options 0
  EXPECT_EQ(bytes[1], 0x01);
  EXPECT_EQ(bytes[2], 0x00);
  EXPECT_EQ(bytes[3], 0x00);
  msg::Odometry back;
  std::string error;
  ASSERT_TRUE(from_cdr(bytes, back, error)) << error;
  EXPECT_EQ(back, m);

  SampleHeader header;
  ASSERT_TRUE(decode_header("pixyslam::msg::Odometry", bytes.data(), bytes.size(), header, error)) << error;
  EXPECT_EQ(header.seq, 42u);
  EXPECT_EQ(header.stamp_ns, m.header().stamp_ns());
  EXPECT_EQ(header.robot_id, "r1");
  EXPECT_EQ(header.frame_id, "base_link");
}

TEST(CdrPayload, StrictDecodingRejectsCutPaddedAndMistypedPayloads) {
  msg::Odometry m = sample_odometry(5);
  m.header().robot_id("r1");
  std::vector<std::uint8_t> bytes = to_cdr(m);
  SampleHeader header;
  std::string error;

  std::vector<std::uint8_t> cut(bytes.begin(), bytes.end() - 3);
  EXPECT_FALSE(decode_header("pixyslam::msg::Odometry", cut.data(), cut.size(), header, error));
  EXPECT_FALSE(error.empty());

  std::vector<std::uint8_t> padded = bytes;  // alignment padding (zeros) is fine
  padded.insert(padded.end(), {0, 0});
  EXPECT_TRUE(decode_header("pixyslam::msg::Odometry", padded.data(), padded.size(), header, error)) << error;
  std::vector<std::uint8_t> garbage = bytes;  // anything else after the sample is not
  garbage.insert(garbage.end(), {0xAB, 0xCD, 0xEF, 0x01, 0x02, 0x03, 0x04, 0x05});
  EXPECT_FALSE(decode_header("pixyslam::msg::Odometry", garbage.data(), garbage.size(), header, error));

  // An Odometry payload is not a MapState.
  EXPECT_FALSE(decode_header("pixyslam::msg::MapState", bytes.data(), bytes.size(), header, error));
  EXPECT_FALSE(decode_header("pixyslam::msg::Nope", bytes.data(), bytes.size(), header, error));
  EXPECT_NE(error.find("unknown type"), std::string::npos) << error;
  EXPECT_FALSE(decode_header("pixyslam::msg::Odometry", bytes.data(), 2, header, error));
}

TEST(CdrPayload, KnownTopicsAreTheSystemsTopicsWithTheirDdsTypeNames) {
  const auto& topics = known_topics();
  ASSERT_EQ(topics.size(), 8u);
  EXPECT_EQ(topics[0].topic, dds::kOdometryTopic);
  EXPECT_EQ(topics[0].type_name, "pixyslam::msg::Odometry");
  EXPECT_EQ(topics[0].idl_stem, "odometry");
  EXPECT_EQ(topics[2].type_name, "pixyslam::msg::MapState");
  ASSERT_NE(find_topic("pixyslam/ground_truth"), nullptr);
  EXPECT_EQ(find_topic("pixyslam/ground_truth")->type_name, "pixyslam::msg::GroundTruth");
  EXPECT_EQ(find_topic("odometry"), nullptr);
  EXPECT_EQ(topics[4].topic, dds::kDiagnosticsTopic);
  EXPECT_EQ(topics[4].type_name, "pixyslam::msg::Diagnostics");
  EXPECT_EQ(topics[5].topic, dds::kOptimisedMapTopic);
  EXPECT_EQ(topics[5].type_name, "pixyslam::msg::OptimisedMap");
  EXPECT_EQ(topics[5].idl_stem, "optimised_map");
  ASSERT_NE(find_topic("pixyslam/optimised_map"), nullptr);
  EXPECT_EQ(topics[6].topic, dds::kRobotSightingTopic);
  EXPECT_EQ(topics[6].type_name, "pixyslam::msg::RobotSighting");
  EXPECT_EQ(topics[6].idl_stem, "robot_sighting");
  EXPECT_EQ(topics[7].topic, dds::kFleetMapTopic);
  EXPECT_EQ(topics[7].type_name, "pixyslam::msg::FleetMap");
}

// ---------------------------------------------------------------- topic patterns

// A robot_id or participant name from the network in a log line: no terminal
// escape gets through, and a long one is cut.
TEST(WireText, ControlBytesAreReplacedAndLongTextIsCut) {
  EXPECT_EQ(printable("robot1"), "robot1");
  EXPECT_EQ(printable(std::string("a\x1b[2Jb\n\x7f\0c", 10)), "a?[2Jb???c");
  EXPECT_EQ(printable(std::string(100, 'x'), 10), std::string(10, 'x') + "...");
  EXPECT_EQ(printable("caf\xc3\xa9"), "caf\xc3\xa9");  // UTF-8 kept
}

// 8-bit controls act on terminals too: C1 (U+009B is an escape-sequence start,
// U+0085 a line break) and raw bytes that are no UTF-8 become '?'; a cut never
// splits a character.
TEST(WireText, C1ControlsAndBytesThatAreNotUtf8AreReplaced) {
  EXPECT_EQ(printable("a\xc2\x9b" "31mb\xc2\x85" "c"), "a?31mb?c");
  EXPECT_EQ(printable("a\x9b" "31m"), "a?31m");                      // a lone continuation byte
  EXPECT_EQ(printable("\xc0\xaf\xe0\x80\xaf"), "?????");         // overlong forms
  EXPECT_EQ(printable("\xed\xa0\x80"), "???");                     // a surrogate
  EXPECT_EQ(printable("\xf4\x90\x80\x80"), "????");               // above U+10FFFF
  EXPECT_EQ(printable("x\xe2\x82"), "x??");                         // cut short
  EXPECT_EQ(printable("\xe2\x82\xac\xf0\x9f\x98\x80\xc2\xa0"), "\xe2\x82\xac\xf0\x9f\x98\x80\xc2\xa0");
  EXPECT_EQ(printable("ab\xe2\x82\xac", 4), "ab...");  // the euro sign would not fit whole
  EXPECT_EQ(printable("ab\xe2\x82\xac", 5), "ab\xe2\x82\xac");
}

// A reader of the newest state: stale samples (a little older than the newest)
// are dropped, but one stamp far ahead does not make every later sample stale.
TEST(NewestStamp, DropsStaleSamplesButNotEverythingAfterAStampFarAhead) {
  NewestStamp order(10);
  EXPECT_TRUE(order.take(100));
  EXPECT_TRUE(order.take(100));  // the same stamp again: taken
  EXPECT_FALSE(order.take(95));  // a late joiner's older state
  EXPECT_TRUE(order.take(~std::uint64_t{0}));
  EXPECT_TRUE(order.take(105));  // far behind: the time went back
  EXPECT_TRUE(order.take(110));
  EXPECT_FALSE(order.take(100));  // stale again, relative to 110
  EXPECT_EQ(order.taken(), 5u);
  EXPECT_EQ(order.stale(), 2u);
  EXPECT_EQ(order.time_resets(), 1u);
  EXPECT_EQ(order.newest_ns(), 110u);
}

TEST(TopicSelection, GlobMatchesWholeNames) {
  EXPECT_TRUE(glob_match("pixyslam/*", "pixyslam/odometry"));
  EXPECT_TRUE(glob_match("*", "pixyslam/odometry"));
  EXPECT_TRUE(glob_match("*/odometry", "pixyslam/odometry"));
  EXPECT_TRUE(glob_match("pixyslam/*_*", "pixyslam/map_state"));
  EXPECT_TRUE(glob_match("pixyslam/?ap_state", "pixyslam/map_state"));
  EXPECT_TRUE(glob_match("pixyslam/odometry", "pixyslam/odometry"));
  EXPECT_FALSE(glob_match("pixyslam/odometr", "pixyslam/odometry"));
  EXPECT_FALSE(glob_match("pixyslam/*_*", "pixyslam/odometry"));
  EXPECT_FALSE(glob_match("pixyslam/?", "pixyslam/odometry"));
  EXPECT_FALSE(glob_match("other/*", "pixyslam/odometry"));
  EXPECT_TRUE(glob_match("**a*", "a"));
  EXPECT_FALSE(glob_match("", "a"));
  EXPECT_TRUE(glob_match("", ""));
}

const std::vector<std::string> kKnown = {"pixyslam/odometry", "pixyslam/landmark_observation",
                                         "pixyslam/map_state", "pixyslam/ground_truth"};

TEST(TopicSelection, IncludesExcludesAndKeepsTheKnownOrder) {
  EXPECT_EQ(select_topics({"pixyslam/*", "!pixyslam/ground_truth"}, kKnown).topics,
            (std::vector<std::string>{"pixyslam/odometry", "pixyslam/landmark_observation", "pixyslam/map_state"}));
  EXPECT_EQ(select_topics({"!pixyslam/ground_truth", "!*observation"}, kKnown).topics,
            (std::vector<std::string>{"pixyslam/odometry", "pixyslam/map_state"}));
  EXPECT_EQ(select_topics({"pixyslam/map_state", "pixyslam/odometry"}, kKnown).topics,
            (std::vector<std::string>{"pixyslam/odometry", "pixyslam/map_state"}));
  EXPECT_EQ(select_topics({"pixyslam/*o*", "pixyslam/odometry"}, kKnown).topics.size(), 3u);  // overlap is fine
}

TEST(TopicSelection, ErrorsNameThePattern) {
  TopicSelection s = select_topics({"pixyslam/odometry", "pixyslam/odometri"}, kKnown);
  EXPECT_EQ(s.bad_pattern, 1u);
  EXPECT_NE(s.error.find("unknown topic 'pixyslam/odometri'"), std::string::npos) << s.error;
  s = select_topics({"other/*"}, kKnown);
  EXPECT_NE(s.error.find("pattern 'other/*' matches no known topic"), std::string::npos) << s.error;
  s = select_topics({"pixyslam/*", "!pixyslam/*"}, kKnown);
  EXPECT_EQ(s.error, "the patterns select no topic");
  EXPECT_TRUE(s.topics.empty());
  s = select_topics({"!x"}, kKnown);
  EXPECT_NE(s.error.find("unknown topic 'x'"), std::string::npos) << s.error;
  s = select_topics({"pixyslam/*", "!"}, kKnown);
  EXPECT_EQ(s.bad_pattern, 1u);
  EXPECT_EQ(s.error, "empty topic pattern");
  s = select_topics({"!pixyslam/map_state", "!pixyslam/map_state"}, kKnown);
  EXPECT_NE(s.error.find("given twice"), std::string::npos) << s.error;
  EXPECT_FALSE(select_topics({}, kKnown).error.empty());
}

}  // namespace
}  // namespace pixyslam::dds
