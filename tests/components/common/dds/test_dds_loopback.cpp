// Two participants in one process on the shipped loopback profile: every
// message arrives, in order, with the header filled by the writer.
#include <chrono>
#include <condition_variable>
#include <filesystem>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include <map>
#include <utility>
#include <vector>

#include <unistd.h>

#include <optional>

#include <fastdds/dds/domain/DomainParticipant.hpp>
#include <fastdds/dds/domain/DomainParticipantFactory.hpp>
#include <fastdds/dds/domain/DomainParticipantListener.hpp>
#include <atomic>
#include <thread>

#include <gtest/gtest.h>

#include "pixyslam/config/yaml_reader.h"
#include "pixyslam/dds/endpoints.h"
#include "raw_sample_writer.h"

namespace pixyslam::dds {
namespace {

DdsOptions loopback_options() {
  DdsOptions o;
  o.profiles_file = std::string(PIXYSLAM_CONFIG_DIR) + "/dds/profiles.xml";
  o.domain_id = 0;  // ctest runs one DDS test at a time (RESOURCE_LOCK dds)
  o.robot_id = "test_robot";
  return o;
}

// A reader that keeps every message it receives; wait_for(n) waits until it has n.
template <class Message>
struct Collector {
  explicit Collector(Participant& participant)
      : reader(participant, [this](const Message& m) {
          std::lock_guard<std::mutex> lock(mutex);
          got.push_back(m);
          cv.notify_all();
        }) {}
  bool wait_for(std::size_t n) {
    std::unique_lock<std::mutex> lock(mutex);
    return cv.wait_for(lock, std::chrono::seconds(10), [&] { return got.size() >= n; });
  }
  std::mutex mutex;
  std::condition_variable cv;
  std::vector<Message> got;
  Reader<Message> reader;  // last: its callback uses the members above
};

TEST(DdsLoopback, EveryOdometryMessageArrivesInOrder) {
  Participant sender(loopback_options(), "test_sender");
  Participant receiver(loopback_options(), "test_receiver");
  Collector<msg::Odometry> collected(receiver);
  const std::vector<msg::Odometry>& got = collected.got;
  const Reader<msg::Odometry>& reader = collected.reader;
  Writer<msg::Odometry> writer(sender);
  ASSERT_TRUE(writer.wait_for_readers(1, std::chrono::seconds(10)));

  constexpr int kCount = 500;
  for (int i = 0; i < kCount; ++i) {
    msg::Odometry m;
    m.header().stamp_ns(1000u + static_cast<std::uint64_t>(i));
    m.v_mps(0.01 * i);
    ASSERT_TRUE(writer.publish(m));
  }
  ASSERT_TRUE(collected.wait_for(kCount)) << "received " << got.size();
  std::lock_guard<std::mutex> lock(collected.mutex);
  ASSERT_EQ(got.size(), static_cast<std::size_t>(kCount));
  for (int i = 0; i < kCount; ++i) {
    EXPECT_EQ(got[i].header().seq(), static_cast<std::uint64_t>(i + 1));
    EXPECT_EQ(got[i].header().robot_id(), "test_robot");
    EXPECT_DOUBLE_EQ(got[i].v_mps(), 0.01 * i);
  }
  EXPECT_EQ(reader.lost(), 0u);
  EXPECT_EQ(reader.received(), static_cast<std::uint64_t>(kCount));
}

TEST(DdsLoopback, ARobotsReaderGetsOnlyItsRobotsSamples) {
  Participant sender(loopback_options(), "test_fleet_sender");
  Participant receiver(loopback_options(), "test_fleet_receiver");
  std::atomic<int> from_other{0};
  std::vector<std::uint64_t> seqs;
  std::mutex mutex;
  Reader<msg::Odometry> robot2(
      receiver,
      [&](const msg::Odometry& m) {
        std::lock_guard<std::mutex> lock(mutex);
        if (m.header().robot_id() != "robot2") ++from_other;
        seqs.push_back(m.header().seq());
      },
      "robot2");
  Collector<msg::Odometry> everyone(receiver);
  Writer<msg::Odometry> w1(sender, "robot1"), w2(sender, "robot2"), w3(sender, "robot2'; x");
  ASSERT_TRUE(w1.wait_for_readers(2, std::chrono::seconds(10)));
  ASSERT_TRUE(w2.wait_for_readers(2, std::chrono::seconds(10)));
  ASSERT_TRUE(w3.wait_for_readers(2, std::chrono::seconds(10)));
  for (int i = 0; i < 50; ++i) {
    msg::Odometry m;
    ASSERT_TRUE(w1.publish(m));
    ASSERT_TRUE(w2.publish(m));
    ASSERT_TRUE(w3.publish(m));
  }
  ASSERT_TRUE(everyone.wait_for(150));
  ASSERT_TRUE(w2.wait_for_acknowledgments(std::chrono::seconds(5)));
  std::this_thread::sleep_for(std::chrono::milliseconds(200));
  std::lock_guard<std::mutex> lock(mutex);
  EXPECT_EQ(from_other.load(), 0);
  ASSERT_EQ(seqs.size(), 50u);  // robot2's, in order, nothing lost
  for (std::size_t i = 0; i < seqs.size(); ++i) EXPECT_EQ(seqs[i], i + 1);
  EXPECT_EQ(robot2.received(), 50u);
  EXPECT_EQ(robot2.lost(), 0u);
  EXPECT_EQ(robot2.other_robot(), 100u);  // robot1's and the look-alike's, dropped and counted
}

// A valid Odometry as the bytes DataWriter::write puts on the wire.
std::vector<std::uint8_t> odometry_bytes(std::uint64_t seq) {
  msg::Odometry m;
  m.header().seq(seq);
  m.header().robot_id("hostile");
  m.v_mps(0.25);
  return test_support::wire_bytes(m);
}

TEST(DdsLoopback, MalformedSamplesAreCountedAndDroppedAndTheReaderGoesOn) {
  Participant sender(loopback_options(), "test_hostile_sender");
  Participant receiver(loopback_options(), "test_receiver");
  Collector<msg::Odometry> collected(receiver);
  const std::vector<msg::Odometry>& got = collected.got;
  const Reader<msg::Odometry>& reader = collected.reader;
  test_support::RawSampleWriter<msg::Odometry> hostile(sender);
  ASSERT_TRUE(hostile.wait_for_readers(1, std::chrono::seconds(10)));

  const std::vector<std::vector<std::uint8_t>> bad =
      test_support::malformed_payloads(odometry_bytes(1), test_support::max_payload_size<msg::Odometry>());
  for (const auto& bytes : bad) ASSERT_TRUE(hostile.write(bytes));
  ASSERT_TRUE(hostile.write(odometry_bytes(1)));             // a valid one after them
  ASSERT_TRUE(hostile.write(odometry_bytes(1ull << 40)));   // hostile seq: a jump, not lost messages
  ASSERT_TRUE(hostile.write(odometry_bytes((1ull << 40) + 3)));  // then 2 really lost
  ASSERT_TRUE(collected.wait_for(3)) << got.size();
  std::lock_guard<std::mutex> lock(collected.mutex);
  ASSERT_EQ(got.size(), 3u);
  EXPECT_DOUBLE_EQ(got[0].v_mps(), 0.25);
  EXPECT_EQ(got[0].header().robot_id(), "hostile");
  EXPECT_EQ(reader.malformed(), bad.size());
  EXPECT_EQ(reader.seq_jumps(), 1u);
  EXPECT_EQ(reader.lost(), 2u);
  EXPECT_EQ(reader.received(), 3u);
}

TEST(SeqTracker, CountsGapsTheWriterCouldHaveMadeAndJumpsItCouldNot) {
  SeqTracker t;
  EXPECT_EQ(t.update(1, 0.0).lost, 0u);
  EXPECT_EQ(t.update(5, 0.0).lost, 3u);           // 2, 3, 4 lost
  const SeqTracker::Result jump = t.update(5 + 2 * SeqTracker::kSlack, 0.01);
  EXPECT_TRUE(jump.jump);                         // 2000 in 10 ms: more than 10 kHz + slack
  EXPECT_EQ(jump.lost, 0u);
  const std::uint64_t base = 5 + 2 * SeqTracker::kSlack;
  const SeqTracker::Result outage = t.update(base + 20001, 2.0);  // 20,000 in 2 s: plausible
  EXPECT_FALSE(outage.jump);
  EXPECT_EQ(outage.lost, 20000u);
  const SeqTracker::Result back = t.update(3, 0.1);  // one writer going back: hostile, or broken
  EXPECT_TRUE(back.jump);
  EXPECT_EQ(back.lost, 0u);
  EXPECT_EQ(t.update(4, 0.1).lost, 0u);           // and on from there
  EXPECT_FALSE(t.update(5, 0.1).jump);
  EXPECT_TRUE(t.update(~0ull, 0.1).jump);         // the top of the range
  EXPECT_EQ(t.update(~0ull, 0.1).lost, 0u);       // a repeat
}

TEST(DdsLoopback, LateJoinerGetsTheRecentMapStatesEndingWithTheCurrent) {
  Participant sender(loopback_options(), "test_map_sender");
  Writer<msg::MapState> writer(sender);
  for (int i = 0; i < 3; ++i) {
    msg::MapState m;
    m.particle_count(100u + static_cast<std::uint32_t>(i));
    writer.publish(m);
  }
  Participant receiver(loopback_options(), "test_map_receiver");
  std::mutex mutex;
  std::condition_variable cv;
  std::vector<std::uint32_t> counts;
  Reader<msg::MapState> reader(receiver, [&](const msg::MapState& m) {
    std::lock_guard<std::mutex> lock(mutex);
    counts.push_back(m.particle_count());
    cv.notify_all();
  });
  std::unique_lock<std::mutex> lock(mutex);
  ASSERT_TRUE(cv.wait_for(lock, std::chrono::seconds(10), [&] { return !counts.empty() && counts.back() == 102u; }));
  // Transient local, keep-last 256: the writer's recent states, in order, the current one last.
  EXPECT_EQ(counts, (std::vector<std::uint32_t>{100u, 101u, 102u}));
}

TEST(DdsLoopback, MissingProfilesFileIsNamed) {
  DdsOptions o = loopback_options();
  o.profiles_file = "/nonexistent/profiles.xml";
  try {
    Participant p(o, "test");
    FAIL() << "expected an error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/profiles.xml"), std::string::npos) << e.what();
  }
}

