#include "pixyslam/dataset_bridge_node/dataset_publisher.h"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>
#include <stdexcept>
#include <thread>

#include "pixyslam/config/parameters_yaml.h"
#include "pixyslam/dds/endpoints.h"
#include "pixyslam/dds/participant.h"
#include "pixyslam/slam/slam_options_yaml.h"

namespace pixyslam::dataset_bridge_node {

const parameters::Table<DatasetBridgeOptions>& dataset_bridge_parameters() {
  using O = DatasetBridgeOptions;
  namespace P = parameters;
  static const P::Table<O> table = {
      P::real<O>("rate", 0.0, 1000.0, "", "times the recording's speed (0: as fast as the readers acknowledge)",
                 [](O& o) -> double& { return o.rate; }),
      P::integer<O, int>("wait_readers", 0, 100, "", "matched readers per topic to wait for before the first sample",
                         [](O& o) -> int& { return o.wait_readers; }),
      P::integer<O, int>("wait_readers_per_robot", 0, 100, "",
                         "... and this many more per robot published (e.g. its estimator and evaluator)",
                         [](O& o) -> int& { return o.wait_readers_per_robot; }),
      P::real<O>("wait_readers_timeout_s", 0.0, 3600.0, "s", "... at most this long (then it starts anyway)",
                 [](O& o) -> double& { return o.wait_readers_timeout_s; }),
      P::integer<O, int>("flow_batch", 1, 100000, "", "rate 0: samples between waits for every reader's acknowledgement",
                         [](O& o) -> int& { return o.flow_batch; }),
      P::real<O>("ack_timeout_s", 0.1, 600.0, "s", "rate 0: longest wait for the acknowledgements",
                 [](O& o) -> double& { return o.ack_timeout_s; }),
  };
  return table;
}

namespace {

// "1,3" (or a YAML list's items joined): robots 1-5, none twice.
std::vector<int> read_robots(const std::string& text, const std::string& where) {
  std::vector<int> robots = parameters::parse_int_list(text, where, mrclam::kFirstRobot);
  mrclam::check_robot_list(robots, where);
  return robots;
}

}  // namespace

DatasetBridgeOptions read_dataset_bridge_options_file(const std::string& path) {
  config::YamlReader root = config::YamlReader::from_file(path);
  DatasetBridgeOptions o;
  std::string filter_config = root.text("filter_config");
  if (!filter_config.empty() && filter_config.front() != '/') filter_config = config::folder_of(path) + "/" + filter_config;
  config::read_referenced(path, "filter_config", [&] {
    config::YamlReader filter_root = config::YamlReader::from_file(filter_config);
    config::YamlReader filter = filter_root.child("filter");
    o.filter = slam::read_filter_options(filter);
    o.sensor_model = offline::read_mrclam_sensor_model(filter_root);
  });
  config::YamlReader y = root.child("dataset_bridge");
  if (y.has("robots")) {
    std::string text;
    for (const std::string& t : y.text_list("robots")) text += (text.empty() ? "" : ",") + t;
    config::check_rules(y, [&] { o.robots = read_robots(text, "robots"); });
  }
  config::read_parameters(y, dataset_bridge_parameters(), o);
  y.finish();
  o.dds = dds::read_dds_section(root, config::folder_of(path));
  root.finish();
  return o;
}

void apply_overrides(DatasetBridgeOptions& o, const std::vector<std::string>& assignments) {
  std::vector<std::string> rest = assignments;
  const std::vector<std::string> dds = parameters::take_section(rest, "dds");
  for (const std::string& a : rest) {
    const std::string robots_key = "dataset_bridge.robots=";
    if (a.rfind(robots_key, 0) == 0) {
      o.robots = read_robots(a.substr(robots_key.size()), "dataset_bridge.robots");
      continue;
    }
    parameters::apply_override(o, dataset_bridge_parameters(), "dataset_bridge", a);
  }
  parameters::check_ranges(o, dataset_bridge_parameters(), "dataset_bridge");
  dds::resolve_settings(o.dds, dds);
}

std::string to_yaml(const DatasetBridgeOptions& o) {
  std::string robots;
  for (int r : o.robots) robots += (robots.empty() ? "" : ", ") + std::to_string(r);
  std::string bridge = parameters::to_yaml(o, dataset_bridge_parameters(), "dataset_bridge");
  bridge.insert(bridge.find('\n') + 1, "  robots: [" + robots + "]\n");
  return bridge + parameters::to_yaml(o.filter, slam::filter_parameters(), "filter") +
         parameters::to_yaml(o.sensor_model, offline::mrclam_sensor_parameters(), "mrclam") + dds::to_yaml(o.dds);
}

namespace {

std::uint64_t to_ns(double t_s) { return static_cast<std::uint64_t>(std::llround(t_s * 1e9)); }

// Range, bearing and the filter's configured sigmas of one detection (LandmarkDetection, RobotDetection).
template <class Detection>
void set_measurement(Detection& d, const slam::RangeBearing& z, const slam::FilterOptions& filter) {
  d.range_m(z.range_m);
  d.bearing_rad(z.bearing_rad);
  d.range_sigma_m(filter.range_sigma_m + filter.range_sigma_per_m * z.range_m);
  d.bearing_sigma_rad(filter.bearing_sigma_rad);
}

// One robot's writers.
struct RobotWriters {
  RobotWriters(dds::Participant& p, const std::string& robot_id)
      : odometry(p, robot_id), observation(p, robot_id), truth(p, robot_id), sighting(p, robot_id) {}
  dds::Writer<msg::Odometry> odometry;
  dds::Writer<msg::LandmarkObservation> observation;
  dds::Writer<msg::GroundTruth> truth;
  dds::Writer<msg::RobotSighting> sighting;
};

}  // namespace

PublishCounters publish_recording(const DatasetBridgeOptions& options,
                                  const std::vector<dataset_bridge::RobotStream>& robots,
                                  const std::atomic<bool>& stop) {
  using dataset_bridge::EventKind;
  PublishCounters c;
  const std::vector<dataset_bridge::Event> events = dataset_bridge::merge_timeline(robots);
  dds::Participant participant(options.dds, "dataset_bridge");
  std::vector<std::unique_ptr<RobotWriters>> writers;
  for (const dataset_bridge::RobotStream& r : robots) writers.push_back(std::make_unique<RobotWriters>(participant, r.robot_id));
  const int readers = options.wait_readers + options.wait_readers_per_robot * static_cast<int>(robots.size());
  if (readers > 0) {
    const auto timeout = std::chrono::milliseconds(static_cast<int>(options.wait_readers_timeout_s * 1000));
    for (auto& w : writers) {
      if (!w->odometry.wait_for_readers(readers, timeout) || !w->observation.wait_for_readers(readers, timeout) ||
          !w->truth.wait_for_readers(readers, timeout)) {
        std::fprintf(stderr, "dataset_bridge: fewer than %d readers matched after %.0f s; publishing anyway\n",
                     readers, options.wait_readers_timeout_s);
        break;
      }
    }
  }
  if (events.empty()) return c;
  const auto start = std::chrono::steady_clock::now();
  const dataset_bridge::Pacer pacer(options.rate, events.front().t_s, start);
  const auto count = [&](bool ok) { if (!ok) ++c.write_failures; };
  std::size_t since_flow = 0;
  for (const dataset_bridge::Event& e : events) {
    if (stop.load()) break;
    if (pacer.paced()) std::this_thread::sleep_until(pacer.due(e.t_s));
    const dataset_bridge::RobotStream& r = robots[e.robot];
    RobotWriters& w = *writers[e.robot];
    switch (e.kind) {
      case EventKind::kOdometry: {
        const slam::OdometrySample& o = r.input.odometry[e.index];
        msg::Odometry m;
        m.header().stamp_ns(to_ns(e.t_s));
        m.header().frame_id("base_link");
        const double period = dataset_bridge::odometry_period(r, e.index);
        m.v_mps(o.v_mps);
        m.w_radps(o.w_radps);
        m.period_s(period);
        m.distance_m(o.v_mps * period);
        m.rotation_rad(o.w_radps * period);
        m.encoder_samples(o.measured ? 1 : 0);
        count(w.odometry.publish(m));
        ++c.odometry;
        break;
      }
      case EventKind::kFrame: {
        const slam::ObservationFrame& f = r.input.frames[e.index];
        msg::LandmarkObservation m;
        m.header().stamp_ns(to_ns(f.t_s));
        m.header().frame_id("camera");
        m.camera_frame(static_cast<std::uint32_t>(e.index + 1));
        m.blocks_in_frame(static_cast<std::uint32_t>(f.detections.size()));
        for (const slam::RangeBearing& z : f.detections) {
          msg::LandmarkDetection d;
          d.landmark_id(z.landmark_id);
          set_measurement(d, z, options.filter);
          m.detections().push_back(d);
        }
        count(w.observation.publish(m));
        ++c.observations;
        break;
      }
      case EventKind::kGroundTruth: {
        const eval::TimedPose& g = r.input.truth[e.index];
        msg::GroundTruth m;
        m.header().stamp_ns(to_ns(g.t_s));
        m.header().frame_id("map");
        m.pose().x_m(g.x_m);
        m.pose().y_m(g.y_m);
        m.pose().theta_rad(g.theta_rad);
        for (const eval::LandmarkPoint& l : r.input.landmarks) {
          msg::TrueLandmark t;
          t.landmark_id(l.id);
          t.x_m(l.x_m);
          t.y_m(l.y_m);
          m.landmarks().push_back(t);
        }
        count(w.truth.publish(m));
        ++c.ground_truth;
        break;
      }
      case EventKind::kSighting: {
        const slam::ObservationFrame& f = r.sightings[e.index];
        msg::RobotSighting m;
        m.header().stamp_ns(to_ns(f.t_s));
        m.header().frame_id("camera");
        for (const slam::RangeBearing& z : f.detections) {
          msg::RobotDetection d;
          d.seen_robot_id(mrclam::robot_id(z.landmark_id));
          set_measurement(d, z, options.filter);
          m.detections().push_back(d);
        }
        count(w.sighting.publish(m));
        ++c.sightings;
        break;
      }
    }
    if (!pacer.paced() && ++since_flow >= static_cast<std::size_t>(options.flow_batch)) {
      since_flow = 0;
      const auto timeout = std::chrono::milliseconds(static_cast<int>(options.ack_timeout_s * 1000));
      for (auto& rw : writers) {
        if (!rw->odometry.wait_for_acknowledgments(timeout)) ++c.ack_timeouts;
        if (!rw->observation.wait_for_acknowledgments(timeout)) ++c.ack_timeouts;
        if (!rw->truth.wait_for_acknowledgments(timeout)) ++c.ack_timeouts;
        if (!rw->sighting.wait_for_acknowledgments(timeout)) ++c.ack_timeouts;
      }
    }
  }
  c.wall_time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  c.recording_time_s = events.back().t_s - events.front().t_s;
  return c;
}

}  // namespace pixyslam::dataset_bridge_node
