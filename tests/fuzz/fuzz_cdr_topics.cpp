// libFuzzer target: arbitrary bytes as a received DDS sample of each topic.
// The first byte picks the topic; the rest is the payload (encapsulation header
// and CDR), decoded with the generated type exactly as a DataReader would. A
// sample that decodes goes on as the estimator would take it: Odometry and
// LandmarkObservation through the node's conversions into a FastSLAM 2.0
// filter, whose estimate must stay finite whatever the values (NaN, inf,
// negative ranges, time going backwards or jumping).

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "fuzz_common.h"
#include "pixyslam/logger_node/cdr_payload.h"
#include "pixyslam/slam/fastslam2.h"
#include "pixyslam/slam_node/map_state_conversions.h"

namespace {

using pixyslam::logger_node::from_cdr;

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

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  const std::vector<std::uint8_t> payload(data + 1, data + size);
  std::string error;
  // One filter gets the sample twice (a repeat is a time that does not advance),
  // with delayed sampling on or off.
  pixyslam::slam::FastSlam2 filter(small_filter((data[0] & 0x10) != 0), pixyslam::slam::Pose2::Zero());
  const std::uint64_t epoch_ns = 1'000'000'000ull;
  switch (data[0] & 0x07) {
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
    default: {
      pixyslam::msg::GroundTruth m;
      (void)from_cdr(payload, m, error);
      break;
    }
  }
  pixyslam::logger_node::SampleHeader header;
  for (const auto& topic : pixyslam::logger_node::known_topics()) {
    (void)pixyslam::logger_node::decode_header(topic.type_name, payload.data(), payload.size(), header, error);
  }
  return 0;
}