// A participant profile the profiles file lacks is a setting's error (exit 2
// in every program), named with where it can be set; nothing joins the network.
TEST(DdsLoopback, UnknownParticipantProfileIsAConfigErrorNamingTheKey) {
  DdsOptions o = loopback_options();
  o.participant_profile = "no_such_profile";
  try {
    Participant p(o, "test");
    FAIL() << "expected an error";
  } catch (const config::ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("dds.participant_profile"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("'no_such_profile'"), std::string::npos) << e.what();
  }
}

TEST(DdsOptions, ReadsKeysAndResolvesTheProfilesPath) {
  auto reader = config::YamlReader::from_string(
      "dds:\n  domain_id: 7\n  profiles_file: dds/profiles.xml\n  robot_id: r2\n", "test.yaml");
  auto dds = reader.child("dds");
  const DdsOptions o = read_dds_options(dds, "/etc/pixyslam");
  EXPECT_EQ(o.domain_id, 7);
  EXPECT_EQ(o.profiles_file, "/etc/pixyslam/dds/profiles.xml");
  EXPECT_EQ(o.robot_id, "r2");
}

// A user's own YAML without the key (or without `dds:`) gets the profiles
// every shipped config names, not a participant that fails for want of one.
TEST(DdsOptions, WithoutAProfilesFileTheDefaultOneIsUsed) {
  auto reader = config::YamlReader::from_string("dds:\n  domain_id: 7\n", "test.yaml");
  auto dds = reader.child("dds");
  EXPECT_EQ(read_dds_options(dds, "/etc/pixyslam").profiles_file, default_profiles_file());
  auto root = config::YamlReader::from_string("other: 1\n", "test.yaml");
  EXPECT_EQ(read_dds_section(root, "/etc/pixyslam").profiles_file, default_profiles_file());
  EXPECT_TRUE(std::filesystem::exists(default_profiles_file()));
}

