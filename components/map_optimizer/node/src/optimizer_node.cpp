#include "pixyslam/map_optimizer_node/optimizer_node.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <ctime>
#include <future>
#include <limits>

#include "pixyslam/slam_node/map_state_conversions.h"

namespace pixyslam::map_optimizer_node {
namespace {

// The filter's poses kept for keyframe guesses: a few seconds of MapStates.
constexpr std::size_t kFilterPosesKept = 2048;
constexpr std::uint64_t kStampToleranceNs = 1000;

double thread_cpu_seconds() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

}  // namespace

OptimizerNode::OptimizerNode(const OptimizerNodeOptions& options)
    : options_(options), inbox_(options.queue, options.use_detection_sigmas) {
  map_optimizer::validate(options_.optimizer);
  participant_ = std::make_unique<dds::Participant>(options_.dds, "map_optimizer");
  writer_ = std::make_unique<dds::Writer<msg::OptimisedMap>>(*participant_);
  // Only this robot's data (dds.robot_id): several robots may share the domain.
  const std::string& robot = options_.dds.robot_id;
  odometry_reader_ = std::make_unique<dds::Reader<msg::Odometry>>(
      *participant_, [this](const msg::Odometry& m) { inbox_.push(m); }, robot);
  observation_reader_ = std::make_unique<dds::Reader<msg::LandmarkObservation>>(
      *participant_, [this](const msg::LandmarkObservation& m) { inbox_.push(m); }, robot);
  map_state_reader_ = std::make_unique<dds::Reader<msg::MapState>>(
      *participant_, [this](const msg::MapState& m) { on_map_state(m); }, robot);
  diagnostics_ = std::make_unique<diagnostics::DiagnosticsPublisher>(
      *participant_, "map_optimizer", options_.dds.diagnostics_period_s, [this] { return diagnostics_snapshot(); });
}

OptimizerNode::~OptimizerNode() {
  stop();
  diagnostics_.reset();
  odometry_reader_.reset();
  observation_reader_.reset();
  map_state_reader_.reset();
  writer_.reset();
  participant_.reset();
}

void OptimizerNode::start() {
  std::lock_guard<std::mutex> lock(run_mutex_);
  if (thread_.joinable() || stopping_) return;
  thread_ = std::thread([this] { loop(); });
}

void OptimizerNode::stop() {
  {
    std::lock_guard<std::mutex> lock(run_mutex_);
    stopping_ = true;
  }
  inbox_.stop();
  if (!thread_.joinable()) return;
  thread_.join();
  diagnostics_->stop();
}

void OptimizerNode::on_map_state(const msg::MapState& m) {
  const msg::Pose2D& p = m.mean_pose();
  std::lock_guard<std::mutex> lock(filter_mutex_);
  filter_poses_.emplace_back(m.header().stamp_ns(), slam::Pose2(p.x_m(), p.y_m(), p.theta_rad()));
  while (filter_poses_.size() > kFilterPosesKept) filter_poses_.pop_front();
  filter_landmarks_.clear();
  for (const msg::LandmarkEstimate& l : m.landmarks()) {
    filter_landmarks_.emplace_back(l.landmark_id(), Eigen::Vector2d(l.x_m(), l.y_m()));
  }
}

OptimizerNodeCounters OptimizerNode::counters() const {
  std::lock_guard<std::mutex> lock(state_mutex_);
  OptimizerNodeCounters c = counters_;
  c.odometry_received = odometry_reader_->received();
  c.observations_received = observation_reader_->received();
  c.map_states_received = map_state_reader_->received();
  c.malformed = odometry_reader_->malformed() + observation_reader_->malformed() + map_state_reader_->malformed() +
                odometry_reader_->callback_errors() + observation_reader_->callback_errors() +
                map_state_reader_->callback_errors();
  c.seq_jumps = odometry_reader_->seq_jumps() + observation_reader_->seq_jumps() + map_state_reader_->seq_jumps();
  return c;
}

msg::OptimisedMap OptimizerNode::latest_map() const {
  std::lock_guard<std::mutex> lock(state_mutex_);
  return map_;
}

diagnostics::Snapshot OptimizerNode::diagnostics_snapshot() const {
  const OptimizerNodeCounters c = counters();
  const slam::SensorQueueCounters queue = inbox_.queue_counters();
  std::lock_guard<std::mutex> lock(state_mutex_);
  const map_optimizer::OptimizerCounters o = optimizer_counters();
  diagnostics::Snapshot s;
  s.counters = {{"odometry_received", c.odometry_received, false},
                {"observations_received", c.observations_received, false},
                {"map_states_received", c.map_states_received, false},
                {"malformed", c.malformed, true},
                {"seq_jumps", c.seq_jumps, true},
                {"samples_late", queue.late, true},
                {"samples_ahead", queue.ahead, true},
                {"samples_flood_dropped", queue.overflow, true},
                {"step_errors", c.step_errors, true},
                {"odometry_dropped", o.odometry_dropped, true},
                {"frames_dropped", o.frames_dropped, true},
                {"observations_invalid", o.observations_invalid, true},
                {"observations_over_map_limit", o.observations_over_map_limit, true},
                {"observations_unknown_id", o.observations_unknown_id, true},
                {"keyframes", o.keyframes, false},
                {"observations", o.observations, false},
                {"window_solves", c.window_solves, false},
                {"whole_solves", c.whole_solves, false},
                {"maps_published", c.maps_published, false},
                {"segments", c.segments, false},
                {"time_rebases", queue.rebases, true}};
  return s;
}

void OptimizerNode::loop() {
  using Clock = std::chrono::steady_clock;
  cpu_start_s_ = thread_cpu_seconds();
  auto next_status = Clock::now() + std::chrono::duration<double>(options_.status_period_s);
  for (;;) {
    const slam_node::SensorInbox::Ready ready = inbox_.wait_ready();
    const bool stopping = ready.stopping;
    if (ready.rebased) restart_at_new_time();
    slam_node::step_each(ready.inputs, [this](const slam::SensorInput& input) { step(input); }, "map_optimizer",
                         state_mutex_, counters_.step_errors);
    if (stopping) {
      std::lock_guard<std::mutex> state_lock(state_mutex_);
      collect_whole(true);
      if (optimizer_ && dirty_) solve(true);
      if (optimizer_) emit_keyframes();
    }
    if (options_.status_period_s > 0.0 && Clock::now() >= next_status) {
      log_status();
      next_status = Clock::now() + std::chrono::duration<double>(options_.status_period_s);
    }
    if (stopping) break;
  }
  log_status();
}

void OptimizerNode::step(const slam::SensorInput& input) {
  std::lock_guard<std::mutex> lock(state_mutex_);
  const double t = slam::input_time(input);
  if (!optimizer_ && rebase_pending_) {
    begin_problem_after_rebase(t);
  } else if (!optimizer_) {
    epoch_ns_ = inbox_.epoch_ns();
    optimizer_ = std::make_unique<map_optimizer::MapOptimizer>(options_.optimizer, options_.initial_pose, t);
    schedule_.emplace(options_.schedule, t);
  }
  {
    std::lock_guard<std::mutex> filter_lock(filter_mutex_);
    for (const auto& [id, position] : filter_landmarks_) optimizer_->set_landmark_guess(id, position);
  }
  if (const auto* odometry = std::get_if<slam::OdometryInput>(&input)) {
    const std::size_t taken_before = optimizer_->counters().odometry;
    optimizer_->add_odometry(odometry->sample);
    last_odometry_seq_ = odometry->seq;
    // At a measured sample the problem took (not a late one), so that the new
    // problem starts at its time and holds its control from there.
    if (options_.max_keyframes > 0 && optimizer_->keyframes().size() >= options_.max_keyframes &&
        odometry->sample.measured && optimizer_->counters().odometry > taken_before) {
      start_segment(odometry->sample);
    }
  } else {
    const auto& observation = std::get<slam::ObservationInput>(input);
    std::optional<slam::Pose2> guess;
    {
      const std::uint64_t stamp = slam_node::to_stamp_ns(observation.frame.t_s, epoch_ns_);
      std::lock_guard<std::mutex> filter_lock(filter_mutex_);
      // The same stamp, up to the rounding of the two processes' time bases.
      const auto it = std::find_if(filter_poses_.rbegin(), filter_poses_.rend(), [stamp](const auto& p) {
        return (p.first > stamp ? p.first - stamp : stamp - p.first) <= kStampToleranceNs;
      });
      if (it != filter_poses_.rend()) {
        guess = it->second;
        ++counters_.guesses_from_filter;
      }
    }
    optimizer_->add_frame(observation.frame, guess);
    last_observation_seq_ = observation.seq;
  }
  last_t_s_ = std::max(last_t_s_, t);
  dirty_ = true;
  collect_whole(false);
  // While the last whole solve still runs, the next one waits for it (and
  // starts at the first input after); windows go on meanwhile.
  const map_optimizer::SolveKind due = schedule_->due(t, !whole_job_.valid());
  if (due == map_optimizer::SolveKind::kWhole) {
    // In the background on a copy.
    dirty_ = false;
    whole_job_ = std::async(std::launch::async, [problem = optimizer_->snapshot(), t] {
      const double cpu_before = thread_cpu_seconds();
      BackgroundWhole job;
      job.solution = map_optimizer::solve_whole_problem(problem, true);
      job.cpu_s = thread_cpu_seconds() - cpu_before;
      job.due_t_s = t;
      return job;
    });
  } else if (due == map_optimizer::SolveKind::kWindow) {
    solve(false);
  }
}

void OptimizerNode::start_segment(const slam::OdometrySample& odometry) {
  const std::size_t keyframes = optimizer_->keyframes().size();
  end_problem();
  begin_problem(odometry.t_s);
  optimizer_->add_odometry(odometry);  // its control, held from now on
  --earlier_segments_.odometry;        // the boundary sample goes to both problems: counted once
  std::fprintf(stderr,
               "map_optimizer: %zu keyframes (optimizer.max_keyframes): a new problem from the current pose, %zu of %zu "
               "landmarks as priors\n",
               keyframes, next_priors_, next_landmarks_.size());
}

void OptimizerNode::end_problem(bool emit) {
  collect_whole(true);
  solve(true);  // a last whole solve, with covariances, published
  if (emit) emit_keyframes();
  next_pose_ = optimizer_->current_pose();
  next_landmarks_ = optimizer_->landmarks();
  earlier_segments_ = optimizer_counters();
  optimizer_.reset();
  ++counters_.segments;
}

void OptimizerNode::begin_problem(double t_s) {
  optimizer_ = std::make_unique<map_optimizer::MapOptimizer>(options_.optimizer, next_pose_, t_s);
  next_priors_ = 0;
  for (const map_optimizer::LandmarkSolution& l : next_landmarks_) {
    if (optimizer_->add_landmark_prior(l.id, l.mean, l.cov, l.observations)) {
      ++next_priors_;
    } else {
      optimizer_->set_landmark_guess(l.id, l.mean);  // no covariance: a first estimate only
    }
  }
  schedule_.emplace(options_.schedule, t_s);
  if (next_priors_ < next_landmarks_.size()) {
    std::fprintf(stderr,
                 "map_optimizer: WARN: %zu landmarks had no covariance (a rank-deficient last solve): they start "
                 "from their position only and leave the map until seen again\n",
                 next_landmarks_.size() - next_priors_);
  }
}

void OptimizerNode::restart_at_new_time() {
  std::lock_guard<std::mutex> lock(state_mutex_);
  if (!optimizer_) return;
  rebase_keyframes_ = optimizer_->keyframes();  // kept to the new time by the next input (step())
  end_problem(false);
  rebase_pending_ = true;
  last_t_s_ = std::numeric_limits<double>::lowest();  // the next input's time, however far back
  std::fprintf(stderr,
               "map_optimizer: WARN: the samples' time went back (after a jump of over max_stamp_jump_s that their "
               "stamps do not follow: a wrong clock or a hostile sender): a new problem from the current pose at their "
               "time, %zu landmarks as priors\n",
               next_landmarks_.size());
}

void OptimizerNode::begin_problem_after_rebase(double t_s) {
  // The keyframes before the new time stay (written out), the ones after it
  // (the jump) go, and the new problem starts at the newest kept.
  const std::uint64_t old_epoch_ns = epoch_ns_;
  epoch_ns_ = inbox_.epoch_ns();  // the inbox's new one
  const std::uint64_t now_ns = slam_node::to_stamp_ns(t_s, epoch_ns_);
  next_pose_ = options_.initial_pose;
  last_emitted_ns_.reset();
  for (const map_optimizer::Keyframe& k : rebase_keyframes_) {
    const std::uint64_t stamp = slam_node::to_stamp_ns(k.t_s, old_epoch_ns);
    if (stamp >= now_ns) break;
    next_pose_ = k.pose;
    emit_keyframe(stamp, k.pose);
  }
  rebase_keyframes_.clear();
  rebase_pending_ = false;
  begin_problem(t_s);
}

void OptimizerNode::emit_keyframes() {
  for (const map_optimizer::Keyframe& k : optimizer_->keyframes()) {
    const std::uint64_t stamp = slam_node::to_stamp_ns(k.t_s, epoch_ns_);
    if (!last_emitted_ns_ || stamp > *last_emitted_ns_) emit_keyframe(stamp, k.pose);
  }
}

void OptimizerNode::emit_keyframe(std::uint64_t stamp_ns, const slam::Pose2& pose) {
  if (keyframe_sink_) keyframe_sink_(stamp_ns, pose);
  last_emitted_ns_ = stamp_ns;
}

map_optimizer::OptimizerCounters OptimizerNode::optimizer_counters() const {
  map_optimizer::OptimizerCounters c = earlier_segments_;
  if (optimizer_) c += optimizer_->counters();
  return c;
}

void OptimizerNode::collect_whole(bool wait) {
  if (!whole_job_.valid()) return;
  if (!wait && whole_job_.wait_for(std::chrono::seconds(0)) != std::future_status::ready) return;
  const BackgroundWhole job = whole_job_.get();
  optimizer_->adopt(job.solution);
  schedule_->solved(map_optimizer::SolveKind::kWhole, job.due_t_s, job.cpu_s);
  background_cpu_s_ += job.cpu_s;
  ++counters_.whole_solves;
  counters_.solve_time_s += job.solution.summary.solve_time_s;
  counters_.cpu_time_s = thread_cpu_seconds() - cpu_start_s_ + background_cpu_s_;
  publish(job.solution.summary, true);
}

void OptimizerNode::solve(bool whole) {
  const map_optimizer::SolveSummary s =
      whole ? optimizer_->solve() : optimizer_->solve(options_.schedule.window_keyframes);
  if (whole) {
    optimizer_->compute_landmark_covariances();
    ++counters_.whole_solves;
    dirty_ = false;
  } else {
    ++counters_.window_solves;
  }
  counters_.solve_time_s += s.solve_time_s;
  counters_.cpu_time_s = thread_cpu_seconds() - cpu_start_s_ + background_cpu_s_;
  publish(s, whole);
}

void OptimizerNode::publish(const map_optimizer::SolveSummary& s, bool whole) {
  msg::OptimisedMap& m = map_;
  m.header().stamp_ns(slam_node::to_stamp_ns(last_t_s_, epoch_ns_));
  m.header().frame_id("map");
  m.current_pose(slam_node::to_pose_msg(optimizer_->current_pose()));
  const std::vector<map_optimizer::Keyframe>& keyframes = optimizer_->keyframes();
  m.keyframe_count(static_cast<std::uint32_t>(keyframes.size()));
  // All keyframes, or an even stride ending at the newest.
  const std::size_t n = keyframes.size();
  const std::size_t limit = static_cast<std::size_t>(options_.published_keyframes);
  const std::size_t stride = n <= limit ? 1 : (n + limit - 2) / (limit - 1);
  std::vector<msg::OptimisedKeyframe>& out = m.keyframes();
  out.clear();
  for (std::size_t i = (n - 1) % stride; i < n; i += stride) {
    msg::OptimisedKeyframe k;
    k.stamp_ns(slam_node::to_stamp_ns(keyframes[i].t_s, epoch_ns_));
    k.pose(slam_node::to_pose_msg(keyframes[i].pose));
    out.push_back(k);
  }
  std::vector<msg::OptimisedLandmark>& landmarks = m.landmarks();
  landmarks.clear();
  for (const map_optimizer::LandmarkSolution& l : optimizer_->landmarks()) {
    msg::OptimisedLandmark o;
    o.landmark_id(l.id);
    o.x_m(l.mean.x());
    o.y_m(l.mean.y());
    o.cov_xx_m2(l.cov(0, 0));
    o.cov_xy_m2(l.cov(0, 1));
    o.cov_yy_m2(l.cov(1, 1));
    o.observations(static_cast<std::uint32_t>(l.observations));
    landmarks.push_back(o);
  }
  m.whole_problem(whole);
  m.converged(s.converged);
  m.iterations(static_cast<std::uint32_t>(s.iterations));
  m.initial_cost(s.initial_cost);
  m.final_cost(s.final_cost);
  m.solve_time_s(s.solve_time_s);
  m.cpu_time_s(counters_.cpu_time_s);
  m.keyframes_free(static_cast<std::uint32_t>(s.keyframes_free));
  m.residuals(static_cast<std::uint32_t>(s.residuals));
  m.odometry_sequence(last_odometry_seq_);
  m.observation_sequence(last_observation_seq_);
  if (writer_->publish(m)) ++counters_.maps_published;
}

void OptimizerNode::log_status() const {
  const OptimizerNodeCounters c = counters();
  std::lock_guard<std::mutex> lock(state_mutex_);
  const map_optimizer::OptimizerCounters o = optimizer_counters();
  std::fprintf(stderr,
               "map_optimizer: odometry %llu, observations %llu, map states %llu, malformed %llu; keyframes %zu (in the "
               "problem %zu, problems begun anew %llu), "
               "factors from %zu observations (%zu invalid), %llu keyframes started at the filter's pose; solves %llu "
               "window / %llu whole, published %llu; CPU %.2f s (Ceres %.2f s)\n",
               static_cast<unsigned long long>(c.odometry_received),
               static_cast<unsigned long long>(c.observations_received),
               static_cast<unsigned long long>(c.map_states_received), static_cast<unsigned long long>(c.malformed),
               o.keyframes, optimizer_ ? optimizer_->keyframes().size() : std::size_t{0},
               static_cast<unsigned long long>(c.segments), o.observations, o.observations_invalid,
               static_cast<unsigned long long>(c.guesses_from_filter), static_cast<unsigned long long>(c.window_solves),
               static_cast<unsigned long long>(c.whole_solves), static_cast<unsigned long long>(c.maps_published),
               c.cpu_time_s, c.solve_time_s);
}

}  // namespace pixyslam::map_optimizer_node
