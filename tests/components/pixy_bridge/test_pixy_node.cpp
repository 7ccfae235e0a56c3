// The pixy bridge's node layer: message conversion, options, and the node
// driven by a scripted byte source (Pixy frames from encode_frame, garbage and
// a corrupted block mixed in), publishing LandmarkObservation over DDS on the
// loopback profile to a reader in the same test.
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <fstream>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

#include "dds_test_support.h"
#include "diagnostics.h"
#include "pixyslam/bridge/byte_source.h"
#include "pixyslam/dds/endpoints.h"
#include "pixyslam/pixy/pixy_block_parser.h"
#include "pixyslam/pixy/pixy_geometry.h"
#include "pixyslam/pixy_node/observation_conversions.h"
#include "pixyslam/pixy_node/pixy_node.h"
#include "pixyslam/pixy_node/pixy_node_options.h"

namespace pixyslam::pixy_node {
namespace {

using std::chrono::milliseconds;
using test_support::LogLines;

// Blocks of the shipped signature map (config/pixy_bridge.yaml): "12" -> 1, "13" -> 2.
// {signature, x, y, width, height, angle_deg, colour_code}: height/width 2.1.
pixy::PixyBlock landmark_1() { return {012, 160, 100, 20, 42, -3, true}; }
pixy::PixyBlock landmark_2() { return {013, 80, 90, 10, 21, 5, true}; }

pixy::PixyBlock unknown_code() {  // tags 7, 7: not in the map
  pixy::PixyBlock b = landmark_1();
  b.signature = 077;
  return b;
}

// ---------------------------------------------------------------- conversions

TEST(ObservationConversions, BlockAndDetectionKeepEveryField) {
  pixy::Detection d;
  d.landmark_id = 7;
  d.range_m = 1.25;
  d.bearing_rad = -0.1;
  d.range_sigma_m = 0.0625;
  d.bearing_sigma_rad = 0.027;
  d.block = landmark_1();
  const msg::LandmarkDetection m = to_detection_msg(d);
  EXPECT_EQ(m.landmark_id(), 7);
  EXPECT_DOUBLE_EQ(m.range_m(), 1.25);
  EXPECT_DOUBLE_EQ(m.bearing_rad(), -0.1);
  EXPECT_DOUBLE_EQ(m.range_sigma_m(), 0.0625);
  EXPECT_DOUBLE_EQ(m.bearing_sigma_rad(), 0.027);
  EXPECT_EQ(m.block().signature(), 012);
  EXPECT_EQ(m.block().x_px(), 160);
  EXPECT_EQ(m.block().y_px(), 100);
  EXPECT_EQ(m.block().width_px(), 20);
  EXPECT_EQ(m.block().height_px(), 42);
  EXPECT_EQ(m.block().angle_deg(), -3);
}

TEST(ObservationConversions, FrameCountsBlocksAndRejections) {
  pixy::PixyFrame frame;
  frame.index = 41;
  frame.blocks = {landmark_1(), unknown_code(), landmark_2()};
  pixy::Detection d;
  d.landmark_id = 1;
  d.block = landmark_1();
  const msg::LandmarkObservation m = to_observation_msg(frame, {d}, 123456789u);
  EXPECT_EQ(m.header().stamp_ns(), 123456789u);
  EXPECT_EQ(m.header().frame_id(), "camera");
  EXPECT_EQ(m.camera_frame(), 41u);
  EXPECT_EQ(m.blocks_in_frame(), 3u);
  EXPECT_EQ(m.blocks_rejected(), 2u);
  ASSERT_EQ(m.detections().size(), 1u);
  EXPECT_EQ(m.detections()[0].landmark_id(), 1);

  const msg::LandmarkObservation empty = to_observation_msg(pixy::PixyFrame{}, {}, 5u);
  EXPECT_EQ(empty.blocks_in_frame(), 0u);
  EXPECT_EQ(empty.blocks_rejected(), 0u);
  EXPECT_TRUE(empty.detections().empty());
}

TEST(ObservationConversions, DetectionsBeyondTheBoundAreLeftOut) {
  pixy::PixyFrame frame;
  std::vector<pixy::Detection> detections(kMaxDetectionsPerMessage + 6);
  frame.blocks.resize(detections.size());
  for (std::size_t i = 0; i < detections.size(); ++i) detections[i].landmark_id = static_cast<int>(i);
  const msg::LandmarkObservation m = to_observation_msg(frame, detections, 1u);
  ASSERT_EQ(m.detections().size(), kMaxDetectionsPerMessage);
  EXPECT_EQ(m.detections().back().landmark_id(), static_cast<int>(kMaxDetectionsPerMessage) - 1);
  EXPECT_EQ(m.blocks_rejected(), 0u);
}

// ---------------------------------------------------------------- options

std::string config_error_of(const std::string& text) {
  try {
    auto root = config::YamlReader::from_string(text, "test.yaml");
    read_pixy_node_options(root, "/cfg");
  } catch (const config::ConfigError& e) {
    return e.what();
  }
  return "(no error)";
}

const char* kPixyYaml = "pixy:\n  landmark_height_m: 0.08\n  landmarks:\n    \"12\": 1\n";

TEST(PixyNodeOptions, ShippedConfigLoadsWithNodeAndDds) {
  const PixyNodeOptions o = read_pixy_node_options_file(std::string(PIXYSLAM_CONFIG_DIR) + "/pixy_bridge.yaml");
  EXPECT_EQ(o.process.serial_device, "/dev/serial0");
  EXPECT_EQ(o.process.baud, 19200);
  EXPECT_DOUBLE_EQ(o.camera_latency_s, 0.0);
  // The file's node: values are the defaults, as it says.
  const PixyNodeOptions defaults;
  EXPECT_DOUBLE_EQ(o.frame_timeout_s, 0.01);
  EXPECT_DOUBLE_EQ(o.frame_timeout_s, defaults.frame_timeout_s);
  EXPECT_EQ(o.process.serial_device, defaults.process.serial_device);
  EXPECT_EQ(o.process.baud, defaults.process.baud);
  EXPECT_DOUBLE_EQ(o.camera_latency_s, defaults.camera_latency_s);
  EXPECT_DOUBLE_EQ(o.process.reopen_period_s, defaults.process.reopen_period_s);
  EXPECT_DOUBLE_EQ(o.process.status_period_s, defaults.process.status_period_s);
  EXPECT_EQ(o.pixy.signatures.size(), 20u);
  EXPECT_EQ(o.dds.profiles_file, std::string(PIXYSLAM_CONFIG_DIR) + "/dds/profiles.xml");
}

TEST(PixyNodeOptions, EffectiveConfigurationReadsBack) {
  auto root = config::YamlReader::from_string(
      std::string("node:\n  serial_device: /dev/ttyUSB3\n  baud: 115200\n  camera_latency_s: 0.02\n"
                  "  frame_timeout_s: 0.1\n  reopen_period_s: 2\n  status_period_s: 5\n") +
          kPixyYaml + "dds:\n  robot_id: r2\n  profiles_file: p.xml\n",
      "test.yaml");
  const PixyNodeOptions o = read_pixy_node_options(root, "/cfg");
  EXPECT_EQ(o.dds.profiles_file, "/cfg/p.xml");
  auto again_root = config::YamlReader::from_string(to_yaml(o), "again.yaml");
  const PixyNodeOptions again = read_pixy_node_options(again_root, "/elsewhere");
  EXPECT_EQ(to_yaml(again), to_yaml(o));
  EXPECT_EQ(again.process.serial_device, "/dev/ttyUSB3");
  EXPECT_EQ(again.process.baud, 115200);
  EXPECT_DOUBLE_EQ(again.camera_latency_s, 0.02);
  EXPECT_DOUBLE_EQ(again.frame_timeout_s, 0.1);
  EXPECT_DOUBLE_EQ(again.process.reopen_period_s, 2.0);
  EXPECT_DOUBLE_EQ(again.process.status_period_s, 5.0);
  EXPECT_EQ(again.pixy.signatures.landmark_of_signature(012), std::optional<int>(1));
  EXPECT_EQ(again.dds.robot_id, "r2");
}

TEST(PixyNodeOptions, ErrorsNameTheFileAndTheKey) {
  struct Case {
    std::string yaml;
    std::string expected;
  };
  const std::string pixy = kPixyYaml;
  const std::vector<Case> cases = {
      {"node:\n  baud: 12345\n" + pixy, "test.yaml: key 'node.baud': value 12345 is not a standard serial rate"},
      {"node:\n  serial_device: ttyS0\n" + pixy, "test.yaml: key 'node.serial_device': value 'ttyS0' is not an absolute path"},
      {"node:\n  camera_latency_s: 2\n" + pixy, "test.yaml: key 'node.camera_latency_s': value 2"},
      {"node:\n  reopen_period_s: 0\n" + pixy, "test.yaml: key 'node.reopen_period_s'"},
      {"node:\n  latency_s: 0\n" + pixy, "test.yaml: key 'node.latency_s': unknown key"},
      {pixy + "dds:\n  domain_id: -1\n", "test.yaml: key 'dds.domain_id'"},
      {pixy + "extra: 1\n", "test.yaml: key 'extra': unknown key"},
      {"node: {}\n", "test.yaml: key 'pixy': missing"},
  };
  for (const Case& c : cases) {
    const std::string e = config_error_of(c.yaml);
    EXPECT_NE(e.find(c.expected), std::string::npos) << "got: " << e << "\nyaml:\n" << c.yaml;
  }
}

TEST(PixyNodeOptions, FileErrorsNameThePath) {
  const std::string path = ::testing::TempDir() + "pixy_node_options_" + std::to_string(::getpid()) + ".yaml";
  {
    std::ofstream out(path);
    out << "node:\n  frame_timeout_s: 0\n" << kPixyYaml;
  }
  try {
    read_pixy_node_options_file(path);
    ADD_FAILURE() << "expected a config error";
  } catch (const config::ConfigError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find(path + ": key 'node.frame_timeout_s'"), std::string::npos) << what;
  }
  std::remove(path.c_str());
}

// ---------------------------------------------------------------- the node over DDS

dds::DdsOptions loopback_options() { return test_support::loopback_options(170, 60, "pixy_test_"); }

// The observations the test's own participant receives (test_support::Inbox).
using ObservationInbox = test_support::Inbox<msg::LandmarkObservation>;
ObservationInbox& observation_inbox() {
  return ObservationInbox::instance(loopback_options(), "test_observation_reader");
}
::testing::Environment* const kInboxCleanup =
    ::testing::AddGlobalTestEnvironment(new test_support::InboxCleanup<msg::LandmarkObservation>);

constexpr std::uint64_t kBaseNs = 1700000000000000000ull;
constexpr std::uint64_t kFrameNs = 20000000ull;  // 50 frames per second
constexpr std::uint64_t kLatencyNs = 3000000ull;

std::uint64_t arrival_ns(std::size_t frame) { return kBaseNs + kFrameNs * frame; }

// Frame i: 0 mod 4 -> landmark 1; 1 -> landmarks 1 and 2 and an unknown code;
// 2 -> no blocks; 3 -> only the unknown code.
std::vector<pixy::PixyBlock> blocks_of_frame(std::size_t i) {
  switch (i % 4) {
    case 0: return {landmark_1()};
    case 1: return {landmark_1(), landmark_2(), unknown_code()};
    case 2: return {};
    default: return {unknown_code()};
  }
}

// The shipped pixy options, on the test's loopback domain, latency kLatencyNs.
PixyNodeOptions shipped_options() {
  PixyNodeOptions options;
  auto root = config::YamlReader::from_file(std::string(PIXYSLAM_CONFIG_DIR) + "/pixy_bridge.yaml");
  options.pixy = read_pixy_node_options(root, PIXYSLAM_CONFIG_DIR).pixy;
  options.dds = loopback_options();
  options.camera_latency_s = 1e-9 * static_cast<double>(kLatencyNs);
  options.process.status_period_s = 0.0;
  return options;
}

// Starts the node once the test's reader matched its writer.
void start_when_read(PixyNode& node) {
  ASSERT_TRUE(node.wait_for_subscribers(1, std::chrono::seconds(10)));
  node.start();
}

TEST(PixyNode, PublishesOneObservationPerFrameAndSkipsBadBytes) {
  // Given 20 camera frames, one chunk each, with garbage before some frames
  // and a corrupted block inside frame 5,
  constexpr std::size_t kFrames = 20;
  auto script = std::make_shared<bridge::ByteScript>();
  const std::vector<std::uint8_t> garbage = {0x01, 0x02, 0x03};
  std::size_t garbage_bytes = 0;
  for (std::size_t i = 0; i < kFrames; ++i) {
    std::vector<std::uint8_t> chunk;
    if (i % 8 == 0 && i > 0) {  // never right after an empty frame's lone sync word
      chunk = garbage;
      garbage_bytes += garbage.size();
    }
    const std::vector<std::uint8_t> frame = pixy::encode_frame(blocks_of_frame(i));
    chunk.insert(chunk.end(), frame.begin(), frame.end());
    if (i == 5) {
      std::vector<std::uint8_t> bad;
      pixy::encode_block(landmark_2(), bad);
      bad[6] ^= 0x40;  // x changes, the checksum no longer matches
      chunk.insert(chunk.end(), bad.begin(), bad.end());
    }
    script->add_bytes(chunk, arrival_ns(i));
  }
  // The camera then sends nothing: the last frame completes by frame_timeout_s.
  script->add_idle(arrival_ns(kFrames - 1) + 1000000000ull);

  // A timeout longer than the frame period: every frame but the last is
  // completed by the next frame's first word.
  PixyNodeOptions options = shipped_options();
  options.frame_timeout_s = 0.05;
  LogLines log;
  ObservationInbox& inbox = observation_inbox();
  inbox.clear();
  PixyNode node(options, std::make_unique<bridge::ScriptedByteSource>(script, "/dev/pixy_test"), log.sink(),
                bridge::ByteScript::clock(script));
  start_when_read(node);

  // Then one observation per frame arrives, in order, also for frames without
  // detections, stamped when the frame's last block (or its start) was read
  // minus the latency.
  std::vector<msg::LandmarkObservation> got = inbox.wait_for(kFrames, std::chrono::seconds(10));
  ASSERT_EQ(got.size(), kFrames);
  std::this_thread::sleep_for(milliseconds(200));
  ASSERT_EQ(inbox.wait_for(kFrames + 1, milliseconds(1)).size(), kFrames) << "an extra message";
  node.stop();

  const pixy::CameraModel camera = options.pixy.camera;
  for (std::size_t i = 0; i < kFrames; ++i) {
    SCOPED_TRACE("frame " + std::to_string(i));
    const msg::LandmarkObservation& m = got[i];
    EXPECT_EQ(m.header().seq(), i + 1);
    EXPECT_EQ(m.header().robot_id(), loopback_options().robot_id);
    EXPECT_EQ(m.header().frame_id(), "camera");
    EXPECT_EQ(m.camera_frame(), i);
    // A frame without blocks is known only when the next frame's first word
    // arrives (a lone sync word is ambiguous until then), a frame period
    // later: it is stamped that period before.
    EXPECT_EQ(m.header().stamp_ns(), arrival_ns(i) - kLatencyNs);
    switch (i % 4) {
      case 0:
        EXPECT_EQ(m.blocks_in_frame(), 1u);
        EXPECT_EQ(m.blocks_rejected(), 0u);
        ASSERT_EQ(m.detections().size(), 1u);
        break;
      case 1:
        EXPECT_EQ(m.blocks_in_frame(), 3u);  // frame 5's corrupted block is not counted
        EXPECT_EQ(m.blocks_rejected(), 1u);
        ASSERT_EQ(m.detections().size(), 2u);
        EXPECT_EQ(m.detections()[1].landmark_id(), 2);
        EXPECT_DOUBLE_EQ(m.detections()[1].range_m(), pixy::range_m(camera, 21));
        break;
      case 2:
        EXPECT_EQ(m.blocks_in_frame(), 0u);
        EXPECT_TRUE(m.detections().empty());
        break;
      default:
        EXPECT_EQ(m.blocks_in_frame(), 1u);
        EXPECT_EQ(m.blocks_rejected(), 1u);
        EXPECT_TRUE(m.detections().empty());
    }
    if (!m.detections().empty()) {
      const msg::LandmarkDetection& d = m.detections()[0];
      EXPECT_EQ(d.landmark_id(), 1);
      EXPECT_DOUBLE_EQ(d.range_m(), pixy::range_m(camera, 42));
      EXPECT_DOUBLE_EQ(d.bearing_rad(), pixy::bearing_rad(camera, 160));
      EXPECT_DOUBLE_EQ(d.range_sigma_m(), pixy::range_sigma_m(camera, pixy::range_m(camera, 42), 42));
      EXPECT_DOUBLE_EQ(d.bearing_sigma_rad(), camera.bearing_sigma_rad);
      EXPECT_EQ(d.block().signature(), 012);
      EXPECT_EQ(d.block().x_px(), 160);
      EXPECT_EQ(d.block().height_px(), 42);
      EXPECT_EQ(d.block().angle_deg(), -3);
    }
  }
  EXPECT_EQ(inbox.lost(), 0u);

  // And the bad bytes were counted and skipped.
  const PixyNodeCounters c = node.counters();
  EXPECT_EQ(c.parser.frames, kFrames);
  EXPECT_EQ(c.parser.checksum_errors, 1u);
  EXPECT_GE(c.parser.bytes_skipped, garbage_bytes);
  EXPECT_GE(c.parser.resyncs, 2u);
  EXPECT_EQ(c.published, kFrames);
  EXPECT_EQ(c.frames_timed_out, 1u);
  EXPECT_EQ(c.detections.detections, 5u * 1 + 5u * 2);
  EXPECT_EQ(c.detections.unknown_signature, 5u + 5u);
  EXPECT_TRUE(log.contains("final status: frames 20"));
}

TEST(PixyNode, FramesReadInOneChunkAreStampedWhenTheCameraSentThem) {
  // Given a camera sending 24 frames at 10 Hz, each with landmark 1, of which
  // the host read frames 12 to 19 in one chunk 60 ms after frame 19 (the
  // reader, or the camera's writer, was left unscheduled for 0.8 s, as on a
  // loaded host),
  ObservationInbox& inbox = observation_inbox();
  inbox.clear();
  constexpr std::size_t kFrames = 24;
  constexpr std::uint64_t kCameraNs = 100000000ull;
  const auto sent_ns = [&](std::size_t i) { return kBaseNs + kCameraNs * i; };
  auto script = std::make_shared<bridge::ByteScript>();
  std::vector<std::uint8_t> bunch;
  for (std::size_t i = 0; i < kFrames; ++i) {
    const std::vector<std::uint8_t> frame = pixy::encode_frame({landmark_1()});
    if (i < 12 || i >= 20) {
      script->add_bytes(frame, sent_ns(i));
      continue;
    }
    bunch.insert(bunch.end(), frame.begin(), frame.end());
    if (i == 19) script->add_bytes(bunch, sent_ns(i) + 60000000ull);
  }
  script->add_idle(sent_ns(kFrames - 1) + 1000000000ull);
  const PixyNodeOptions options = shipped_options();
  ASSERT_EQ(options.pixy.rate.frame_rate_hz, 50.0);  // the Pixy's rate, faster than this camera's
  LogLines log;
  PixyNode node(options, std::make_unique<bridge::ScriptedByteSource>(script, "/dev/pixy_test"), log.sink(),
                bridge::ByteScript::clock(script));
  start_when_read(node);

  // then every frame is published, stamped when the camera sent it: the
  // bunched ones a period apart (100 ms, measured on the frames before), in
  // the camera's phase, not all at the read.
  const std::vector<msg::LandmarkObservation> got = inbox.wait_for(kFrames, std::chrono::seconds(10));
  node.stop();
  ASSERT_EQ(got.size(), kFrames);
  for (std::size_t i = 0; i < kFrames; ++i) {
    EXPECT_EQ(got[i].header().stamp_ns(), sent_ns(i) - kLatencyNs) << "frame " << i;
    EXPECT_EQ(got[i].detections().size(), 1u) << "frame " << i;
  }
  EXPECT_EQ(node.counters().rate.rate_limited, 0u);
}

// A scripted device that records the timeout of every read.
class TimeoutRecordingSource final : public bridge::ByteSource {
 public:
  explicit TimeoutRecordingSource(std::shared_ptr<bridge::ByteScript> script) : inner_(std::move(script)) {}
  void open() override { inner_.open(); }
  void close() override { inner_.close(); }
  bool is_open() const override { return inner_.is_open(); }
  serial::ReadResult read_some(std::uint8_t* buffer, std::size_t max, milliseconds timeout) override {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      timeouts_.push_back(timeout.count());
    }
    return inner_.read_some(buffer, max, timeout);
  }
  std::string name() const override { return inner_.name(); }
  std::vector<long long> timeouts() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return timeouts_;
  }

 private:
  bridge::ScriptedByteSource inner_;
  mutable std::mutex mutex_;
  std::vector<long long> timeouts_;
};