TEST(DdsOptions, OutOfRangeDomainNamesTheKey) {
  auto reader = config::YamlReader::from_string("dds:\n  domain_id: 300\n", "test.yaml");
  auto dds = reader.child("dds");
  try {
    read_dds_options(dds, "");
    FAIL() << "expected an error";
  } catch (const config::ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("dds.domain_id"), std::string::npos) << e.what();
  }
}

// Deployment settings: YAML keys, environment overrides, and their errors.
TEST(DdsOptions, ReadsDeploymentKeys) {
  auto reader = config::YamlReader::from_string(
      "dds:\n  participant_profile: lan_peers\n  interfaces: [10.200.0.1]\n"
      "  initial_peers: [10.200.0.1, 10.200.0.2]\n  discovery_server: 10.200.0.3:11811\n"
      "  discovery_server_id: 2\n  security_dir: sec\n",
      "test.yaml");
  auto dds = reader.child("dds");
  const DdsOptions o = read_dds_options(dds, "/etc/pixyslam");
  EXPECT_EQ(o.participant_profile, "lan_peers");
  EXPECT_EQ(o.interfaces, std::vector<std::string>{"10.200.0.1"});
  EXPECT_EQ(o.initial_peers.size(), 2u);
  EXPECT_EQ(o.discovery_server, "10.200.0.3:11811");
  EXPECT_EQ(o.discovery_server_id, 2);
  EXPECT_EQ(o.security_dir, "/etc/pixyslam/sec");
}

