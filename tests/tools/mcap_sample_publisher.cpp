// Test publisher for the logger's integration tests: N rounds, each one message
// of every topic (or of Odometry only), at a fixed rate, seq 1..N per topic.
//   mcap_sample_publisher --profiles config/dds/profiles.xml --domain D --count N
//                         [--rate-hz HZ] [--topics all|odometry] [--diagnostics] [--readers N] [--wait-readers S]
// Waits for one matched reader per topic, then publishes; prints
// "progress N" (rounds published) every 10 rounds, line-buffered, so that a
// test knows how far it got; then waits for the readers' acknowledgments and
// prints "published TOPIC N" per topic. Exit status: 0 when everything was
// published and acknowledged, 1 when not (e.g. the reader was killed) or on
// DDS errors, 2 on usage errors. SIGINT/SIGTERM end the run early.
#include <chrono>
#include <cstdio>
#include <exception>
#include <functional>
#include <memory>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "pixyslam/app/cli.h"
#include "pixyslam/app/process_main.h"
#include "pixyslam/app/stop_signal.h"
#include "pixyslam/dds/endpoints.h"

namespace pixyslam {
namespace {

msg::Odometry odometry(std::uint64_t i) {
  msg::Odometry m;
  m.header().stamp_ns(dds::now_ns());
  m.header().frame_id("base_link");
  m.v_mps(0.001 * static_cast<double>(i % 300));
  m.w_radps(-0.0005 * static_cast<double>(i % 100));
  m.period_s(0.1);
  m.distance_m(0.0001 * static_cast<double>(i));
  m.encoder_samples(static_cast<std::uint32_t>(i % 7));
  return m;
}

msg::LandmarkObservation observation(std::uint64_t i) {
  msg::LandmarkObservation m;
  m.header().stamp_ns(dds::now_ns());
  m.header().frame_id("camera");
  m.camera_frame(static_cast<std::uint32_t>(i));
  m.blocks_in_frame(static_cast<std::uint32_t>(i % 3));
  for (std::uint64_t k = 0; k < i % 3; ++k) {
    msg::LandmarkDetection d;
    d.landmark_id(static_cast<std::int32_t>(10 + k));
    d.range_m(1.0 + 0.01 * static_cast<double>(k));
    d.bearing_rad(0.1 * static_cast<double>(k));
    d.range_sigma_m(0.07);
    d.bearing_sigma_rad(0.027);
    m.detections().push_back(d);
  }
  return m;
}

msg::MapState map_state(std::uint64_t i) {
  msg::MapState m;
  m.header().stamp_ns(dds::now_ns());
  m.header().frame_id("map");
  msg::Pose2D pose;
  pose.x_m(0.01 * static_cast<double>(i));
  m.mean_pose(pose);
  m.best_pose(pose);
  m.particle_count(100);
  for (int k = 0; k < 3; ++k) m.particle_poses().push_back(pose);
  msg::LandmarkEstimate l;
  l.landmark_id(10);
  l.x_m(1.0);
  l.cov_xx_m2(0.01);
  l.cov_yy_m2(0.01);
  m.landmarks().push_back(l);
  m.odometry_sequence(i);
  return m;
}

msg::GroundTruth ground_truth(std::uint64_t i) {
  msg::GroundTruth m;
  m.header().stamp_ns(dds::now_ns());
  m.header().frame_id("map");
  msg::Pose2D pose;
  pose.x_m(0.01 * static_cast<double>(i));
  m.pose(pose);
  m.v_mps(0.2);
  msg::TrueLandmark l;
  l.landmark_id(10);
  l.x_m(1.0);
  m.landmarks().push_back(l);
  return m;
}

msg::OptimisedMap optimised_map(std::uint64_t i) {
  msg::OptimisedMap m;
  m.header().stamp_ns(dds::now_ns());
  m.header().frame_id("map");
  m.current_pose().x_m(0.01 * static_cast<double>(i));
  m.keyframe_count(3);
  for (int k = 0; k < 3; ++k) {
    msg::OptimisedKeyframe keyframe;
    keyframe.stamp_ns(m.header().stamp_ns() - static_cast<std::uint64_t>(3 - k) * 1000u);
    keyframe.pose().x_m(0.01 * static_cast<double>(i) - 0.001 * (3 - k));
    m.keyframes().push_back(keyframe);
  }
  msg::OptimisedLandmark l;
  l.landmark_id(10);
  l.x_m(1.0);
  l.cov_xx_m2(0.004);
  l.cov_yy_m2(0.004);
  l.observations(static_cast<std::uint32_t>(i));
  m.landmarks().push_back(l);
  m.converged(true);
  m.iterations(static_cast<std::uint32_t>(i % 20));
  m.keyframes_free(3);
  m.residuals(6);
  m.odometry_sequence(i);
  return m;
}

msg::RobotSighting robot_sighting(std::uint64_t i) {
  msg::RobotSighting m;
  m.header().stamp_ns(dds::now_ns());
  m.header().frame_id("camera");
  msg::RobotDetection d;
  d.seen_robot_id("robot" + std::to_string(2 + i % 4));
  d.range_m(1.0 + 0.001 * static_cast<double>(i % 1000));
  d.bearing_rad(-0.3);
  d.range_sigma_m(0.1);
  d.bearing_sigma_rad(0.05);
  m.detections().push_back(d);
  return m;
}

msg::FleetMap fleet_map(std::uint64_t i) {
  msg::FleetMap m;
  m.header().stamp_ns(dds::now_ns());
  m.header().frame_id("map");
  msg::FleetLandmark l;
  l.landmark_id(10);
  l.x_m(1.0 + 0.0001 * static_cast<double>(i));
  l.cov_xx_m2(0.002);
  l.cov_yy_m2(0.002);
  l.robots(2);
  m.landmarks().push_back(l);
  msg::RobotFrameCheck c;
  c.robot_id("robot1");
  c.verdict("agrees");
  c.fused(true);
  m.robots().push_back(c);
  return m;
}

msg::Diagnostics diagnostics(std::uint64_t i) {
  msg::Diagnostics m;
  m.header().stamp_ns(dds::now_ns());
  m.header().frame_id("mcap_sample_publisher");
  m.process("mcap_sample_publisher");
  m.pid(static_cast<std::uint32_t>(1000 + i));
  m.level(static_cast<std::uint8_t>(i % 3));
  m.status(i % 3 == 0 ? "" : "status " + std::to_string(i));
  m.uptime_s(0.1 * static_cast<double>(i));
  for (int k = 0; k < 2; ++k) {
    msg::DiagnosticCounter c;
    c.name(k == 0 ? "rounds" : "rejected");
    c.value(i * static_cast<std::uint64_t>(k + 1));
    m.counters().push_back(c);
  }
  return m;
}

// One topic's writer, publishing make(i) in round i.
struct TopicPublisher {
  std::string topic;
  std::function<bool(std::uint64_t)> publish;
  std::function<bool(int, std::chrono::milliseconds)> wait_for_readers;
  std::function<bool(std::chrono::seconds)> wait_for_acknowledgments;
  std::function<std::uint64_t()> published;
};

template <class Message>
TopicPublisher topic_publisher(dds::Participant& participant, Message (*make)(std::uint64_t)) {
  auto writer = std::make_shared<dds::Writer<Message>>(participant);
  return {std::string(dds::MessageTraits<Message>::topic),
          [writer, make](std::uint64_t i) {
            Message m = make(i);
            return writer->publish(m);
          },
          [writer](int count, std::chrono::milliseconds wait) { return writer->wait_for_readers(count, wait); },
          [writer](std::chrono::seconds wait) { return writer->wait_for_acknowledgments(wait); },
          [writer] { return writer->published(); }};
}

int run(int argc, char** argv) {
  dds::DdsOptions options;
  int count = 0;
  double rate_hz = 500.0;
  std::string topics = "all";
  double wait_s = 20.0;
  bool with_diagnostics = false;
  int readers = 1;
  app::Cli cli{"mcap_sample_publisher", "Publishes N messages of every topic (or Odometry only) for the logger tests."};
  cli.option("--profiles", options.profiles_file, "the Fast DDS profiles XML").required().existing_file().type("FILE");
  std::vector<std::string> dds_overrides;
  app::add_domain(cli, dds_overrides);
  cli.option("--count", count, "messages per topic").required().range(1, 100000000).type("N");
  cli.option("--rate-hz", rate_hz, "rounds per second").positive().type("HZ");
  cli.option("--topics", topics, "every data topic, or Odometry only").choices({"all", "odometry"});
  cli.flag("--diagnostics", with_diagnostics, "also publish N Diagnostics");
  cli.option("--wait-readers", wait_s, "seconds to wait for the readers").non_negative().type("S");
  cli.option("--readers", readers, "matched readers per topic to wait for").range(1, 100).type("N");
  if (const auto done = cli.parse(argc, argv)) return *done;
  dds::resolve_settings(options, dds_overrides);
  options.robot_id = "sample_publisher";
  const auto total = static_cast<std::uint64_t>(count);

  dds::Participant participant(options, "mcap_sample_publisher");
  std::vector<TopicPublisher> publishers = {topic_publisher(participant, &odometry)};
  if (topics == "all") {
    publishers.push_back(topic_publisher(participant, &observation));
    publishers.push_back(topic_publisher(participant, &map_state));
    publishers.push_back(topic_publisher(participant, &ground_truth));
    publishers.push_back(topic_publisher(participant, &optimised_map));
    publishers.push_back(topic_publisher(participant, &robot_sighting));
    publishers.push_back(topic_publisher(participant, &fleet_map));
  }
  if (with_diagnostics) publishers.push_back(topic_publisher(participant, &diagnostics));
  const auto wait = std::chrono::milliseconds(static_cast<long>(wait_s * 1000.0));
  for (const TopicPublisher& p : publishers) {
    if (!p.wait_for_readers(readers, wait)) {
      std::fprintf(stderr, "mcap_sample_publisher: fewer than %d reader(s) of %s on domain %d after %.0f s\n", readers,
                   p.topic.c_str(), options.domain_id, wait_s);
      return 1;
    }
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(200));  // every reader fully matched

  using Clock = std::chrono::steady_clock;
  const auto start = Clock::now();
  const auto period = std::chrono::duration<double>(1.0 / rate_hz);
  bool ok = true;
  std::uint64_t round = 0;
  for (std::uint64_t i = 1; i <= total && !app::StopSignal::requested(); ++i) {
    std::this_thread::sleep_until(start + std::chrono::duration_cast<Clock::duration>(period * static_cast<double>(i - 1)));
    for (const TopicPublisher& p : publishers) ok = p.publish(i) && ok;
    round = i;
    if (i % 10 == 0 || i == total) std::printf("progress %llu\n", static_cast<unsigned long long>(i));
  }
  // Stopped early: the reader may be gone, nothing to wait for.
  const auto ack = app::StopSignal::requested() ? std::chrono::seconds(0) : std::chrono::seconds(10);
  for (const TopicPublisher& p : publishers) ok = p.wait_for_acknowledgments(ack) && ok;
  for (const TopicPublisher& p : publishers) {
    std::printf("published %s %llu\n", p.topic.c_str(), static_cast<unsigned long long>(p.published()));
  }
  return ok && round == total ? 0 : 1;
}

}  // namespace
}  // namespace pixyslam

int main(int argc, char** argv) {
  pixyslam::app::StopSignal::install();
  std::setvbuf(stdout, nullptr, _IOLBF, 0);
  return pixyslam::app::run_main("mcap_sample_publisher", [&] { return pixyslam::run(argc, argv); });
}