TEST(PixyNode, TheDeviceReadWaitsOnlyUntilTheOpenFrameTimesOut) {
  // Given one frame and then silence (a camera that sees one landmark once),
  ObservationInbox& inbox = observation_inbox();
  inbox.clear();
  auto script = std::make_shared<bridge::ByteScript>();
  script->add_bytes(pixy::encode_frame({landmark_1()}), kBaseNs);
  PixyNodeOptions options = shipped_options();
  options.frame_timeout_s = 0.01;
  auto source = std::make_unique<TimeoutRecordingSource>(script);
  TimeoutRecordingSource& recorder = *source;
  LogLines log;
  PixyNode node(options, std::move(source), log.sink(), bridge::ByteScript::clock(script));
  start_when_read(node);
  // while the frame is open, every read waits until it times out (10 ms, rounded
  // up to the next ms), not the whole 50 ms poll period;
  std::this_thread::sleep_for(milliseconds(100));
  EXPECT_TRUE(inbox.wait_for(1, milliseconds(1)).empty()) << "the script's clock has not passed the timeout";
  script->add_idle(kBaseNs + 15000000ull);
  ASSERT_EQ(inbox.wait_for(1, std::chrono::seconds(10)).size(), 1u);
  std::this_thread::sleep_for(milliseconds(120));
  node.stop();
  const std::vector<long long> timeouts = recorder.timeouts();
  ASSERT_GE(timeouts.size(), 4u);
  EXPECT_EQ(timeouts.front(), 50) << "no frame open yet";
  EXPECT_EQ(timeouts[1], 11);
  EXPECT_GE(std::count(timeouts.begin(), timeouts.end(), 11), 3) << "while the frame was open";
  // and once it is published, the reads wait the poll period again.
  EXPECT_EQ(timeouts.back(), 50);
  EXPECT_EQ(std::count_if(timeouts.begin(), timeouts.end(), [](long long t) { return t != 11 && t != 50; }), 0);
}