TEST(DdsOptions, AnnounceIdentityIsOnUnlessSecureOrSet) {
  for (const auto& [text, expected] : std::vector<std::pair<std::string, std::optional<bool>>>{
           {"true", true}, {"false", false}, {"auto", std::nullopt}}) {
    auto reader = config::YamlReader::from_string("dds:\n  announce_identity: " + text + "\n", "test.yaml");
    auto dds = reader.child("dds");
    const DdsOptions o = read_dds_options(dds, "/etc/pixyslam");
    EXPECT_EQ(o.announce_identity, expected) << text;
  }
  DdsOptions o;
  EXPECT_TRUE(announces_identity(o, false));
  EXPECT_FALSE(announces_identity(o, true));
  o.announce_identity = true;
  EXPECT_TRUE(announces_identity(o, true));
  o.announce_identity = false;
  EXPECT_FALSE(announces_identity(o, false));
  auto bad = config::YamlReader::from_string("dds:\n  announce_identity: sometimes\n", "test.yaml");
  auto dds = bad.child("dds");
  try {
    read_dds_options(dds, "/etc/pixyslam");
    FAIL() << "expected an error";
  } catch (const config::ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("dds.announce_identity"), std::string::npos) << e.what();
  }
}

// What a participant tells everyone on the domain before any security: with
// announce_identity false, neither its role nor the host, pid and process.
class DiscoveryRecorder : public eprosima::fastdds::dds::DomainParticipantListener {
 public:
  void on_participant_discovery(eprosima::fastdds::dds::DomainParticipant*,
                                eprosima::fastrtps::rtps::ParticipantDiscoveryInfo&& info) override {
    std::lock_guard<std::mutex> lock(mutex);
    std::map<std::string, std::string>& p = seen[info.info.m_participantName.to_string()];
    for (const auto& property : info.info.m_properties) p[property.first()] = property.second();
  }
  std::mutex mutex;
  std::map<std::string, std::map<std::string, std::string>> seen;
};

