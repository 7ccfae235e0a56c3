#include "pixyslam/dataset_bridge/timeline.h"

#include <algorithm>
#include <tuple>

namespace pixyslam::dataset_bridge {

RobotStream make_robot_stream(const mrclam::RobotData& data, const offline::MrclamSensorModel& model) {
  RobotStream s;
  s.robot = data.robot;
  s.robot_id = mrclam::robot_id(data.robot);
  s.input = offline::mrclam_input(data, model);
  for (const mrclam::MeasurementFrame& f : data.robot_sightings) s.sightings.push_back(offline::mrclam_frame(f, model));
  return s;
}

void keep_first_seconds(RobotStream& stream, double duration_s) {
  if (duration_s <= 0.0) return;
  offline::keep_first_seconds(stream.input, duration_s);
  offline::erase_after(stream.sightings, stream.input.start_time_s + duration_s);
}

std::vector<Event> merge_timeline(const std::vector<RobotStream>& robots) {
  std::vector<Event> events;
  for (std::size_t r = 0; r < robots.size(); ++r) {
    const offline::RunInput& in = robots[r].input;
    const double start = in.start_time_s;
    for (std::size_t i = 0; i < in.truth.size(); ++i) {
      if (in.truth[i].t_s >= start) events.push_back({in.truth[i].t_s, r, EventKind::kGroundTruth, i});
    }
    // The held control: the last odometry before the start, published at the start.
    std::size_t first = 0;
    while (first + 1 < in.odometry.size() && in.odometry[first + 1].t_s <= start) ++first;
    for (std::size_t i = first; i < in.odometry.size(); ++i) {
      events.push_back({std::max(in.odometry[i].t_s, start), r, EventKind::kOdometry, i});
    }
    for (std::size_t i = 0; i < in.frames.size(); ++i) {
      if (in.frames[i].t_s >= start) events.push_back({in.frames[i].t_s, r, EventKind::kFrame, i});
    }
    for (std::size_t i = 0; i < robots[r].sightings.size(); ++i) {
      if (robots[r].sightings[i].t_s >= start) events.push_back({robots[r].sightings[i].t_s, r, EventKind::kSighting, i});
    }
  }
  std::stable_sort(events.begin(), events.end(), [](const Event& a, const Event& b) {
    return std::tie(a.t_s, a.kind, a.robot, a.index) < std::tie(b.t_s, b.kind, b.robot, b.index);
  });
  return events;
}

double odometry_period(const RobotStream& robot, std::size_t index, double last_period_s) {
  const std::vector<slam::OdometrySample>& o = robot.input.odometry;
  if (index + 1 < o.size()) return o[index + 1].t_s - std::max(o[index].t_s, robot.input.start_time_s);
  return last_period_s;
}

Pacer::Clock::time_point Pacer::due(double t_s) const {
  if (rate_ <= 0.0) return start_;
  const double wall_s = std::max(0.0, t_s - first_t_s_) / rate_;
  return start_ + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(wall_s));
}

}  // namespace pixyslam::dataset_bridge
