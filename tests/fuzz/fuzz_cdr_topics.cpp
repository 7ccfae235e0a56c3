// libFuzzer target: arbitrary bytes as a received DDS sample of each topic.
// The first byte picks the topic (PIXYSLAM_FUZZ_TOPIC pins one: 0 odometry, 1
// landmark_observation, 2 map_state, 3 ground_truth, 4 diagnostics, 5 optimised_map); the rest is the
// payload (encapsulation header and CDR). It goes through the readers' own
// GuardedPubSubType::deserialize exactly as Fast DDS hands it over (no
// pre-check of the encapsulation), which must never throw; then through the
// log tools' strict decoder. A sample that decodes goes on as the estimator would take it: Odometry and
// LandmarkObservation through the node's conversions into a FastSLAM 2.0
// filter, whose estimate must stay finite whatever the values (NaN, inf,
// negative ranges, time going backwards or jumping).

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include <cstdlib>
#include <cstring>

#include <fastdds/rtps/common/SerializedPayload.h>

#include "fuzz_common.h"
#include "pixyslam/dds/guarded_type.h"
#include "pixyslam/dds/cdr_payload.h"
#include "pixyslam/slam/fastslam2.h"
#include "pixyslam/slam_node/map_state_conversions.h"

namespace {

using pixyslam::dds::from_cdr;

void check_filter(const pixyslam::slam::FastSlam2& filter) {
  const pixyslam::slam::PoseEstimate e = filter.pose_estimate();
  FUZZ_CHECK(e.mean.allFinite());
  FUZZ_CHECK(e.cov.allFinite());
  for (const pixyslam::slam::LandmarkEstimate& lm : filter.landmarks_of_best()) {
    FUZZ_CHECK(lm.mean.allFinite());
    FUZZ_CHECK(lm.cov.allFinite());
  }
}

pixyslam::slam::FilterOptions small_filter(bool delayed) {
  pixyslam::slam::FilterOptions o;
  o.particles = 8;
  o.delayed_sampling.enabled = delayed;
  return o;
}

// What a DataReader does with the bytes: the guarded deserialize. It may
// refuse them, never throw (an exception would abort the fuzzer).
template <class Message>
void reader_decode(const std::vector<std::uint8_t>& bytes) {
  pixyslam::dds::GuardedPubSubType<Message> type;
  eprosima::fastrtps::rtps::SerializedPayload_t payload(static_cast<std::uint32_t>(bytes.size()));
  if (!bytes.empty()) std::memcpy(payload.data, bytes.data(), bytes.size());
  payload.length = static_cast<std::uint32_t>(bytes.size());
  Message message;
  const bool ok = type.deserialize(&payload, &message);
  FUZZ_CHECK(type.malformed() == (ok ? 0u : 1u));
}

int pinned_topic() {
  static const int topic = [] {
    const char* v = std::getenv("PIXYSLAM_FUZZ_TOPIC");
    return v != nullptr ? std::atoi(v) : -1;
  }();
  return topic;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  const std::vector<std::uint8_t> payload(data + 1, data + size);
  std::string error;
  // One filter gets the sample twice (a repeat is a time that does not advance),
  // with delayed sampling on or off.
  pixyslam::slam::FastSlam2 filter(small_filter((data[0] & 0x10) != 0), pixyslam::slam::Pose2::Zero());
  const std::uint64_t epoch_ns = 1'000'000'000ull;
  const int topic = pinned_topic() >= 0 ? pinned_topic() : (data[0] & 0x07);
  switch (topic) {
    case 0: reader_decode<pixyslam::msg::Odometry>(payload); break;
    case 1: reader_decode<pixyslam::msg::LandmarkObservation>(payload); break;
    case 2: reader_decode<pixyslam::msg::MapState>(payload); break;
    case 4: reader_decode<pixyslam::msg::Diagnostics>(payload); break;
    case 5: reader_decode<pixyslam::msg::OptimisedMap>(payload); break;
    default: reader_decode<pixyslam::msg::GroundTruth>(payload); break;
  }
  switch (topic) {
    case 0: {
      pixyslam::msg::Odometry m;
      if (!from_cdr(payload, m, error)) return 0;
      const pixyslam::slam::OdometryInput in = pixyslam::slam_node::to_odometry_input(m, epoch_ns);
      filter.add_odometry(in.sample);
      filter.add_odometry(in.sample);
      check_filter(filter);
      break;
    }
    case 1: {
      pixyslam::msg::LandmarkObservation m;
      if (!from_cdr(payload, m, error)) return 0;
      for (bool sigmas : {false, true}) {
        const pixyslam::slam::ObservationInput in = pixyslam::slam_node::to_observation_input(m, epoch_ns, sigmas);
        filter.add_observations(in.frame);
        check_filter(filter);
      }
      break;
    }
    case 2: {
      pixyslam::msg::MapState m;
      (void)from_cdr(payload, m, error);
      break;
    }
    case 4: {
      pixyslam::msg::Diagnostics m;
      (void)from_cdr(payload, m, error);
      break;
    }
    case 5: {
      pixyslam::msg::OptimisedMap m;
      (void)from_cdr(payload, m, error);
      break;
    }
    default: {
      pixyslam::msg::GroundTruth m;
      (void)from_cdr(payload, m, error);
      break;
    }
  }
  pixyslam::dds::SampleHeader header;
  for (const auto& topic : pixyslam::dds::known_topics()) {
    (void)pixyslam::dds::decode_header(topic.type_name, payload.data(), payload.size(), header, error);
  }
  return 0;
}