TEST(DdsLoopback, ParticipantsWithoutIdentityAnnounceNoNameHostOrPid) {
  DiscoveryRecorder recorder;
  auto* observer = create_participant(loopback_options(), "test_observer", &recorder);
  ASSERT_NE(observer, nullptr);
  {
    Participant announced(loopback_options(), "test_announced");
    DdsOptions quiet = loopback_options();
    quiet.announce_identity = false;
    Participant hidden(quiet, "test_hidden");
    const auto end = std::chrono::steady_clock::now() + std::chrono::seconds(10);
    for (;;) {
      {
        std::lock_guard<std::mutex> lock(recorder.mutex);
        if (recorder.seen.count("test_announced") && recorder.seen.count("pixyslam")) break;
      }
      ASSERT_LT(std::chrono::steady_clock::now(), end) << "both participants not discovered";
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
  }
  eprosima::fastdds::dds::DomainParticipantFactory::get_instance()->delete_participant(observer);
  std::lock_guard<std::mutex> lock(recorder.mutex);
  EXPECT_EQ(recorder.seen.count("test_hidden"), 0u);
  EXPECT_EQ(recorder.seen["test_announced"].count("pixyslam.pid"), 1u);
  EXPECT_EQ(recorder.seen["test_announced"]["pixyslam.pid"], std::to_string(getpid()));
  for (const char* key : {"pixyslam.host", "pixyslam.pid", "pixyslam.process"}) {
    EXPECT_EQ(recorder.seen["pixyslam"].count(key), 0u) << key;
  }
}

TEST(DdsOptions, BadAddressesNameTheKey) {
  for (const char* text : {"dds:\n  interfaces: [10.200.0]\n", "dds:\n  initial_peers: [robot.local]\n",
                           "dds:\n  discovery_server: 10.200.0.3\n", "dds:\n  discovery_server: 10.0.0.1:70000\n"}) {
    auto reader = config::YamlReader::from_string(text, "test.yaml");
    auto dds = reader.child("dds");
    try {
      read_dds_options(dds, "");
      ADD_FAILURE() << "expected an error for " << text;
    } catch (const config::ConfigError& e) {
      EXPECT_NE(std::string(e.what()).find("test.yaml"), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find("dds."), std::string::npos) << e.what();
    }
  }
}

TEST(DdsOptions, EnvironmentOverridesEachSetting) {
  const std::map<std::string, std::string> env{{"PIXYSLAM_DDS_DOMAIN", "42"},
                                               {"PIXYSLAM_DDS_PROFILE", "secure"},
                                               {"PIXYSLAM_DDS_INTERFACES", "10.1.0.1"},
                                               {"PIXYSLAM_DDS_PEERS", "10.1.0.1, 10.1.0.2"},
                                               {"PIXYSLAM_DDS_SERVER", "10.1.0.3:11811"},
                                               {"PIXYSLAM_DDS_SERVER_ID", "1"},
                                               {"PIXYSLAM_DDS_SECURITY_DIR", "/sec"},
                                               {"PIXYSLAM_DDS_TYPE_INFORMATION", "false"},
                                               {"PIXYSLAM_DDS_LOG", "warning"}};
  auto lookup = [&](const char* name) -> const char* {
    const auto it = env.find(name);
    return it == env.end() ? nullptr : it->second.c_str();
  };
  DdsOptions o;
  apply_environment(o, lookup);
  EXPECT_EQ(o.domain_id, 42);
  EXPECT_EQ(o.participant_profile, "secure");
  EXPECT_EQ(o.interfaces, std::vector<std::string>{"10.1.0.1"});
  EXPECT_EQ(o.initial_peers, (std::vector<std::string>{"10.1.0.1", "10.1.0.2"}));
  EXPECT_EQ(o.discovery_server, "10.1.0.3:11811");
  EXPECT_EQ(o.discovery_server_id, 1);
  EXPECT_EQ(o.log_level, DdsLogLevel::kWarning);
  EXPECT_EQ(o.security_dir, "/sec");
  EXPECT_FALSE(o.type_information);
  // Nothing set: nothing changes.
  DdsOptions unchanged;
  apply_environment(unchanged, [](const char*) -> const char* { return nullptr; });
  EXPECT_EQ(to_yaml(unchanged), to_yaml(DdsOptions{}));
}

TEST(DdsOptions, BadEnvironmentNamesTheVariable) {
  for (const auto& [name, value] : std::vector<std::pair<std::string, std::string>>{
           {"PIXYSLAM_DDS_DOMAIN", "300"},
           {"PIXYSLAM_DDS_PEERS", "10.0.0.1,nope"},
           {"PIXYSLAM_DDS_SERVER", "10.0.0.1"},
           {"PIXYSLAM_DDS_TYPE_INFORMATION", "maybe"},
           {"PIXYSLAM_DDS_LOG", "verbose"}}) {
    DdsOptions o;
    try {
      apply_environment(o, [&](const char* n) { return n == name ? value.c_str() : nullptr; });
      ADD_FAILURE() << "expected an error for " << name;
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find(name), std::string::npos) << e.what();
    }
  }
}

