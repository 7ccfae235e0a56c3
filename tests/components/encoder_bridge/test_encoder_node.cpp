// The encoder bridge's node layer: message conversion,
// options, and the node itself driven by a scripted byte source (and once by a
// real pseudo-terminal), publishing Odometry over DDS on the loopback profile
// to a reader in the same test.
#include <unistd.h>

#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdint>
#include <fstream>
#include <memory>
#include <mutex>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

#include "dds_test_support.h"
#include "pixyslam/bridge/byte_source.h"
#include "pixyslam/dds/endpoints.h"
#include "pixyslam/encoder/arduino_line_parser.h"
#include "pixyslam/encoder/arduino_clock.h"
#include "pixyslam/encoder_node/encoder_node.h"
#include "pixyslam/encoder_node/encoder_node_options.h"
#include "pixyslam/encoder_node/odometry_conversions.h"
#include "pixyslam/serial/pseudo_terminal.h"

namespace pixyslam::encoder_node {
namespace {

using std::chrono::milliseconds;
using test_support::LogLines;

constexpr std::int64_t kMs = 1000000;  // ns

// ---------------------------------------------------------------- conversions

TEST(OdometryConversions, OutputBecomesAMessageStampedAtThePeriodStart) {
  encoder::OdometryOutput o;
  o.t_s = 2.5;
  o.duration_s = 0.1;
  o.v_mps = 0.2;
  o.w_radps = -0.5;
  o.distance_m = 0.02;
  o.rotation_rad = -0.05;
  const std::uint64_t epoch = 1700000000000000000ull;
  const msg::Odometry m = to_odometry_msg(o, 5, epoch);
  EXPECT_EQ(m.header().stamp_ns(), epoch + 2500000000ull);
  EXPECT_EQ(m.header().frame_id(), "base_link");
  EXPECT_DOUBLE_EQ(m.v_mps(), 0.2);
  EXPECT_DOUBLE_EQ(m.w_radps(), -0.5);
  EXPECT_DOUBLE_EQ(m.period_s(), 0.1);
  EXPECT_DOUBLE_EQ(m.distance_m(), 0.02);
  EXPECT_DOUBLE_EQ(m.rotation_rad(), -0.05);
  EXPECT_EQ(m.encoder_samples(), 5u);
}

TEST(OdometryConversions, StampRoundsToTheNanosecondAndNeverUnderflows) {
  EXPECT_EQ(to_stamp_ns(0.9025, 1000000000ull), 1902500000ull);
  EXPECT_EQ(to_stamp_ns(1e-9 * 0.6, 10), 11u);
  EXPECT_EQ(to_stamp_ns(-0.5e-9 * 3, 10), 8u);
  EXPECT_EQ(to_stamp_ns(-5.0, 10), 0u);
}

// ---------------------------------------------------------------- options

std::string valid_yaml(const std::string& extra = "") {
  return encoder::to_yaml(encoder::EncoderOptions{}) + extra;
}

std::string config_error_of(const std::string& text) {
  try {
    auto root = config::YamlReader::from_string(text, "test.yaml");
    read_encoder_node_options(root, "/cfg");
  } catch (const config::ConfigError& e) {
    return e.what();
  }
  return "(no error)";
}

TEST(EncoderNodeOptions, ShippedConfigLoadsWithNodeAndDds) {
  const EncoderNodeOptions o =
      read_encoder_node_options_file(std::string(PIXYSLAM_CONFIG_DIR) + "/encoder_bridge.yaml");
  EXPECT_EQ(o.process.serial_device, "/dev/ttyACM0");
  EXPECT_EQ(o.process.baud, 115200);
  EXPECT_DOUBLE_EQ(o.process.reopen_period_s, 1.0);
  EXPECT_DOUBLE_EQ(o.clock_window_s, 1.0);
  EXPECT_EQ(o.dds.profiles_file, std::string(PIXYSLAM_CONFIG_DIR) + "/dds/profiles.xml");
  // The core's file reader accepts the same file.
  EXPECT_DOUBLE_EQ(encoder::read_encoder_options_file(std::string(PIXYSLAM_CONFIG_DIR) + "/encoder_bridge.yaml")
                       .wheel_base_m,
                   o.encoder.wheel_base_m);
}

TEST(EncoderNodeOptions, EffectiveConfigurationReadsBack) {
  auto root = config::YamlReader::from_string(
      valid_yaml("node:\n  serial_device: /dev/ttyUSB1\n  baud: 57600\n  reopen_period_s: 0.25\n  status_period_s: 0\n"
                 "  clock_window_s: 2\n"
                 "dds:\n  domain_id: 3\n  profiles_file: /x/p.xml\n  robot_id: r7\n"),
      "test.yaml");
  const EncoderNodeOptions o = read_encoder_node_options(root, "/cfg");
  auto again_root = config::YamlReader::from_string(to_yaml(o), "again.yaml");
  const EncoderNodeOptions again = read_encoder_node_options(again_root, "/elsewhere");
  EXPECT_EQ(to_yaml(again), to_yaml(o));
  EXPECT_EQ(again.process.serial_device, "/dev/ttyUSB1");
  EXPECT_EQ(again.process.baud, 57600);
  EXPECT_DOUBLE_EQ(again.process.reopen_period_s, 0.25);
  EXPECT_DOUBLE_EQ(again.process.status_period_s, 0.0);
  EXPECT_DOUBLE_EQ(again.clock_window_s, 2.0);
  EXPECT_EQ(again.dds.domain_id, 3);
  EXPECT_EQ(again.dds.profiles_file, "/x/p.xml");
  EXPECT_EQ(again.dds.robot_id, "r7");
}

TEST(EncoderNodeOptions, ErrorsNameTheFileAndTheKey) {
  struct Case {
    std::string yaml;
    std::string expected;
  };
  const std::vector<Case> cases = {
      {valid_yaml("node:\n  reopen_period_s: 0\n"), "test.yaml: key 'node.reopen_period_s': value 0"},
      {valid_yaml("node:\n  clock_window: 1\n"), "test.yaml: key 'node.clock_window': unknown key"},
      {valid_yaml("node:\n  clock_window_s: abc\n"), "test.yaml: key 'node.clock_window_s'"},
      // The serial link is the process's, as in pixy_bridge.yaml; a non-standard
      // rate is refused with the list of the standard ones.
      {valid_yaml("node:\n  serial_device: ttyACM0\n"), "key 'node.serial_device': value 'ttyACM0' is not an absolute path"},
      {valid_yaml("node:\n  baud: 115201\n"), "key 'node.baud': value 115201 is not a standard serial rate (50, "},
      {valid_yaml("node:\n  baud: 2e5\n"), "key 'node.baud': expected an integer"},
      {valid_yaml("  serial_device: /dev/ttyACM0\nnode:\n  serial_device: /dev/ttyUSB0\n"),
       "key 'encoder_bridge.serial_device': given twice: here and as node.serial_device"},
      {valid_yaml("  baud: 115201\n"), "key 'encoder_bridge.baud': value 115201 is not a standard serial rate"},
      {valid_yaml("dds:\n  domain_id: 300\n"), "test.yaml: key 'dds.domain_id'"},
      {valid_yaml("nodes: {}\n"), "test.yaml: key 'nodes': unknown key"},
      {"node: {}\n", "test.yaml: key 'encoder_bridge': missing"},
  };
  for (const Case& c : cases) {
    const std::string e = config_error_of(c.yaml);
    EXPECT_NE(e.find(c.expected), std::string::npos) << "got: " << e << "\nyaml:\n" << c.yaml;
  }
}

// Until 2026-11-29 the serial link was in encoder_bridge:. An installed file
// the user edited keeps it after an upgrade: still taken (with a warning on
// stderr), so the robot comes up.
TEST(EncoderNodeOptions, TheSerialLinkWhereItWasBeforeIsStillTaken) {
  auto root = config::YamlReader::from_string(valid_yaml("  serial_device: /dev/ttyUSB7\n  baud: 57600\n"), "old.yaml");
  const EncoderNodeOptions o = read_encoder_node_options(root, "/cfg");
  EXPECT_EQ(o.process.serial_device, "/dev/ttyUSB7");
  EXPECT_EQ(o.process.baud, 57600);
  EXPECT_DOUBLE_EQ(o.encoder.wheel_base_m, encoder::EncoderOptions{}.wheel_base_m);
  // On the command line the old name says where the key went.
  EncoderNodeOptions set = o;
  std::vector<std::string> assignments = {"encoder_bridge.baud=9600"};
  try {
    apply_overrides(set, assignments);
    ADD_FAILURE() << "encoder_bridge.baud accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("moved to node.baud"), std::string::npos) << e.what();
  }
  assignments = {"node.baud=9600"};
  apply_overrides(set, assignments);
  EXPECT_EQ(set.process.baud, 9600);
}

TEST(EncoderNodeOptions, FileErrorsNameThePath) {
  const std::string path = ::testing::TempDir() + "encoder_node_options_" + std::to_string(::getpid()) + ".yaml";
  {
    std::ofstream out(path);
    out << valid_yaml("node:\n  status_period_s: -1\n");
  }
  try {
    read_encoder_node_options_file(path);
    ADD_FAILURE() << "expected a config error";
  } catch (const config::ConfigError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find(path + ": key 'node.status_period_s'"), std::string::npos) << what;
  }
  std::remove(path.c_str());
}

// ---------------------------------------------------------------- the node over DDS

dds::DdsOptions loopback_options() { return test_support::loopback_options(100, 64, "encoder_test_"); }

EncoderNodeOptions node_options() {
  EncoderNodeOptions o;
  o.dds = loopback_options();
  o.process.reopen_period_s = 0.02;
  o.process.status_period_s = 0.0;
  return o;
}

// The Odometry the test's own participant receives (test_support::Inbox).
using OdometryInbox = test_support::Inbox<msg::Odometry>;
OdometryInbox& odometry_inbox() { return OdometryInbox::instance(loopback_options(), "test_odometry_reader"); }
::testing::Environment* const kInboxCleanup =
    ::testing::AddGlobalTestEnvironment(new test_support::InboxCleanup<msg::Odometry>);

constexpr std::uint64_t kBaseNs = 1700000000000000000ull;  // host time of Arduino time 0 (a whole second)
constexpr std::uint32_t kStartUs = 1000000;                 // the first sample, 1 s after boot
constexpr std::int32_t kLeftTicksPerSample = 20;
constexpr std::int32_t kRightTicksPerSample = 30;

encoder::EncoderSample sample_number(std::uint32_t j) {
  encoder::EncoderSample s;
  s.seq = 100 + j;
  s.arduino_time_us = kStartUs + 20000 * j;
  s.left_ticks = static_cast<std::int32_t>(j) * kLeftTicksPerSample;
  s.right_ticks = static_cast<std::int32_t>(j) * kRightTicksPerSample;
  return s;
}

// Arrival of sample j: 2.5 ms after it was taken for the first, 2 ms for the
// rest, plus up to 3 ms of jitter on every third (the clock mapping removes it).
std::uint64_t arrival_ns(std::uint32_t j, std::mt19937& prng) {
  const std::uint64_t taken = kBaseNs + static_cast<std::uint64_t>(sample_number(j).arduino_time_us) * 1000;
  if (j == 0) return taken + 2500000;
  std::uniform_int_distribution<std::uint64_t> jitter(1, 3000000);
  return taken + 2000000 + (j % 3 == 2 ? jitter(prng) : 0);
}

TEST(EncoderNode, PublishesOnePeriodAtATimeWithMappedStampsAndSkipsBadBytes) {
  // Given 56 samples at 50 Hz, constant wheel speeds, jittered arrivals and
  // rejected lines of every kind mixed in,
  auto script = std::make_shared<bridge::ByteScript>();
  std::mt19937 prng(42);
  char unknown[32];
  std::snprintf(unknown, sizeof unknown, "$XYZ,1*%02X\r\n", encoder::arduino_checksum("XYZ,1"));
  const std::array<std::string, 5> junk = {
      "garbage without a dollar\r\n",  // skipped bytes, no line
      "$ENC,1,2,3*\r\n",                // bad framing
      "$ENC,1,2000,3,4*00\r\n",         // bad checksum
      "$ENC,7,140",                      // cut short by the next '$': unterminated
      unknown,                           // valid checksum, unknown type
  };
  std::array<std::uint64_t, 5> used{};
  for (std::uint32_t j = 0; j < 56; ++j) {
    std::string chunk;
    if (j % 7 == 3) {
      const std::size_t kind = (j / 7) % junk.size();
      chunk += junk[kind];
      ++used[kind];
    }
    chunk += encoder::format_line(sample_number(j));
    script->add_bytes(chunk, arrival_ns(j, prng));
  }
  // When the node reads them and a reader listens,
  LogLines log;
  OdometryInbox& inbox = odometry_inbox();
  inbox.clear();
  EncoderNode node(node_options(), std::make_unique<bridge::ScriptedByteSource>(script), log.sink(),
                   bridge::ByteScript::clock(script));
  ASSERT_TRUE(node.wait_for_subscribers(1, std::chrono::seconds(10)));
  node.start();

  // Then periods 0..9 go out: [t0 + 0.1 k, t0 + 0.1 (k + 1)), t0 = the first
  // sample's host time (2.5 ms after its Arduino time; the others map to 2 ms).
  std::vector<msg::Odometry> got = inbox.wait_for(10, std::chrono::seconds(10));
  ASSERT_EQ(got.size(), 10u);
  std::this_thread::sleep_for(milliseconds(300));
  got = inbox.wait_for(11, milliseconds(1));
  ASSERT_EQ(got.size(), 10u) << "an extra message";

  const double metres_per_tick = 2.0 * M_PI * 0.0325 / 1320.0;
  const double step_distance = 0.5 * (kLeftTicksPerSample + kRightTicksPerSample) * metres_per_tick;
  const double step_rotation = (kRightTicksPerSample - kLeftTicksPerSample) * metres_per_tick / 0.135;
  const std::uint64_t t0 = kBaseNs + static_cast<std::uint64_t>(kStartUs) * 1000 + 2500000;
  for (std::size_t k = 0; k < got.size(); ++k) {
    const msg::Odometry& m = got[k];
    SCOPED_TRACE("period " + std::to_string(k));
    EXPECT_EQ(m.header().seq(), k + 1);
    EXPECT_EQ(m.header().robot_id(), loopback_options().robot_id);
    EXPECT_EQ(m.header().frame_id(), "base_link");
    EXPECT_EQ(m.header().stamp_ns(), t0 + 100000000ull * k);
    EXPECT_DOUBLE_EQ(m.period_s(), 0.1);
    // Period 0 also holds the half millisecond by which the first sample came
    // late (0.5 ms of step 6); every later period holds exactly five steps.
    const double steps = k == 0 ? 5.025 : 5.0;
    EXPECT_NEAR(m.distance_m(), steps * step_distance, 1e-12);
    EXPECT_NEAR(m.rotation_rad(), steps * step_rotation, 1e-12);
    EXPECT_NEAR(m.v_mps(), steps * step_distance / 0.1, 1e-10);
    EXPECT_NEAR(m.w_radps(), steps * step_rotation / 0.1, 1e-10);
    EXPECT_EQ(m.encoder_samples(), k == 0 ? 6u : 5u);
  }
  EXPECT_EQ(inbox.lost(), 0u);

  // And every bad line was counted and skipped.
  const EncoderNodeCounters c = node.counters();
  EXPECT_EQ(c.parser.samples, 56u);
  EXPECT_EQ(c.parser.bad_framing, used[1]);
  EXPECT_EQ(c.parser.bad_checksum, used[2]);
  EXPECT_EQ(c.parser.unterminated_lines, used[3]);
  EXPECT_EQ(c.parser.unknown_type, used[4]);
  EXPECT_EQ(c.parser.rejected_lines(), used[1] + used[2] + used[3] + used[4]);
  EXPECT_GE(c.parser.bytes_skipped, used[0] * junk[0].size());
  EXPECT_EQ(c.wheel.steps, 55u);
  EXPECT_EQ(c.published, 10u);
  EXPECT_EQ(c.device.opens, 1u);

  // When the Arduino then goes quiet for 2 s, the elapsed periods go out as
  // "no data" (up to max_sample_gap_s ago), with the stream's rate and stamps.
  const std::uint64_t last_arrival = script->now_ns();
  script->add_idle(last_arrival + 2000000000ull);
  got = inbox.wait_for(25, std::chrono::seconds(10));
  ASSERT_EQ(got.size(), 25u);
  // Period 10 still holds samples 51..55 (4.975 steps over its first 99.5 ms:
  // step 56 never came); the stream stalled in it, so their mean velocity
  // holds for the whole period (the rest is unknown, not standing still).
  EXPECT_EQ(got[10].encoder_samples(), 5u);
  EXPECT_NEAR(got[10].distance_m(), 5.0 * step_distance, 1e-12);
  for (std::size_t k = 11; k < got.size(); ++k) {
    EXPECT_EQ(got[k].encoder_samples(), 0u) << k;
    EXPECT_EQ(got[k].v_mps(), 0.0) << k;
    EXPECT_EQ(got[k].header().stamp_ns(), t0 + 100000000ull * k) << k;
    EXPECT_EQ(got[k].header().seq(), k + 1);
  }
  node.stop();
  EXPECT_EQ(node.counters().empty_periods, 14u);
  EXPECT_TRUE(log.contains("final status", "samples 56")) << log.all();
}

TEST(EncoderNode, HoldsItsMessagesUntilTheReadersMatchAndLosesNone) {
  // Given a node that waits for two readers (node.wait_readers) while only the
  // test's inbox listens, and an Arduino that is already sending,
  auto script = std::make_shared<bridge::ByteScript>();
  std::mt19937 prng(3);
  for (std::uint32_t j = 0; j < 56; ++j) script->add_bytes(encoder::format_line(sample_number(j)), arrival_ns(j, prng));
  LogLines log;
  OdometryInbox& inbox = odometry_inbox();
  inbox.clear();
  EncoderNodeOptions options = node_options();
  options.process.wait_readers = 2;
  options.process.wait_readers_timeout_s = 60.0;
  EncoderNode node(options, std::make_unique<bridge::ScriptedByteSource>(script), log.sink(),
                   bridge::ByteScript::clock(script));
  ASSERT_TRUE(node.wait_for_subscribers(1, std::chrono::seconds(10)));
  node.start();

  // Then the device is read but nothing goes out,
  std::this_thread::sleep_for(milliseconds(500));
  EXPECT_EQ(node.counters().parser.samples, 56u);
  EXPECT_TRUE(inbox.wait_for(1, milliseconds(1)).empty());
  EXPECT_EQ(node.counters().published, 0u);

  // and when a second reader matches, both get every period from seq 1 on.
  std::mutex mutex;
  std::vector<std::uint64_t> late_seqs;
  {
    dds::Participant late_participant(loopback_options(), "late_odometry_reader");
    dds::Reader<msg::Odometry> late(late_participant, [&](const msg::Odometry& m) {
      std::lock_guard<std::mutex> lock(mutex);
      late_seqs.push_back(m.header().seq());
    });
    const std::vector<msg::Odometry> got = inbox.wait_for(10, std::chrono::seconds(10));
    ASSERT_EQ(got.size(), 10u);
    for (std::size_t k = 0; k < got.size(); ++k) EXPECT_EQ(got[k].header().seq(), k + 1);
    for (int i = 0; i < 500; ++i) {
      {
        std::lock_guard<std::mutex> lock(mutex);
        if (late_seqs.size() >= 10) break;
      }
      std::this_thread::sleep_for(milliseconds(10));
    }
  }
  node.stop();
  std::lock_guard<std::mutex> lock(mutex);
  ASSERT_EQ(late_seqs.size(), 10u);
  for (std::size_t k = 0; k < late_seqs.size(); ++k) EXPECT_EQ(late_seqs[k], k + 1);
  EXPECT_TRUE(log.contains("2 readers matched: publishing the 10 messages held")) << log.all();
}

TEST(EncoderNode, MissingAndHungUpDeviceIsLoggedAndReopened) {
  // Given a device that is missing twice, then delivers an Arduino reset and
  // samples, hangs up, and comes back with more samples,
  auto script = std::make_shared<bridge::ByteScript>();
  script->fail_next_opens(2);
  std::mt19937 prng(7);
  script->add_bytes(encoder::format_line(encoder::EncoderReset{"1.2.3", 999}), kBaseNs);
  for (std::uint32_t j = 0; j < 10; ++j) script->add_bytes(encoder::format_line(sample_number(j)), arrival_ns(j, prng));
  script->add_hangup(arrival_ns(9, prng) + 5 * kMs);
  for (std::uint32_t j = 10; j < 20; ++j) script->add_bytes(encoder::format_line(sample_number(j)), arrival_ns(j, prng));

  LogLines log;
  OdometryInbox& inbox = odometry_inbox();
  inbox.clear();
  EncoderNode node(node_options(), std::make_unique<bridge::ScriptedByteSource>(script, "/dev/ttyTEST7"),
                   log.sink(), bridge::ByteScript::clock(script));
  ASSERT_TRUE(node.wait_for_subscribers(1, std::chrono::seconds(10)));
  node.start();
  ASSERT_TRUE(script->wait_finished(std::chrono::seconds(10)));
  // 20 samples over 0.38 s: periods 0..2 are complete.
  const std::vector<msg::Odometry> got = inbox.wait_for(3, std::chrono::seconds(10));
  node.stop();

  // Then the node never gave up, and said what happened, naming the device.
  EXPECT_EQ(got.size(), 3u);
  const EncoderNodeCounters c = node.counters();
  EXPECT_EQ(c.device.open_failures, 2u);
  EXPECT_EQ(c.device.opens, 2u);
  EXPECT_EQ(c.device.hangups, 1u);
  EXPECT_EQ(c.parser.resets, 1u);
  EXPECT_EQ(c.wheel.ticks_per_revolution_mismatches, 1u);
  EXPECT_EQ(c.clock.restarts, 3u);  // two opens and the RST line
  EXPECT_TRUE(log.contains("cannot open serial device '/dev/ttyTEST7'", "attempt 1")) << log.all();
  EXPECT_TRUE(log.contains("opened serial device '/dev/ttyTEST7' after 2 failed attempts")) << log.all();
  EXPECT_TRUE(log.contains("'/dev/ttyTEST7' hung up")) << log.all();
  EXPECT_TRUE(log.contains("firmware '1.2.3'", "differs from the configured 1320")) << log.all();
  EXPECT_TRUE(log.contains("final status: device '/dev/ttyTEST7'", "hang-ups 1")) << log.all();
}

TEST(EncoderNode, ADeviceThatFallsSilentWithoutAHangupIsNamedOncePerSilence) {
  // Given an Arduino that sends, then nothing for 7 s (a UART wire pulled: no
  // hang-up), then again, then nothing for 3 s,
  auto script = std::make_shared<bridge::ByteScript>();
  std::mt19937 prng(7);
  for (std::uint32_t j = 0; j < 10; ++j) script->add_bytes(encoder::format_line(sample_number(j)), arrival_ns(j, prng));
  const std::uint64_t quiet_from = arrival_ns(9, prng);
  for (int k = 1; k <= 70; ++k) script->add_idle(quiet_from + static_cast<std::uint64_t>(k) * 100 * kMs);
  const std::uint64_t back_ns = quiet_from + 7100 * kMs;
  script->add_bytes(encoder::format_line(sample_number(10)), back_ns);
  for (int k = 1; k <= 30; ++k) script->add_idle(back_ns + static_cast<std::uint64_t>(k) * 100 * kMs);

  LogLines log;
  EncoderNodeOptions options = node_options();
  options.process.silence_warn_s = 5.0;
  EncoderNode node(options, std::make_unique<bridge::ScriptedByteSource>(script, "/dev/ttyTEST8"), log.sink(),
                   bridge::ByteScript::clock(script));
  node.start();
  ASSERT_TRUE(script->wait_finished(std::chrono::seconds(10)));
  node.stop();

  // Then the silence of 7 s was named once, with the device, and its end; the
  // 3 s after it were not.
  const EncoderNodeCounters c = node.counters();
  EXPECT_EQ(c.device.silences, 1u);
  EXPECT_FALSE(c.device.silent);
  EXPECT_EQ(c.device.hangups, 0u);
  EXPECT_TRUE(log.contains("no bytes from serial device '/dev/ttyTEST8' for 5.", "no hang-up")) << log.all();
  EXPECT_TRUE(log.contains("serial device '/dev/ttyTEST8' sends again after 7.")) << log.all();
  EXPECT_TRUE(log.contains("final status: device '/dev/ttyTEST8'", "silences 1")) << log.all();
}

TEST(EncoderNode, ReadsARealPseudoTerminalAndReportsItsHangup) {
  // Given the Arduino's lines written in real time (50 Hz) into a pty,
  // (through a symbolic link, so that the device is surely gone afterwards)
  const std::string device = ::testing::TempDir() + "encoder_node_pty_" + std::to_string(::getpid());
  auto pty = std::make_unique<serial::PseudoTerminal>(device);
  EncoderNodeOptions options = node_options();
  options.process.serial_device = device;
  LogLines log;
  OdometryInbox& inbox = odometry_inbox();
  inbox.clear();
  EncoderNode node(options, log.sink());
  ASSERT_TRUE(node.wait_for_subscribers(1, std::chrono::seconds(10)));
  node.start();
  for (int i = 0; i < 200 && node.counters().device.opens == 0; ++i) std::this_thread::sleep_for(milliseconds(5));
  ASSERT_EQ(node.counters().device.opens, 1u) << log.all();

  const auto start = std::chrono::steady_clock::now();
  for (std::uint32_t j = 0; j < 60; ++j) {
    std::this_thread::sleep_until(start + milliseconds(20 * j));
    encoder::EncoderSample s = sample_number(j);
    s.arduino_time_us = 20000 * j;
    pty->write_all(encoder::format_line(s));
  }
  // Then periods 0..10 arrive with the wheel speed (and later ones as "no
  // data"), stamped 0.1 s apart on the host clock near now.
  const std::vector<msg::Odometry> got = inbox.wait_for(11, std::chrono::seconds(10));
  ASSERT_GE(got.size(), 11u) << log.all();
  const double metres_per_tick = 2.0 * M_PI * 0.0325 / 1320.0;
  const double v = 0.5 * (kLeftTicksPerSample + kRightTicksPerSample) * metres_per_tick / 0.02;
  double sum_v = 0.0;
  for (std::size_t k = 1; k < got.size(); ++k) {
    // Periods 2..9 are fully covered by samples (the first ones settle the
    // clock); scheduling delays move single periods' edges a little.
    if (k >= 2 && k <= 9) {
      EXPECT_NEAR(got[k].v_mps(), v, 0.15 * v) << k;
      sum_v += got[k].v_mps();
    }
    const std::uint64_t spacing = got[k].header().stamp_ns() - got[k - 1].header().stamp_ns();
    EXPECT_NEAR(static_cast<double>(spacing), 1e8, 2.0) << k;
  }
  EXPECT_NEAR(sum_v / 8.0, v, 0.03 * v);
  const double age_s = static_cast<double>(dds::now_ns() - got.back().header().stamp_ns()) * 1e-9;
  EXPECT_GT(age_s, 0.0);
  EXPECT_LT(age_s, 5.0);

  // When the pty goes away, the node reports the hang-up naming the device and
  // keeps trying to open it.
  pty.reset();
  for (int i = 0; i < 400 && node.counters().device.open_failures == 0; ++i) {
    std::this_thread::sleep_for(milliseconds(5));
  }
  node.stop();
  EXPECT_EQ(node.counters().device.hangups, 1u) << log.all();
  EXPECT_GE(node.counters().device.open_failures, 1u) << log.all();
  EXPECT_TRUE(log.contains("'" + device + "' hung up")) << log.all();
  EXPECT_TRUE(log.contains("cannot open serial device '" + device + "'")) << log.all();
}

}  // namespace
}  // namespace pixyslam::encoder_node
