#include "pixyslam/fleet_map_node/fleet_map_node.h"

#include <chrono>
#include <cmath>
#include <cstdio>

#include "pixyslam/config/parameters_yaml.h"
#include "pixyslam/config/yaml_reader.h"
#include "pixyslam/dds/endpoints.h"
#include "pixyslam/dds/participant.h"
#include "pixyslam/dds/wire_text.h"
#include "pixyslam/diagnostics/diagnostics_publisher.h"

namespace pixyslam::fleet_map_node {
namespace {
// A MapState this much older than its robot's newest is a restarted estimator.
constexpr double kRestartGapS = 10.0;
}  // namespace

const parameters::Table<FleetMapOptions>& fleet_map_parameters() {
  using O = FleetMapOptions;
  using D = fleet_map::FusionOptions::Disagreement;
  namespace P = parameters;
  static const P::Table<O> table = {
      P::real<O>("period_s", 0.05, 3600.0, "s", "a fleet map this often while some robot's map changed",
                 [](O& o) -> double& { return o.period_s; }),
      P::integer<O, int>("max_robots", 1, 4096, "", "robots fused at most; MapStates of further robot ids are dropped",
                         [](O& o) -> int& { return o.max_robots; }),
      P::real<O>("robot_timeout_s", 0.0, 1e6, "s",
                 "a robot heard from no MapState for this long leaves the fusion and frees its place (0: never)",
                 [](O& o) -> double& { return o.robot_timeout_s; }),
      P::integer<O, int>("min_common_landmarks", 3, 100000, "",
                         "landmarks a robot must share with the others for its frame to be checked (and aligned)",
                         [](O& o) -> int& { return o.fusion.min_common_landmarks; }),
      P::real<O>("agreement_probability", 0.5, 0.999999, "",
                 "frames agree below the rigid-offset F test's quantile at this probability",
                 [](O& o) -> double& { return o.fusion.agreement_probability; }),
      P::choice<O, D>("disagreement", {{"align", D::kAlign}, {"set_aside", D::kSetAside}},
                      "robots whose frames disagree: align (move every map onto the robots' mean frame) or "
                      "set_aside (fuse only robots that agree)",
                      [](O& o) -> D& { return o.fusion.disagreement; }),
  };
  return table;
}

FleetMapOptions read_fleet_map_options_file(const std::string& path) {
  config::YamlReader root = config::YamlReader::from_file(path);
  FleetMapOptions o;
  config::YamlReader y = root.child("fleet_map");
  config::read_parameters(y, fleet_map_parameters(), o);
  y.finish();
  o.dds = dds::read_dds_section(root, config::folder_of(path));
  root.finish();
  return o;
}

void apply_overrides(FleetMapOptions& o, const std::vector<std::string>& assignments) {
  std::vector<std::string> rest = assignments;
  const std::vector<std::string> dds = parameters::take_section(rest, "dds");
  for (const std::string& a : rest) parameters::apply_override(o, fleet_map_parameters(), "fleet_map", a);
  parameters::check_ranges(o, fleet_map_parameters(), "fleet_map");
  dds::resolve_settings(o.dds, dds);
}

std::string to_yaml(const FleetMapOptions& o) {
  return parameters::to_yaml(o, fleet_map_parameters(), "fleet_map") + dds::to_yaml(o.dds);
}

fleet_map::RobotMap to_robot_map(const msg::MapState& state) {
  fleet_map::RobotMap m;
  m.robot_id = state.header().robot_id();
  m.stamp_ns = state.header().stamp_ns();
  for (const msg::LandmarkEstimate& l : state.landmarks()) {
    fleet_map::LandmarkEstimate e;
    e.id = l.landmark_id();
    e.mean = {l.x_m(), l.y_m()};
    e.cov << l.cov_xx_m2(), l.cov_xy_m2(), l.cov_xy_m2(), l.cov_yy_m2();
    m.landmarks.push_back(e);
  }
  return m;
}

msg::FleetMap to_fleet_map_msg(const fleet_map::FleetMap& fleet, const std::vector<fleet_map::RobotMap>& maps,
                               std::uint64_t stamp_ns) {
  msg::FleetMap m;
  m.header().stamp_ns(stamp_ns);
  m.header().frame_id("map");
  for (const fleet_map::FusedLandmark& l : fleet.landmarks) {
    msg::FleetLandmark f;
    f.landmark_id(l.id);
    f.x_m(l.mean.x());
    f.y_m(l.mean.y());
    f.cov_xx_m2(l.cov(0, 0));
    f.cov_xy_m2(l.cov(0, 1));
    f.cov_yy_m2(l.cov(1, 1));
    f.robots(static_cast<std::uint32_t>(l.robots));
    m.landmarks().push_back(f);
  }
  for (std::size_t r = 0; r < fleet.robots.size(); ++r) {
    const fleet_map::FrameCheck& c = fleet.robots[r];
    msg::RobotFrameCheck k;
    k.robot_id(c.robot_id);
    k.map_stamp_ns(r < maps.size() ? maps[r].stamp_ns : 0);
    k.landmarks(static_cast<std::uint32_t>(c.landmarks));
    k.common(static_cast<std::uint32_t>(c.common));
    k.verdict(fleet_map::to_string(c.verdict));
    k.f_statistic(c.f_statistic);
    k.threshold(c.threshold);
    k.offset_m(c.offset_m);
    k.rotation_rad(c.rotation_rad);
    k.residual_m(c.residual_m);
    k.fused(c.fused);
    k.moved_rotation_rad(c.moved_rotation_rad);
    k.moved_shift_m(c.moved_shift_m);
    m.robots().push_back(k);
  }
  return m;
}

FleetMapNode::FleetMapNode(const FleetMapOptions& options) : options_(options) {
  participant_ = std::make_unique<dds::Participant>(options_.dds, "fleet_map");
  writer_ = std::make_unique<dds::Writer<msg::FleetMap>>(*participant_);
  // Every robot's map: no robot filter.
  reader_ = std::make_unique<dds::Reader<msg::MapState>>(*participant_,
                                                         [this](const msg::MapState& m) { on_map_state(m); }, "");
  diagnostics_ = std::make_unique<diagnostics::DiagnosticsPublisher>(
      *participant_, "fleet_map", options_.dds.diagnostics_period_s, [this] { return diagnostics_snapshot(); });
}

FleetMapNode::~FleetMapNode() {
  stop();
  diagnostics_.reset();
}

diagnostics::Snapshot FleetMapNode::diagnostics_snapshot() const {
  const FleetMapCounters c = counters();
  diagnostics::Snapshot s;
  s.counters = {{"map_states", c.map_states, false},
                {"robots", c.robots, false},
                {"stale", c.stale, false},
                {"restarts", c.restarts, true},
                {"robots_over_limit", c.robots_over_limit, true},
                {"robots_timed_out", c.robots_timed_out, false},
                {"malformed", c.malformed, true},
                {"seq_jumps", c.seq_jumps, true},
                {"fleet_maps", c.fleet_maps, false},
                {"publish_failures", c.publish_failures, true}};
  return s;
}

void FleetMapNode::start() {
  std::lock_guard<std::mutex> lock(mutex_);
  if (thread_.joinable() || stopping_) return;
  thread_ = std::thread([this] { loop(); });
}

void FleetMapNode::stop() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stopping_ = true;
  }
  cv_.notify_all();
  if (thread_.joinable()) thread_.join();
  if (diagnostics_) diagnostics_->stop();
  if (!reader_) return;
  const FleetMapCounters last = counters();
  std::lock_guard<std::mutex> lock(mutex_);
  counters_.malformed = last.malformed;
  counters_.seq_jumps = last.seq_jumps;
  reader_.reset();  // no callback after this
}

