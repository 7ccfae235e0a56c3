#pragma once

// What the DDS node tests share: the loopback options of a test process, an
// inbox for the messages a node publishes, and a log sink to assert on.

#include <unistd.h>

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "pixyslam/bridge/device_reader.h"
#include "pixyslam/dds/endpoints.h"
#include "pixyslam/dds/participant.h"

namespace pixyslam::test_support {

// The shipped loopback profile on a domain (one of [first_domain,
// first_domain + domains)) and with a robot id of this process: test cases
// that ctest runs at the same time (each in a process of its own) neither
// share ports nor see each other's messages.
inline dds::DdsOptions loopback_options(int first_domain, int domains, const std::string& robot_id_prefix) {
  dds::DdsOptions o;
  o.profiles_file = std::string(PIXYSLAM_CONFIG_DIR) + "/dds/profiles.xml";
  o.domain_id = first_domain + static_cast<int>(::getpid() % domains);
  o.robot_id = robot_id_prefix + std::to_string(::getpid());
  return o;
}

// Collects the messages of type Message that the test's own participant
// receives from the robot id of its options. One per type for the whole
// program, created before any node: the loopback profile's initial peers reach
// participants 0-3 of a domain on this host (Fast DDS's default range), ids are
// never reused within a process, and two participants can find each other when
// one of them is in that range. InboxCleanup deletes it before main returns.
template <class Message>
class Inbox {
 public:
  // The inbox; the first call creates it with these arguments.
  static Inbox& instance(const dds::DdsOptions& options, const std::string& participant_name) {
    if (slot() == nullptr) slot() = new Inbox(options, participant_name);
    return *slot();
  }
  static void destroy() {
    delete slot();
    slot() = nullptr;
  }

  // Forgets what arrived so far (messages of earlier tests).
  void clear() {
    std::lock_guard<std::mutex> lock(mutex_);
    got_.clear();
  }
  // Waits until at least `count` messages arrived; returns all received so far.
  std::vector<Message> wait_for(std::size_t count, std::chrono::milliseconds timeout) {
    std::unique_lock<std::mutex> lock(mutex_);
    cv_.wait_for(lock, timeout, [&] { return got_.size() >= count; });
    return got_;
  }
  std::uint64_t lost() const { return reader_.lost(); }

 private:
  static Inbox*& slot() {
    static Inbox* inbox = nullptr;
    return inbox;
  }
  Inbox(const dds::DdsOptions& options, const std::string& participant_name)
      : robot_id_(options.robot_id),
        participant_(options, participant_name),
        reader_(participant_, [this](const Message& m) {
          if (m.header().robot_id() != robot_id_) return;
          std::lock_guard<std::mutex> lock(mutex_);
          got_.push_back(m);
          cv_.notify_all();
        }) {}

  const std::string robot_id_;
  dds::Participant participant_;
  std::mutex mutex_;
  std::condition_variable cv_;
  std::vector<Message> got_;
  dds::Reader<Message> reader_;
};

// Destroys the Inbox<Message> before main returns (DDS entities must not
// outlive main). Register one per inbox type:
//   ::testing::AddGlobalTestEnvironment(new InboxCleanup<msg::Odometry>);
template <class Message>
class InboxCleanup : public ::testing::Environment {
 public:
  void TearDown() override { Inbox<Message>::destroy(); }
};

// Log lines of a node, for assertions. Copies share the lines.
struct LogLines {
  std::shared_ptr<std::mutex> mutex = std::make_shared<std::mutex>();
  std::shared_ptr<std::vector<std::string>> lines = std::make_shared<std::vector<std::string>>();

  bridge::LogFunction sink() const {
    return [m = mutex, l = lines](const std::string& line) {
      std::lock_guard<std::mutex> lock(*m);
      l->push_back(line);
    };
  }
  // A line holds both `a` and `b`.
  bool contains(const std::string& a, const std::string& b = "") const {
    std::lock_guard<std::mutex> lock(*mutex);
    for (const std::string& line : *lines) {
      if (line.find(a) != std::string::npos && line.find(b) != std::string::npos) return true;
    }
    return false;
  }
  bool empty() const {
    std::lock_guard<std::mutex> lock(*mutex);
    return lines->empty();
  }
  std::string all() const {
    std::lock_guard<std::mutex> lock(*mutex);
    std::string s;
    for (const std::string& line : *lines) s += line + "\n";
    return s;
  }
};

}  // namespace pixyslam::test_support