// The diagnostics reports of the node under test (robot id of loopback_options()).
using DiagnosticsInbox = test_support::Inbox<msg::Diagnostics>;
::testing::Environment* const kDiagnosticsInboxCleanup =
    ::testing::AddGlobalTestEnvironment(new test_support::InboxCleanup<msg::Diagnostics>);

TEST(PixyNode, SyncWordFloodIsReadToTheEndAndRateLimitedWithAWarning) {
  // Given a line that delivers "aa55 aa55 ..." at 1 MB/s for 2 s (a frame
  // without blocks every 2 bytes), then, after 0.5 s of silence, a real
  // camera's 50 frames at 50 Hz, each with landmark 1,
  ObservationInbox& inbox = observation_inbox();
  inbox.clear();
  DiagnosticsInbox& diagnostics = DiagnosticsInbox::instance(loopback_options(), "test_diagnostics_reader");
  diagnostics.clear();
  auto script = std::make_shared<bridge::ByteScript>();
  constexpr std::size_t kChunk = 4096;
  constexpr std::size_t kFloodChunks = 488;  // 2.0 MB, 2.0 s at 1 MB/s
  std::vector<std::uint8_t> flood;
  for (std::size_t i = 0; i < kChunk / 2; ++i) {
    flood.push_back(0x55);
    flood.push_back(0xaa);
  }
  std::size_t bytes = 0;
  std::uint64_t t = kBaseNs;
  for (std::size_t i = 0; i < kFloodChunks; ++i) {
    t = kBaseNs + static_cast<std::uint64_t>(1e3 * static_cast<double>((i + 1) * kChunk));  // 1 us per byte
    script->add_bytes(flood, t);
    bytes += flood.size();
  }
  const std::uint64_t flood_end_ns = t;
  constexpr std::size_t kValidFrames = 50;
  const std::vector<std::uint8_t> frame = pixy::encode_frame({landmark_1()});
  for (std::size_t i = 0; i < kValidFrames; ++i) {
    t = flood_end_ns + 500000000ull + kFrameNs * i;
    script->add_bytes(frame, t);
    bytes += frame.size();
  }
  script->add_idle(t + 1000000000ull);  // the last frame completes by frame_timeout_s

  PixyNodeOptions options;
  options.pixy.signatures.add(012, 1);
  options.dds = loopback_options();
  options.dds.diagnostics_period_s = 0.2;
  options.process.status_period_s = 0.0;
  LogLines log;
  PixyNode node(options, std::make_unique<bridge::ScriptedByteSource>(script, "/dev/pixy_flood"), log.sink(),
                bridge::ByteScript::clock(script));
  ASSERT_TRUE(node.wait_for_subscribers(1, std::chrono::seconds(10)));
  node.start();
  ASSERT_TRUE(script->wait_finished(std::chrono::seconds(20)));
  std::this_thread::sleep_for(milliseconds(300));  // the last flush and a diagnostics report

  // then every byte was read and parsed,
  const PixyNodeCounters c = node.counters();
  EXPECT_EQ(c.device.bytes, bytes);
  EXPECT_EQ(c.parser.bytes_in, bytes);
  EXPECT_GE(c.parser.frames, kFloodChunks * kChunk / 2);
  // frames without blocks were published at most at pixy.frame_rate_hz (50 Hz
  // over 2 s, plus the tolerance's burst) and the camera's frames all were;
  // every other frame was dropped before any DDS work and counted,
  const pixy::FrameRateOptions& rate = options.pixy.rate;
  const auto most_empty = static_cast<std::uint64_t>(rate.frame_rate_hz * (2.0 + rate.tolerance_s)) + 2;
  EXPECT_LE(c.published, most_empty + kValidFrames);
  EXPECT_EQ(c.rate.published, c.published);
  EXPECT_EQ(c.rate.rate_limited, c.parser.frames - c.published);
  EXPECT_EQ(c.rate.empty_rate_limited, c.rate.rate_limited);
  const std::vector<msg::LandmarkObservation> got = inbox.wait_for(c.published, std::chrono::seconds(10));
  EXPECT_EQ(got.size(), c.published);
  EXPECT_EQ(std::count_if(got.begin(), got.end(), [](const auto& m) { return m.detections().size() == 1; }),
            static_cast<std::ptrdiff_t>(kValidFrames));
  // a WARN line named the offered rate and the limit,
  EXPECT_TRUE(log.contains("WARN: frame rate over the limit: "));
  EXPECT_TRUE(log.contains("50 Hz for frames without blocks (pixy.frame_rate_hz)"));
  // and the diagnostics topic said WARN, naming the counter.
  const std::vector<msg::Diagnostics> reports = diagnostics.wait_for(1, std::chrono::seconds(5));
  const bool warned = std::any_of(reports.begin(), reports.end(), [](const msg::Diagnostics& d) {
    return d.process() == "pixy_bridge" && d.level() == 1 &&
           d.status().find("frames_rate_limited +") != std::string::npos;
  });
  EXPECT_TRUE(warned) << reports.size() << " reports";
  node.stop();
  EXPECT_TRUE(log.contains("final status: frames "));
}

