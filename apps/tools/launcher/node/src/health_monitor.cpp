#include "pixyslam/launcher/health_monitor.h"

#include <cstdlib>
#include <map>

#include <fastdds/dds/domain/DomainParticipant.hpp>
#include <fastdds/dds/domain/DomainParticipantFactory.hpp>
#include <fastdds/dds/domain/DomainParticipantListener.hpp>

#include "pixyslam/dds/wire_text.h"

namespace pixyslam::launcher {

namespace fdds = eprosima::fastdds::dds;
using eprosima::fastrtps::rtps::ParticipantDiscoveryInfo;

class HealthMonitor::Listener : public fdds::DomainParticipantListener {
 public:
  void on_participant_discovery(fdds::DomainParticipant*, ParticipantDiscoveryInfo&& info) override {
    std::map<std::string, std::string> properties;
    for (const auto& p : info.info.m_properties) properties[p.first()] = p.second();
    std::lock_guard<std::mutex> lock(mutex_);
    std::string& who = names_[info.info.m_guid.guidPrefix];
    const std::string name = dds::printable(info.info.m_participantName.to_string());
    if (properties.count("pixyslam.process") != 0) {
      who = dds::printable(properties["pixyslam.process"]) + "@" + dds::printable(properties["pixyslam.host"]) +
            " pid " + dds::printable(properties["pixyslam.pid"], 12);
    } else if (who.empty() && name == "pixyslam") {
      who = "'pixyslam' (identity not announced: dds.announce_identity)";
    } else if (who.empty()) {
      who = "'" + name + "' (not a pixyslam process)";
    }
    switch (info.status) {
      case ParticipantDiscoveryInfo::DISCOVERED_PARTICIPANT:
        events_.push_back(who + ": joined");
        break;
      case ParticipantDiscoveryInfo::REMOVED_PARTICIPANT:
        events_.push_back(who + ": left");
        names_.erase(info.info.m_guid.guidPrefix);  // participants that come and go are not kept
        break;
      case ParticipantDiscoveryInfo::DROPPED_PARTICIPANT:
        events_.push_back(who + ": LOST (no liveliness within its lease: crashed, hung or unreachable)");
        names_.erase(info.info.m_guid.guidPrefix);
        ++lost_;
        break;
      default:
        break;
    }
  }

  std::vector<std::string> take() {
    std::lock_guard<std::mutex> lock(mutex_);
    std::vector<std::string> out;
    out.swap(events_);
    return out;
  }
  int lost() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return lost_;
  }

 private:
  mutable std::mutex mutex_;
  std::map<eprosima::fastrtps::rtps::GuidPrefix_t, std::string> names_;
  std::vector<std::string> events_;
  int lost_ = 0;
};

HealthMonitor::HealthMonitor(const dds::DdsOptions& options) : listener_(std::make_unique<Listener>()) {
  participant_ = dds::create_participant(options, "pixyslam_launch", listener_.get());
}

HealthMonitor::~HealthMonitor() {
  participant_->set_listener(nullptr);
  fdds::DomainParticipantFactory::get_instance()->delete_participant(participant_);
}

std::vector<std::string> HealthMonitor::take_events() { return listener_->take(); }
int HealthMonitor::lost() const { return listener_->lost(); }

}  // namespace pixyslam::launcher
