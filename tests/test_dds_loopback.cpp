// Two participants in one process on the shipped loopback profile: every
// message arrives, in order, with the header filled by the writer.
#include <chrono>
#include <condition_variable>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

#include "pixyslam/dds/endpoints.h"

namespace pixyslam::dds {
namespace {

DdsOptions loopback_options() {
  DdsOptions o;
  o.profiles_file = std::string(PIXYSLAM_CONFIG_DIR) + "/dds/profiles.xml";
  o.domain_id = 0;  // ctest runs one DDS test at a time (RESOURCE_LOCK dds)
  o.robot_id = "test_robot";
  return o;
}

TEST(DdsLoopback, EveryOdometryMessageArrivesInOrder) {
  Participant sender(loopback_options(), "test_sender");
  Participant receiver(loopback_options(), "test_receiver");
  std::mutex mutex;
  std::condition_variable cv;
  std::vector<msg::Odometry> got;
  Reader<msg::Odometry> reader(receiver, [&](const msg::Odometry& m) {
    std::lock_guard<std::mutex> lock(mutex);
    got.push_back(m);
    cv.notify_all();
  });
  Writer<msg::Odometry> writer(sender);
  ASSERT_TRUE(writer.wait_for_readers(1, std::chrono::seconds(10)));

  constexpr int kCount = 500;
  for (int i = 0; i < kCount; ++i) {
    msg::Odometry m;
    m.header().stamp_ns(1000u + static_cast<std::uint64_t>(i));
    m.v_mps(0.01 * i);
    ASSERT_TRUE(writer.publish(m));
  }
  std::unique_lock<std::mutex> lock(mutex);
  ASSERT_TRUE(cv.wait_for(lock, std::chrono::seconds(10), [&] { return got.size() == kCount; }))
      << "received " << got.size();
  for (int i = 0; i < kCount; ++i) {
    EXPECT_EQ(got[i].header().seq(), static_cast<std::uint64_t>(i + 1));
    EXPECT_EQ(got[i].header().robot_id(), "test_robot");
    EXPECT_DOUBLE_EQ(got[i].v_mps(), 0.01 * i);
  }
  EXPECT_EQ(reader.lost(), 0u);
  EXPECT_EQ(reader.received(), static_cast<std::uint64_t>(kCount));
}

TEST(DdsLoopback, LateJoinerGetsTheLastMapState) {
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
  ASSERT_TRUE(cv.wait_for(lock, std::chrono::seconds(10), [&] { return !counts.empty(); }));
  EXPECT_EQ(counts.front(), 102u);  // keep-last 1: only the current map
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

TEST(DdsLoopback, UnknownParticipantProfileIsNamed) {
  DdsOptions o = loopback_options();
  o.participant_profile = "no_such_profile";
  try {
    Participant p(o, "test");
    FAIL() << "expected an error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("no_such_profile"), std::string::npos) << e.what();
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

}  // namespace
}  // namespace pixyslam::dds