TEST(PixyNode, MissingDeviceIsLoggedAndRetried) {
  auto script = std::make_shared<bridge::ByteScript>();
  script->fail_next_opens(3);
  const std::vector<std::uint8_t> frame = pixy::encode_frame({landmark_1()});
  script->add_bytes(frame, kBaseNs);
  script->add_bytes(frame, kBaseNs + kFrameNs);
  PixyNodeOptions options;
  options.pixy.signatures.add(012, 1);
  options.dds = loopback_options();
  options.process.reopen_period_s = 0.01;
  options.process.status_period_s = 0.0;
  LogLines log;
  ObservationInbox& inbox = observation_inbox();
  inbox.clear();
  PixyNode node(options, std::make_unique<bridge::ScriptedByteSource>(script, "/dev/ttyPIXY9"), log.sink(),
                bridge::ByteScript::clock(script));
  ASSERT_TRUE(node.wait_for_subscribers(1, std::chrono::seconds(10)));
  node.start();
  EXPECT_EQ(inbox.wait_for(1, std::chrono::seconds(10)).size(), 1u);  // frame 0; frame 1 still open
  node.stop();
  EXPECT_EQ(node.counters().device.open_failures, 3u);
  ASSERT_FALSE(log.empty());
  EXPECT_TRUE(log.contains("cannot open serial device '/dev/ttyPIXY9'"));
}

}  // namespace
}  // namespace pixyslam::pixy_node