// The settings resolved once, in the process's main: file, then environment,
// then command line; a Participant takes them as given.
TEST(DdsOptions, ResolvedFromFileThenEnvironmentThenCommandLine) {
  auto reader = config::YamlReader::from_string("dds:\n  domain_id: 7\n  participant_profile: lan_peers\n", "t.yaml");
  auto dds = reader.child("dds");
  DdsOptions o = read_dds_options(dds, "");
  ASSERT_EQ(setenv("PIXYSLAM_DDS_DOMAIN", "9", 1), 0);
  ASSERT_EQ(setenv("PIXYSLAM_DDS_PEERS", "10.1.0.1,10.1.0.2", 1), 0);
  DdsOptions from_environment = o;
  resolve_settings(from_environment);
  EXPECT_EQ(from_environment.domain_id, 9);
  EXPECT_EQ(from_environment.participant_profile, "lan_peers");  // not in the environment: the file's
  EXPECT_EQ(from_environment.initial_peers, (std::vector<std::string>{"10.1.0.1", "10.1.0.2"}));
  DdsOptions from_command_line = o;
  resolve_settings(from_command_line, {domain_override("11"), "dds.robot_id=r7"});
  EXPECT_EQ(from_command_line.domain_id, 11);
  EXPECT_EQ(from_command_line.robot_id, "r7");
  // A bad value names where it came from.
  for (const auto& overrides : std::vector<std::vector<std::string>>{{domain_override("233")},
                                                                      {"dds.interfaces=10.0.0"},
                                                                      {"dds.no_such_key=1"}}) {
    DdsOptions bad = o;
    try {
      resolve_settings(bad, overrides);
      ADD_FAILURE() << "expected an error for " << overrides.front();
    } catch (const config::ConfigError& e) {
      EXPECT_NE(std::string(e.what()).find("command line"), std::string::npos) << e.what();
    }
  }
  ASSERT_EQ(setenv("PIXYSLAM_DDS_DOMAIN", "300", 1), 0);
  try {
    resolve_settings(o);
    ADD_FAILURE() << "expected an error";
  } catch (const config::ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("PIXYSLAM_DDS_DOMAIN"), std::string::npos) << e.what();
  }
  // Participant reads no environment: the domain it was given.
  DdsOptions given = loopback_options();
  given.domain_id = 3;
  {
    Participant participant(given, "test_no_environment");
    EXPECT_EQ(participant.native().get_domain_id(), 3u);
  }
  unsetenv("PIXYSLAM_DDS_DOMAIN");
  unsetenv("PIXYSLAM_DDS_PEERS");
}

// The printed effective configuration reads back as the same settings.
TEST(DdsOptions, EffectiveConfigurationReadsBack) {
  DdsOptions o;
  o.domain_id = 12;
  o.profiles_file = "/etc/it's/profiles.xml";
  o.interfaces = {"10.0.0.1", "10.0.0.2"};
  o.discovery_server = "10.0.0.3:11811";
  o.announce_identity = false;
  o.diagnostics_period_s = 0.25;
  auto reader = config::YamlReader::from_string(to_yaml(o), "printed.yaml");
  auto dds = reader.child("dds");
  const DdsOptions back = read_dds_options(dds, "");
  EXPECT_EQ(to_yaml(back), to_yaml(o));
  EXPECT_EQ(back.profiles_file, o.profiles_file);
  EXPECT_EQ(back.interfaces, o.interfaces);
  EXPECT_EQ(back.announce_identity, o.announce_identity);
}

TEST(DdsLoopback, SecureProfileWithoutSecurityFilesIsRefused) {
  DdsOptions o = loopback_options();
  o.participant_profile = "secure";
  try {
    Participant p(o, "test");
    FAIL() << "expected an error";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("security_dir"), std::string::npos) << e.what();
  }
  o.security_dir = "/nonexistent_pixyslam_security";
  try {
    Participant p(o, "test");
    FAIL() << "expected an error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent_pixyslam_security/ca.cert.pem"), std::string::npos)
        << e.what();
  }
}

}  // namespace
}  // namespace pixyslam::dds
