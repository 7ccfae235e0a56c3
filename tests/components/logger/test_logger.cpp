// The logger: sequence analysis (pure), CDR payloads, and a LoggerNode on the
// shipped loopback profile recording what writers in this test publish, read
// back with McapReader (its options: test_logger_options.cpp).
#include <signal.h>
#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

#include "pixyslam/dds/endpoints.h"
#include "pixyslam/log_tool/sequence_check.h"
#include "pixyslam/mcap/mcap_reader.h"
#include "pixyslam/dds/cdr_payload.h"
#include "pixyslam/logger_node/logger_node.h"
#include "pixyslam/logger_node/logger_options.h"
#include "sample_messages.h"

namespace pixyslam::logger_node {
namespace {

using log_tool::analyze_sequence;
using log_tool::describe;
using log_tool::SequenceReport;
using dds::from_cdr;
using dds::known_topics;
using dds::to_cdr;
using dds::TopicInfo;

// ---------------------------------------------------------------- the node

// The logger records everything on its domain, so these tests use a domain of
// their own: other DDS tests (RESOURCE_LOCK serialises only one ctest run) and
// anything else on domain 0 of this machine would be recorded too.
dds::DdsOptions loopback_options() {
  dds::DdsOptions o;
  o.profiles_file = std::string(PIXYSLAM_CONFIG_DIR) + "/dds/profiles.xml";
  o.domain_id = 100 + static_cast<int>(::getpid() % 100);
  o.robot_id = "test_robot";
  return o;
}

// A file in the temp folder, removed at the end unless kept.
class TempFile {
 public:
  explicit TempFile(const std::string& name, const char* keep_env = nullptr) {
    const char* keep = keep_env ? std::getenv(keep_env) : nullptr;
    if (keep != nullptr && *keep != '\0') {
      path_ = keep;
      keep_ = true;
    } else {
      path_ = (std::filesystem::temp_directory_path() /
               ("pixyslam_" + name + "_" + std::to_string(::getpid()) + ".mcap"))
                  .string();
    }
    std::filesystem::remove(path_);
  }
  ~TempFile() {
    if (!keep_) std::filesystem::remove(path_);
  }
  const std::string& path() const { return path_; }

