#pragma once
// The sensors' side of a node test: one participant with an odometry and a
// camera writer on the node's domain.
#include <chrono>

#include "landmark_observation.h"
#include "odometry.h"
#include "pixyslam/dds/endpoints.h"
#include "pixyslam/dds/participant.h"

namespace pixyslam::test_support {

struct SensorWriters {
  explicit SensorWriters(const dds::DdsOptions& options)
      : participant(options, "test_sensors"), odometry(participant), observations(participant) {}
  // Both writers matched with a reader each (within 10 s each).
  bool matched() {
    return odometry.wait_for_readers(1, std::chrono::seconds(10)) &&
           observations.wait_for_readers(1, std::chrono::seconds(10));
  }
  dds::Participant participant;
  dds::Writer<msg::Odometry> odometry;
  dds::Writer<msg::LandmarkObservation> observations;
};

}  // namespace pixyslam::test_support
