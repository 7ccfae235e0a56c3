#pragma once

#include <chrono>
#include <cstddef>
#include <string>
#include <vector>

#include "pixyslam/mrclam/mrclam_dataset.h"
#include "pixyslam/offline/offline_run.h"

// A recording of several robots as one time-ordered stream of samples, paced
// against the wall clock: what dataset_bridge publishes. Pure: no DDS, no clock
// (the pacer takes the time it is given).
namespace pixyslam::dataset_bridge {

// One robot of the recording: its samples as the filter gets them (the data
// set's sensor corrections applied: offline::mrclam_input), and the other
// robots it saw (the same corrections; landmark_id = the robot seen).
struct RobotStream {
  int robot = 0;                 // the data set's subject number
  std::string robot_id;          // "robot<N>", the header's robot_id
  offline::RunInput input;       // odometry, frames, truth, landmarks, start pose and time
  std::vector<slam::ObservationFrame> sightings;
};

RobotStream make_robot_stream(const mrclam::RobotData& data, const offline::MrclamSensorModel& model);

// The first `duration_s` seconds of the stream from its start (sightings too;
// offline::keep_first_seconds); <= 0 keeps everything.
void keep_first_seconds(RobotStream& stream, double duration_s);

enum class EventKind { kGroundTruth, kOdometry, kFrame, kSighting };

// One sample to publish: robots[robot].input.<kind>[index] (sightings: .sightings).
struct Event {
  double t_s = 0.0;
  std::size_t robot = 0;
  EventKind kind = EventKind::kOdometry;
  std::size_t index = 0;
};

// Every robot's samples from its start_time_s on, in time order; on equal
// times ground truth, then odometry, frames, sightings, then by robot. The
// last odometry before a robot's start is kept as its first (the control it
// holds at the start; the publisher stamps it at the start time), as the
// offline runner holds it.
std::vector<Event> merge_timeline(const std::vector<RobotStream>& robots);

// The odometry period the publisher gives sample `index` of `robot`: until the
// next one, or `last_period_s` for the last.
double odometry_period(const RobotStream& robot, std::size_t index, double last_period_s = 0.1);

// Wall-clock pacing at `rate` times the recording's speed (rate <= 0: none).
class Pacer {
 public:
  using Clock = std::chrono::steady_clock;
  Pacer(double rate, double first_t_s, Clock::time_point start) : rate_(rate), first_t_s_(first_t_s), start_(start) {}
  // When the sample of recording time t_s is due.
  Clock::time_point due(double t_s) const;
  bool paced() const { return rate_ > 0.0; }

 private:
  double rate_;
  double first_t_s_;
  Clock::time_point start_;
};

}  // namespace pixyslam::dataset_bridge