FleetMapCounters FleetMapNode::counters() const {
  std::lock_guard<std::mutex> lock(mutex_);
  FleetMapCounters c = counters_;
  c.robots = maps_.size();
  if (reader_) {  // reset only by stop(), on the thread that calls counters() after it
    c.malformed = reader_->malformed() + reader_->callback_errors();
    c.seq_jumps = reader_->seq_jumps();
  }
  return c;
}

void FleetMapNode::on_map_state(const msg::MapState& state) {
  std::lock_guard<std::mutex> lock(mutex_);
  ++counters_.map_states;
  const std::uint64_t stamp = state.header().stamp_ns();
  const auto now = std::chrono::steady_clock::now();
  const auto it = maps_.find(state.header().robot_id());
  if (it == maps_.end() && maps_.size() >= static_cast<std::size_t>(options_.max_robots)) {
    time_out_silent_robots(now);
    if (maps_.size() >= static_cast<std::size_t>(options_.max_robots)) {
      ++counters_.robots_over_limit;
      return;
    }
  }
  if (it != maps_.end() && stamp < it->second.map.stamp_ns) {
    if (static_cast<double>(it->second.map.stamp_ns - stamp) * 1e-9 <= kRestartGapS) {
      ++counters_.stale;
      return;
    }
    ++counters_.restarts;
  }
  maps_[state.header().robot_id()] = {to_robot_map(state), now};
  changed_ = true;
}