 private:
  std::string path_;
  bool keep_ = false;
};

LoggerOptions node_options(const std::string& path) {
  LoggerOptions o;
  o.output_file = path;
  o.dds = loopback_options();
  o.chunk_size_bytes = 4096;  // many chunks, so that a cut file still holds some
  o.dds.diagnostics_period_s = 0.0;  // no reports of its own: the message counts stay exact
  return o;
}

bool wait_until(const std::function<bool()>& done, std::chrono::seconds timeout) {
  const auto end = std::chrono::steady_clock::now() + timeout;
  while (!done()) {
    if (std::chrono::steady_clock::now() > end) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  return true;
}

std::uint64_t received(const LoggerNode& node, const std::string& topic) {
  for (const TopicCounters& t : node.counters().topics) {
    if (t.topic == topic) return t.received;
  }
  return 0;
}

const TopicCounters& topic_counters(const LoggerCounters& c, const std::string& topic) {
  for (const TopicCounters& t : c.topics) {
    if (t.topic == topic) return t;
  }
  throw std::runtime_error("no counters for " + topic);
}

msg::LandmarkObservation observation(int i) {
  msg::LandmarkObservation m;
  m.header().stamp_ns(1'700'000'000'000'000'000ull + static_cast<std::uint64_t>(i) * 100'000'000ull + 7);
  m.header().frame_id("camera");
  m.camera_frame(static_cast<std::uint32_t>(1000 + i));
  m.blocks_in_frame(static_cast<std::uint32_t>(i % 4 + 1));
  m.blocks_rejected(1);
  for (int k = 0; k < i % 4; ++k) {
    msg::LandmarkDetection d;
    d.landmark_id(10 + k);
    d.range_m(1.0 + 0.1 * i + k);
    d.bearing_rad(-0.3 + 0.05 * k);
    d.range_sigma_m(0.07);
    d.bearing_sigma_rad(0.027);
    msg::PixyBlock block;
    block.signature(static_cast<std::uint16_t>(012 + k));
    block.x_px(static_cast<std::uint16_t>(100 + i));
    block.y_px(50);
    block.width_px(12);
    block.height_px(30);
    block.angle_deg(static_cast<std::int16_t>(-k));
    d.block(block);
    m.detections().push_back(d);
  }
  return m;
}

msg::MapState map_state(int i) {
  msg::MapState m;
  m.header().stamp_ns(1'700'000'000'000'000'000ull + static_cast<std::uint64_t>(i) * 100'000'000ull + 9);
  m.header().frame_id("map");
  msg::Pose2D mean;
  mean.x_m(0.1 * i);
  mean.y_m(-0.05 * i);
  mean.theta_rad(0.01 * i);
  m.mean_pose(mean);
  m.best_pose(mean);
  for (int k = 0; k < 9; ++k) m.pose_covariance()[static_cast<std::size_t>(k)] = 0.001 * (k + 1) * (i + 1);
  m.effective_sample_size(50.0 + i);
  m.particle_count(100);
  for (int k = 0; k < 5; ++k) m.particle_poses().push_back(mean);
  for (int k = 0; k < i % 6; ++k) {
    msg::LandmarkEstimate l;
    l.landmark_id(10 + k);
    l.x_m(1.0 * k);
    l.y_m(2.0 * k);
    l.cov_xx_m2(0.01);
    l.cov_xy_m2(0.001);
    l.cov_yy_m2(0.02);
    l.times_observed(static_cast<std::uint32_t>(i));
    m.landmarks().push_back(l);
  }
  m.update_time_s(0.0001 * i);
  m.odometry_sequence(static_cast<std::uint64_t>(5 * i));
  m.observation_sequence(static_cast<std::uint64_t>(i));
  return m;
}

msg::GroundTruth ground_truth(int i) {
  msg::GroundTruth m;
  m.header().stamp_ns(1'700'000'000'000'000'000ull + static_cast<std::uint64_t>(i) * 100'000'000ull + 3);
  m.header().frame_id("map");
  msg::Pose2D pose;
  pose.x_m(0.2 * i);
  m.pose(pose);
  m.v_mps(0.3);
  m.w_radps(0.01 * i);
  for (int k = 0; k < 3; ++k) {
    msg::TrueLandmark l;
    l.landmark_id(10 + k);
    l.x_m(1.5 * k);
    l.y_m(-1.5 * k);
    m.landmarks().push_back(l);
  }
  return m;
}

msg::OptimisedMap optimised_map(int i) {
  msg::OptimisedMap m;
  m.header().stamp_ns(1'700'000'000'000'000'000ull + static_cast<std::uint64_t>(i) * 500'000'000ull + 11);
  m.header().frame_id("map");
  m.current_pose().x_m(0.5 * i);
  m.keyframe_count(static_cast<std::uint32_t>(3 * i + 1));
  for (int k = 0; k <= 3 * i; ++k) {
    msg::OptimisedKeyframe f;
    f.stamp_ns(1'700'000'000'000'000'000ull + static_cast<std::uint64_t>(k) * 100'000'000ull);
    f.pose().x_m(0.1 * k);
    f.pose().theta_rad(0.01 * k);
    m.keyframes().push_back(f);
  }
  for (int k = 0; k < i % 4; ++k) {
    msg::OptimisedLandmark l;
    l.landmark_id(10 + k);
    l.x_m(1.0 * k);
    l.y_m(-2.0 * k);
    l.cov_xx_m2(0.001 * k);
    l.cov_xy_m2(0.0);
    l.cov_yy_m2(0.002 * k);
    l.observations(static_cast<std::uint32_t>(i + k));
    m.landmarks().push_back(l);
  }
  m.whole_problem(i % 3 == 0);
  m.converged(true);
  m.iterations(static_cast<std::uint32_t>(5 + i));
  m.initial_cost(100.0 / (i + 1));
  m.final_cost(1.0 / (i + 1));
  m.solve_time_s(0.01 * i);
  m.cpu_time_s(0.1 * i);
  m.keyframes_free(static_cast<std::uint32_t>(i));
  m.residuals(static_cast<std::uint32_t>(20 * i));
  m.odometry_sequence(static_cast<std::uint64_t>(50 * i));
  m.observation_sequence(static_cast<std::uint64_t>(5 * i));
  return m;
}

// Every message of `topic` in `reader`, decoded; checks the MCAP fields
// against the header on the way.
template <class Message>
std::vector<Message> decoded(const mcap::McapReader& reader, const std::string& topic) {
  std::vector<Message> out;
  const mcap::McapChannel* channel = reader.find_channel(topic);
  EXPECT_NE(channel, nullptr) << topic;
  if (channel == nullptr) return out;
  for (const mcap::McapMessage& m : reader.messages()) {
    if (m.channel_id != channel->id) continue;
    Message message;
    std::string error;
    EXPECT_TRUE(from_cdr(m.data, message, error)) << topic << ": " << error;
    EXPECT_EQ(m.sequence, static_cast<std::uint32_t>(message.header().seq())) << topic;
    EXPECT_EQ(m.publish_time_ns, message.header().stamp_ns()) << topic;
    out.push_back(message);
  }
  return out;
}

template <class Message>
void expect_recorded(const mcap::McapReader& reader, const std::vector<Message>& sent) {
  const std::string topic(dds::MessageTraits<Message>::topic);
  const std::vector<Message> got = decoded<Message>(reader, topic);
  ASSERT_EQ(got.size(), sent.size()) << topic;
  std::vector<std::uint64_t> seqs;
  for (std::size_t i = 0; i < got.size(); ++i) {
    EXPECT_EQ(got[i], sent[i]) << topic << " message " << i;
    seqs.push_back(got[i].header().seq());
  }
  const SequenceReport r = analyze_sequence(seqs);
  EXPECT_TRUE(r.complete()) << topic << ": " << describe(r);
  EXPECT_EQ(r.backwards, 0u) << topic;
  EXPECT_EQ(r.max, sent.size()) << topic;
}

// The recording that the log_tool_* ctests check with pixyslam_log (they set
// PIXYSLAM_LOGGER_TEST_OUT to keep it): 500 Odometry, 50 LandmarkObservation,
// 100 MapState, 20 GroundTruth, 10 OptimisedMap.
TEST(LoggerNode, RecordsEveryTopicExactly) {
  const TempFile file("test_logger_recording", "PIXYSLAM_LOGGER_TEST_OUT");
  const std::uint64_t start_ns = dds::now_ns();
  LoggerNode node(node_options(file.path()));
  node.start();

  dds::Participant robot(loopback_options(), "test_robot");
  dds::Writer<msg::Odometry> odometry_writer(robot);
  dds::Writer<msg::LandmarkObservation> observation_writer(robot);
  dds::Writer<msg::MapState> map_writer(robot);
  dds::Writer<msg::GroundTruth> truth_writer(robot);
  dds::Writer<msg::OptimisedMap> optimised_writer(robot);
  dds::Writer<msg::RobotSighting> sighting_writer(robot);
  ASSERT_TRUE(odometry_writer.wait_for_readers(1, std::chrono::seconds(10)));
  ASSERT_TRUE(observation_writer.wait_for_readers(1, std::chrono::seconds(10)));
  ASSERT_TRUE(map_writer.wait_for_readers(1, std::chrono::seconds(10)));
  ASSERT_TRUE(truth_writer.wait_for_readers(1, std::chrono::seconds(10)));
  ASSERT_TRUE(optimised_writer.wait_for_readers(1, std::chrono::seconds(10)));
  ASSERT_TRUE(sighting_writer.wait_for_readers(1, std::chrono::seconds(10)));

  std::vector<msg::Odometry> odometry_sent;
  std::vector<msg::LandmarkObservation> observations_sent;
  std::vector<msg::MapState> maps_sent;
  std::vector<msg::GroundTruth> truths_sent;
  std::vector<msg::OptimisedMap> optimised_sent;
  for (int i = 0; i < 500; ++i) {
    odometry_sent.push_back(test::sample_odometry(i));
    ASSERT_TRUE(odometry_writer.publish(odometry_sent.back()));  // fills seq and robot_id
    if (i % 10 == 0) {
      observations_sent.push_back(observation(i / 10));
      ASSERT_TRUE(observation_writer.publish(observations_sent.back()));
    }
    if (i % 5 == 0) {
      // The MapState writer keeps only the last sample (transient local, depth
      // 1): at the estimator's pace every one arrives; a burst could lose some.
      maps_sent.push_back(map_state(i / 5));
      ASSERT_TRUE(map_writer.publish(maps_sent.back()));
      std::this_thread::sleep_for(std::chrono::milliseconds(2));
    }
    if (i % 25 == 0) {
      truths_sent.push_back(ground_truth(i / 25));
      ASSERT_TRUE(truth_writer.publish(truths_sent.back()));
    }
    if (i % 50 == 0) {
      // Keep-last 64 (the optimiser's pace: one solution per solve): spaced out
      // like the MapStates above.
      optimised_sent.push_back(optimised_map(i / 50));
      ASSERT_TRUE(optimised_writer.publish(optimised_sent.back()));
      std::this_thread::sleep_for(std::chrono::milliseconds(2));
    }
    if (i % 100 == 0) {
      msg::RobotSighting sighting;
      msg::RobotDetection d;
      d.seen_robot_id("robot" + std::to_string(i / 100 + 2));
      d.range_m(1.0 + i / 100);
      sighting.detections().push_back(d);
      ASSERT_TRUE(sighting_writer.publish(sighting));
    }
  }
  ASSERT_EQ(observations_sent.size(), 50u);
  ASSERT_EQ(maps_sent.size(), 100u);
  ASSERT_EQ(truths_sent.size(), 20u);
  ASSERT_EQ(optimised_sent.size(), 10u);
  EXPECT_TRUE(wait_until(
      [&] {
        return received(node, "pixyslam/odometry") == 500 && received(node, "pixyslam/map_state") == 100 &&
               received(node, "pixyslam/landmark_observation") == 50 && received(node, "pixyslam/ground_truth") == 20 &&
               received(node, "pixyslam/optimised_map") == 10 && received(node, "pixyslam/robot_sighting") == 5;
      },
      std::chrono::seconds(20)))
      << node.counters_text();
  node.stop();
  const std::uint64_t end_ns = dds::now_ns();

  const LoggerCounters c = node.counters();
  EXPECT_TRUE(c.error.empty()) << c.error;
  const std::map<std::string, std::uint64_t> expected = {{"pixyslam/odometry", 500},
                                                         {"pixyslam/landmark_observation", 50},
                                                         {"pixyslam/map_state", 100},
                                                         {"pixyslam/ground_truth", 20},
                                                         {"pixyslam/diagnostics", 0},
                                                         {"pixyslam/optimised_map", 10},
                                                         {"pixyslam/robot_sighting", 5},
                                                         {"pixyslam/fleet_map", 0}};
  ASSERT_EQ(c.topics.size(), 8u);
  for (const auto& [topic, count] : expected) {
    const TopicCounters& t = topic_counters(c, topic);
    EXPECT_EQ(t.received, count) << topic;
    EXPECT_EQ(t.written, count) << topic;
    EXPECT_EQ(t.dropped, 0u) << topic;
    EXPECT_EQ(t.reader.seq_gaps, 0u) << topic;
  }
  EXPECT_EQ(c.file.messages, 685u);
  EXPECT_GT(c.file.chunks, 1u);
  EXPECT_GT(c.queue_peak_messages, 0u);
  EXPECT_NE(node.counters_text().find("pixyslam/odometry: received 500, written 500, dropped 0, seq gaps 0"),
            std::string::npos)
      << node.counters_text();

  const mcap::McapReader reader(file.path());
  EXPECT_TRUE(reader.clean()) << reader.diagnostics_text();
  ASSERT_TRUE(reader.statistics().has_value());
  EXPECT_EQ(reader.statistics()->message_count, 685u);
  EXPECT_EQ(reader.messages().size(), 685u);
  for (const mcap::McapChunkInfo& chunk : reader.chunks()) {
    EXPECT_EQ(chunk.compression, mcap::mcap_compression_name(default_compression()));
  }

  // Channels and schemas.
  ASSERT_EQ(reader.channels().size(), 8u);
  ASSERT_EQ(reader.schemas().size(), 8u);
  for (const TopicInfo& info : known_topics()) {
    const mcap::McapChannel* channel = reader.find_channel(info.topic);
    ASSERT_NE(channel, nullptr) << info.topic;
    EXPECT_EQ(channel->message_encoding, "cdr");
    EXPECT_EQ(channel->metadata.at("type_name"), info.type_name);
    EXPECT_EQ(channel->metadata.at("robot_id"), "test_robot");
    const mcap::McapSchema* schema = reader.find_schema(channel->schema_id);
    ASSERT_NE(schema, nullptr) << info.topic;
    EXPECT_EQ(schema->name, info.type_name);
    EXPECT_EQ(schema->encoding, "omgidl");
    EXPECT_EQ(schema->data, std::string(msg::idl_text(info.idl_stem)));
    EXPECT_NE(schema->data.find("struct MessageHeader"), std::string::npos);  // includes inlined
  }

  // Every message: bytes decode to what was sent; MCAP fields; times.
  expect_recorded(reader, odometry_sent);
  expect_recorded(reader, observations_sent);
  expect_recorded(reader, maps_sent);
  expect_recorded(reader, truths_sent);
  expect_recorded(reader, optimised_sent);
  std::uint64_t previous_log_time = 0;
  for (const mcap::McapMessage& m : reader.messages()) {
    EXPECT_GE(m.log_time_ns, start_ns);
    EXPECT_LE(m.log_time_ns, end_ns);
    EXPECT_GE(m.log_time_ns, previous_log_time);  // written in receive order
    previous_log_time = m.log_time_ns;
  }
  // The bytes are what a Fast DDS writer sends for that sample.
  const mcap::McapChannel* odometry_channel = reader.find_channel("pixyslam/odometry");
  const auto first = std::find_if(reader.messages().begin(), reader.messages().end(),
                                  [&](const mcap::McapMessage& m) { return m.channel_id == odometry_channel->id; });
  ASSERT_NE(first, reader.messages().end());
  EXPECT_EQ(first->data, to_cdr(odometry_sent.front()));
}

TEST(LoggerNode, DropsAndCountsSamplesBeyondTheQueueBound) {
  const TempFile file("test_logger_bound");
  LoggerOptions options = node_options(file.path());
  options.topics = {"pixyslam/odometry"};
  dds::Participant robot(loopback_options(), "test_robot");
  dds::Writer<msg::Odometry> writer(robot);
  // Room for exactly 10 samples of this size (robot_id and frame_id fixed).
  msg::Odometry probe = test::sample_odometry(0);
  probe.header().robot_id("test_robot");
  options.queue_max_bytes = 10 * to_cdr(probe).size();

  LoggerNode node(options);  // not started: nothing leaves the queue
  ASSERT_TRUE(writer.wait_for_readers(1, std::chrono::seconds(10)));
  for (int i = 0; i < 30; ++i) {
    msg::Odometry m = test::sample_odometry(i);
    ASSERT_TRUE(writer.publish(m));
  }
  ASSERT_TRUE(wait_until([&] { return received(node, "pixyslam/odometry") == 30; }, std::chrono::seconds(10)))
      << node.counters_text();
  LoggerCounters c = node.counters();
  EXPECT_EQ(c.topics[0].dropped, 20u);
  EXPECT_EQ(c.queue_peak_messages, 10u);
  EXPECT_EQ(c.queue_peak_bytes, options.queue_max_bytes);

  node.stop();  // writes what is queued, then closes
  c = node.counters();
  EXPECT_EQ(c.topics[0].written, 10u);
  EXPECT_EQ(c.topics[0].dropped, 20u);
  const mcap::McapReader reader(file.path());
  EXPECT_TRUE(reader.clean()) << reader.diagnostics_text();
  ASSERT_EQ(reader.messages().size(), 10u);
  EXPECT_EQ(reader.channels().size(), 1u);
  std::vector<std::uint64_t> seqs;
  for (const mcap::McapMessage& m : reader.messages()) seqs.push_back(m.sequence);
  EXPECT_EQ(describe(analyze_sequence(seqs)), "seq 1..10");
}

TEST(LoggerNode, FlushTimerBoundsWhatACrashLoses) {
  const TempFile file("test_logger_flush");
  LoggerOptions options = node_options(file.path());
  options.topics = {"pixyslam/odometry"};
  options.chunk_size_bytes = std::size_t{1} << 20;  // never full in this test
  options.flush_period_s = 0.2;
  LoggerNode node(options);
  node.start();
  dds::Participant robot(loopback_options(), "test_robot");
  dds::Writer<msg::Odometry> writer(robot);
  ASSERT_TRUE(writer.wait_for_readers(1, std::chrono::seconds(10)));
  for (int i = 0; i < 50; ++i) {
    msg::Odometry m = test::sample_odometry(i);
    ASSERT_TRUE(writer.publish(m));
  }
  ASSERT_TRUE(wait_until([&] { return node.counters().topics[0].written == 50; }, std::chrono::seconds(10)))
      << node.counters_text();
  // Still recording (no footer yet), as a killed logger would leave the file.
  std::this_thread::sleep_for(std::chrono::milliseconds(600));
  {
    const mcap::McapReader reader(file.path());
    EXPECT_FALSE(reader.recovery().footer_present);
    EXPECT_EQ(reader.recovery().messages_recovered, 50u) << reader.diagnostics_text();
    EXPECT_EQ(reader.messages().size(), 50u);
  }
  node.stop();
  const mcap::McapReader reader(file.path());
  EXPECT_TRUE(reader.clean()) << reader.diagnostics_text();
  EXPECT_EQ(reader.messages().size(), 50u);
}

// Reads rotated files base_000, base_001, ... (until one is missing).
std::vector<std::string> rotated_files(const std::string& base) {
  std::vector<std::string> out;
  for (std::size_t i = 0; std::filesystem::exists(rotated_file_name(base, i)); ++i) {
    out.push_back(rotated_file_name(base, i));
  }
  return out;
}

// Every rotated file of base, also past a gap (keep_files deletes the lowest).
void remove_rotated(const std::string& base) {
  for (std::size_t i = 0; i < 1000; ++i) std::filesystem::remove(rotated_file_name(base, i));
}

// Removes base's rotated files now and when the test ends, also when an
// assertion ends it early.
class RotatedFilesGuard {
 public:
  explicit RotatedFilesGuard(std::string base) : base_(std::move(base)) { remove_rotated(base_); }
  ~RotatedFilesGuard() { remove_rotated(base_); }
  RotatedFilesGuard(const RotatedFilesGuard&) = delete;
  RotatedFilesGuard& operator=(const RotatedFilesGuard&) = delete;

 private:
  std::string base_;
};

// Each file complete and clean, with every selected channel; together, seq
// 1..count of Odometry in order.
void expect_complete_rotation(const std::vector<std::string>& files, const LoggerCounters& c,
                              std::size_t channels, std::uint64_t count) {
  ASSERT_EQ(c.files.size(), files.size());
  std::vector<std::uint64_t> seqs;
  for (std::size_t i = 0; i < files.size(); ++i) {
    const mcap::McapReader reader(files[i]);
    EXPECT_TRUE(reader.clean()) << files[i] << ":\n" << reader.diagnostics_text();
    EXPECT_EQ(reader.channels().size(), channels) << files[i];
    EXPECT_EQ(reader.schemas().size(), channels) << files[i];
    EXPECT_EQ(c.files[i].path, files[i]);
    EXPECT_TRUE(c.files[i].closed);
    EXPECT_EQ(c.files[i].counters.messages, reader.messages().size()) << files[i];
    ASSERT_TRUE(reader.statistics().has_value());
    EXPECT_EQ(reader.statistics()->message_count, reader.messages().size());
    const mcap::McapChannel* odometry = reader.find_channel("pixyslam/odometry");
    ASSERT_NE(odometry, nullptr) << files[i];
    for (const mcap::McapMessage& m : reader.messages()) {
      if (m.channel_id == odometry->id) seqs.push_back(m.sequence);
    }
  }
  const SequenceReport r = analyze_sequence(seqs);
  EXPECT_EQ(describe(r), "seq 1.." + std::to_string(count));
  EXPECT_EQ(r.backwards, 0u);
  EXPECT_EQ(c.file.messages, count);
}

// Odometry seq 1..count from a writer of the test's, as fast as it goes, until
// the logger has received every sample.
void publish_odometry_until_received(const LoggerNode& node, int count) {
  dds::Participant robot(loopback_options(), "test_robot");
  dds::Writer<msg::Odometry> writer(robot);
  ASSERT_TRUE(writer.wait_for_readers(1, std::chrono::seconds(10)));
  for (int i = 0; i < count; ++i) {
    msg::Odometry m = test::sample_odometry(i);
    ASSERT_TRUE(writer.publish(m));
  }
  ASSERT_TRUE(wait_until([&] { return received(node, "pixyslam/odometry") == static_cast<std::uint64_t>(count); },
                         std::chrono::seconds(20)))
      << node.counters_text();
}

TEST(LoggerNode, RotatesBySizeIntoCompleteFiles) {
  const TempFile base("test_logger_rotate_size");
  const RotatedFilesGuard rotated(base.path());
  LoggerOptions options = node_options(base.path());
  options.topics = {"pixyslam/*", "!pixyslam/ground_truth"};
  options.rotate_size_bytes = 65536;
  options.compression = mcap::McapCompression::kNone;  // sizes as written
  LoggerNode node(options);
  node.start();
  constexpr int kCount = 2000;
  publish_odometry_until_received(node, kCount);
  node.stop();
  EXPECT_FALSE(std::filesystem::exists(base.path()));  // only the indexed names
  const std::vector<std::string> files = rotated_files(base.path());
  const LoggerCounters c = node.counters();
  EXPECT_TRUE(c.error.empty()) << c.error;
  EXPECT_GE(files.size(), 3u);
  expect_complete_rotation(files, c, known_topics().size() - 1, kCount);  // all but the ground truth
  for (std::size_t i = 0; i + 1 < files.size(); ++i) {
    const auto size = std::filesystem::file_size(files[i]);
    EXPECT_GE(size + 8192, options.rotate_size_bytes) << files[i];  // rotated near the limit,
    // Not far beyond it: + the summary, which repeats every topic's schema (8 IDL texts, ~16 KiB).
    EXPECT_LE(size, options.rotate_size_bytes + 20480) << files[i];
  }
}

// A station that records for weeks: with keep_files only the newest files stay
// on disk, complete, holding the end of the run; the counters list the deleted ones.
TEST(LoggerNode, KeepsOnlyTheNewestRotatedFiles) {
  const TempFile base("test_logger_keep_files");
  const RotatedFilesGuard rotated(base.path());
  LoggerOptions options = node_options(base.path());
  options.topics = {"pixyslam/odometry"};
  options.rotate_size_bytes = 65536;
  options.keep_files = 2;
  options.compression = mcap::McapCompression::kNone;
  LoggerNode node(options);
  node.start();
  constexpr int kCount = 3000;
  publish_odometry_until_received(node, kCount);
  node.stop();
  const LoggerCounters c = node.counters();
  ASSERT_GE(c.files.size(), 4u);
  std::vector<std::uint64_t> seqs;
  for (std::size_t i = 0; i < c.files.size(); ++i) {
    const bool kept = i + 2 >= c.files.size();
    EXPECT_EQ(c.files[i].removed, !kept) << i;
    EXPECT_EQ(std::filesystem::exists(c.files[i].path), kept) << c.files[i].path;
    if (!kept) continue;
    const mcap::McapReader reader(c.files[i].path);
    EXPECT_TRUE(reader.clean()) << c.files[i].path << ":\n" << reader.diagnostics_text();
    for (const mcap::McapMessage& m : reader.messages()) seqs.push_back(m.sequence);
  }
  ASSERT_FALSE(seqs.empty());
  EXPECT_EQ(seqs.back(), static_cast<std::uint64_t>(kCount));  // the end of the run
  EXPECT_TRUE(std::is_sorted(seqs.begin(), seqs.end()));

  // A restarted logger (the same base) goes on after the newest file of the
  // run before, though its lowest indexes are free: nothing is overwritten.
  const std::string newest = c.files.back().path;
  const auto newest_size = std::filesystem::file_size(newest);
  LoggerNode again(options);
  again.start();
  publish_odometry_until_received(again, 10);
  again.stop();
  const LoggerCounters c2 = again.counters();
  ASSERT_FALSE(c2.files.empty());
  EXPECT_EQ(rotated_file_index(base.path(), c2.files.front().path),
            std::optional<std::size_t>(*rotated_file_index(base.path(), newest) + 1));
  EXPECT_EQ(std::filesystem::file_size(newest), newest_size);
}

TEST(LoggerNode, RotatesByPeriod) {
  const TempFile base("test_logger_rotate_period");
  const RotatedFilesGuard rotated(base.path());
  LoggerOptions options = node_options(base.path());
  options.topics = {"pixyslam/odometry"};
  options.rotate_period_s = 1.0;
  options.flush_period_s = 0.1;
  LoggerNode node(options);
  node.start();
  dds::Participant robot(loopback_options(), "test_robot");
  dds::Writer<msg::Odometry> writer(robot);
  ASSERT_TRUE(writer.wait_for_readers(1, std::chrono::seconds(10)));
  constexpr int kCount = 250;  // 2.5 s at 100 Hz: three files
  const auto start = std::chrono::steady_clock::now();
  for (int i = 0; i < kCount; ++i) {
    std::this_thread::sleep_until(start + std::chrono::milliseconds(10 * i));
    msg::Odometry m = test::sample_odometry(i);
    ASSERT_TRUE(writer.publish(m));
  }
  ASSERT_TRUE(wait_until([&] { return received(node, "pixyslam/odometry") == kCount; }, std::chrono::seconds(20)))
      << node.counters_text();
  node.stop();
  const std::vector<std::string> files = rotated_files(base.path());
  const LoggerCounters c = node.counters();
  EXPECT_TRUE(c.error.empty()) << c.error;
  EXPECT_GE(files.size(), 3u);
  EXPECT_LE(files.size(), 4u);
  expect_complete_rotation(files, c, 1, kCount);
}

// A full disk, simulated per file with RLIMIT_FSIZE (a write past the limit
// fails with EFBIG like one on a full disk with ENOSPC): each file fails at the
// limit. The logger keeps every file as written (readable up to its last
// complete chunk), drops and counts samples while it has no file, opens a new
// file every retry_period_s alternating with fallback_dir, and never stops.
TEST(LoggerNode, WriteFailuresKeepTheFileAndRecordingGoesOnInANewOne) {
  const TempFile base("test_logger_full_disk");
  const RotatedFilesGuard rotated(base.path());
  const std::filesystem::path fallback =
      std::filesystem::temp_directory_path() / ("test_logger_fallback_" + std::to_string(getpid()));
  std::filesystem::remove_all(fallback);
  std::filesystem::create_directories(fallback);
  LoggerOptions options = node_options(base.path());
  options.topics = {"pixyslam/odometry"};
  options.compression = mcap::McapCompression::kNone;
  options.flush_period_s = 0.05;
  options.retry_period_s = 0.2;
  options.fallback_dir = fallback.string();
  dds::Participant robot(loopback_options(), "test_robot");
  dds::Writer<msg::Odometry> writer(robot);
  LoggerNode node(options);
  node.start();
  ASSERT_TRUE(writer.wait_for_readers(1, std::chrono::seconds(10)));

  constexpr rlim_t kFileLimit = 48 * 1024;
  rlimit before{};
  ASSERT_EQ(getrlimit(RLIMIT_FSIZE, &before), 0);
  const auto old_handler = signal(SIGXFSZ, SIG_IGN);
  rlimit limited = before;
  limited.rlim_cur = kFileLimit;
  ASSERT_EQ(setrlimit(RLIMIT_FSIZE, &limited), 0);
  constexpr int kCount = 1500;
  const auto start = std::chrono::steady_clock::now();
  for (int i = 0; i < kCount; ++i) {
    std::this_thread::sleep_until(start + std::chrono::microseconds(1000 * i));
    msg::Odometry m = test::sample_odometry(i);
    ASSERT_TRUE(writer.publish(m));
  }
  const bool all_received =
      wait_until([&] { return received(node, "pixyslam/odometry") == kCount; }, std::chrono::seconds(20));
  EXPECT_FALSE(node.failed());  // still recording, or about to retry
  node.stop();
  setrlimit(RLIMIT_FSIZE, &before);
  signal(SIGXFSZ, old_handler);
  ASSERT_TRUE(all_received) << node.counters_text();

  const LoggerCounters c = node.counters();
  EXPECT_TRUE(c.error.empty()) << c.error;
  EXPECT_GE(c.write_failures, 2u) << c.last_write_error;
  EXPECT_EQ(c.topics[0].written + c.topics[0].dropped, static_cast<std::uint64_t>(kCount));
  ASSERT_GE(c.files.size(), 3u);
  std::size_t in_fallback = 0;
  std::vector<std::uint64_t> seqs;
  for (const LoggedFile& f : c.files) {
    if (std::filesystem::path(f.path).parent_path() == fallback) ++in_fallback;
    const mcap::McapReader reader(f.path);
    EXPECT_GT(reader.messages().size(), 0u) << f.path << "\n" << reader.diagnostics_text();
    if (!f.closed) {
      EXPECT_FALSE(reader.recovery().footer_present) << f.path;
    }
    for (const mcap::McapMessage& m : reader.messages()) seqs.push_back(m.sequence);
  }
  EXPECT_GE(in_fallback, 1u);
  EXPECT_LT(in_fallback, c.files.size());
  // In order across the files, nothing twice, and most of what was sent.
  EXPECT_TRUE(std::is_sorted(seqs.begin(), seqs.end()));
  EXPECT_EQ(std::adjacent_find(seqs.begin(), seqs.end()), seqs.end());
  EXPECT_GE(seqs.size(), static_cast<std::size_t>(kCount) / 2) << node.counters_text();
  for (const LoggedFile& f : c.files) std::filesystem::remove(f.path);
  std::filesystem::remove_all(fallback);
}

// A restarted logger (the launcher restarts an optional process) or a reused
// folder: the recording already there is kept, the next free name written.
TEST(LoggerNode, AnExistingRecordingIsNeverOverwritten) {
  const TempFile base("test_logger_existing");
  const RotatedFilesGuard rotated(base.path());
  const std::string first_restart = rotated_file_name(base.path(), 1);
  { std::ofstream(base.path()) << "earlier recording"; }
  {
    LoggerOptions options = node_options(base.path());
    options.topics = {"pixyslam/odometry"};
    LoggerNode node(options);
    node.stop();
    ASSERT_EQ(node.counters().files.size(), 1u);
    EXPECT_EQ(node.counters().files[0].path, first_restart);
  }
  std::ifstream kept(base.path());
  std::string text;
  std::getline(kept, text);
  EXPECT_EQ(text, "earlier recording");
  EXPECT_TRUE(mcap::McapReader(first_restart).clean());
}

TEST(LoggerNode, BadTopicPatternIsAnError) {
  LoggerOptions options = node_options("/tmp/unused.mcap");
  options.topics = {"nothing/*"};
  EXPECT_THROW(LoggerNode node(options), std::invalid_argument);
}

TEST(LoggerNode, UnwritableFileIsAnErrorNamingIt) {
  LoggerOptions options = node_options("/nonexistent_dir/run.mcap");
  try {
    LoggerNode node(options);
    FAIL() << "expected an error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent_dir/run.mcap"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace pixyslam::logger_node
