#pragma once

#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "pixyslam/dds/participant.h"

namespace eprosima::fastdds::dds {
class DomainParticipant;
}  // namespace eprosima::fastdds::dds

namespace pixyslam::launcher {

// Watches the DDS domain for pixyslam processes coming and going, by DDS
// participant liveliness: every process announces itself (host, pid, process
// name) and its liveliness every second; a process that exits cleanly says
// so ("left"), one that crashes, hangs or loses its link stops announcing and
// is reported LOST when its lease (config/dds/profiles.xml) expires. Events
// are collected on DDS threads and taken by the launcher's main loop.
class HealthMonitor {
 public:
  explicit HealthMonitor(const dds::DdsOptions& options);
  ~HealthMonitor();
  HealthMonitor(const HealthMonitor&) = delete;
  HealthMonitor& operator=(const HealthMonitor&) = delete;

  // Lines like "slam_estimator@laptop pid 4242: joined" since the last call.
  std::vector<std::string> take_events();
  // How many processes were LOST (lease expired) so far.
  int lost() const;

  class Listener;

 private:
  std::unique_ptr<Listener> listener_;
  eprosima::fastdds::dds::DomainParticipant* participant_ = nullptr;
};

}  // namespace pixyslam::launcher