void FleetMapNode::time_out_silent_robots(std::chrono::steady_clock::time_point now) {
  if (options_.robot_timeout_s <= 0.0) return;
  const auto timeout = std::chrono::duration<double>(options_.robot_timeout_s);
  for (auto it = maps_.begin(); it != maps_.end();) {
    if (now - it->second.heard <= timeout) {
      ++it;
      continue;
    }
    std::fprintf(stderr, "fleet_map: no MapState from %s for %g s: it leaves the fleet map\n",
                 dds::printable(it->first).c_str(), options_.robot_timeout_s);
    ++counters_.robots_timed_out;
    verdicts_.erase(it->first);
    it = maps_.erase(it);
    changed_ = true;
  }
}

void FleetMapNode::loop() {
  const auto period = std::chrono::duration<double>(options_.period_s);
  for (;;) {
    bool last = false;
    {
      std::unique_lock<std::mutex> lock(mutex_);
      cv_.wait_for(lock, period, [this] { return stopping_; });
      last = stopping_;
    }
    fuse_and_publish();
    if (last) return;
  }
}

void FleetMapNode::fuse_and_publish() {
  std::vector<fleet_map::RobotMap> maps;
  std::uint64_t stamp = 0;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    time_out_silent_robots(std::chrono::steady_clock::now());
    if (!changed_) return;
    changed_ = false;
    for (const auto& entry : maps_) {
      maps.push_back(entry.second.map);
      stamp = std::max(stamp, entry.second.map.stamp_ns);
    }
    // With every robot gone the (empty) fleet map keeps the last stamp.
    if (maps.empty()) stamp = published_stamp_ns_;
    published_stamp_ns_ = stamp;
  }
  const fleet_map::FleetMap fleet = fleet_map::fuse_maps(maps, options_.fusion);
  msg::FleetMap message = to_fleet_map_msg(fleet, maps, stamp);
  const bool ok = writer_->publish(message);
  std::lock_guard<std::mutex> lock(mutex_);
  ++(ok ? counters_.fleet_maps : counters_.publish_failures);
  for (const fleet_map::FrameCheck& c : fleet.robots) {
    const std::string verdict = fleet_map::to_string(c.verdict);
    std::string& logged = verdicts_[c.robot_id];
    if (logged == verdict) continue;
    logged = verdict;
    std::fprintf(stderr,
                 "fleet_map: %s's frame %s with the others' (%zu shared landmarks, F %.1f / %.1f; offset %.2f m, "
                 "rotation %.1f deg, residual %.2f m)%s\n",
                 dds::printable(c.robot_id).c_str(), verdict.c_str(), c.common, c.f_statistic, c.threshold, c.offset_m,
                 c.rotation_rad * 180.0 / M_PI, c.residual_m,
                 c.fused ? (c.verdict == fleet_map::FrameVerdict::kDisagrees &&
                                    options_.fusion.disagreement == fleet_map::FusionOptions::Disagreement::kAlign
                                ? ": aligned"
                                : "")
                         : ": set aside");
  }
}

}  // namespace pixyslam::fleet_map_node
