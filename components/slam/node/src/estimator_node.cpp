#include "pixyslam/slam_node/estimator_node.h"

#include <chrono>
#include <cstdio>
#include <filesystem>

#include "pixyslam/config/yaml_reader.h"

#include "pixyslam/slam_node/map_state_conversions.h"

namespace pixyslam::slam_node {

EstimatorNode::EstimatorNode(const EstimatorOptions& options)
    : options_(options), inbox_(options.queue, options.use_detection_sigmas) {
  slam::validate(options_.filter);
  if (!options_.checkpoint.file.empty()) {
    // A directory (or device, FIFO) can be neither read nor replaced by rename():
    // a configuration error now, not a failed write every period.
    std::error_code ec;
    const std::filesystem::file_status st = std::filesystem::status(options_.checkpoint.file, ec);
    if (std::filesystem::exists(st) && !std::filesystem::is_regular_file(st)) {
      throw config::ConfigError(options_.checkpoint.file + ": not a regular file (" +
                                (std::filesystem::is_directory(st) ? "a directory" : "not a plain file") +
                                "; estimator.checkpoint.file or --checkpoint)");
    }
  }
  participant_ = std::make_unique<dds::Participant>(options_.dds, "slam_estimator");
  map_writer_ = std::make_unique<dds::Writer<msg::MapState>>(*participant_);
  // Only this robot's sensors (dds.robot_id): several robots may share the domain.
  odometry_reader_ = std::make_unique<dds::Reader<msg::Odometry>>(
      *participant_, [this](const msg::Odometry& m) { inbox_.push(m); }, options_.dds.robot_id);
  observation_reader_ = std::make_unique<dds::Reader<msg::LandmarkObservation>>(
      *participant_, [this](const msg::LandmarkObservation& m) { inbox_.push(m); }, options_.dds.robot_id);
  if (options_.initial_pose_source == "ground_truth") {
    truth_reader_ = std::make_unique<dds::Reader<msg::GroundTruth>>(
        *participant_,
        [this](const msg::GroundTruth& m) {
          const slam::Pose2 pose(m.pose().x_m(), m.pose().y_m(), m.pose().theta_rad());
          // Any participant can send one: a start pose must be finite and on a map.
          if (!pose.allFinite() || pose.head<2>().cwiseAbs().maxCoeff() > 1e6) {
            ++truth_invalid_;
            return;
          }
          std::lock_guard<std::mutex> lock(truth_mutex_);
          if (first_truth_) return;
          first_truth_ = pose;
          truth_cv_.notify_all();
        },
        options_.dds.robot_id);
  }
  diagnostics_ = std::make_unique<diagnostics::DiagnosticsPublisher>(
      *participant_, "slam_estimator", options_.dds.diagnostics_period_s, [this] { return diagnostics_snapshot(); });
  const CheckpointOptions& k = options_.checkpoint;
  if (!k.file.empty() && k.resume) {
    if (!std::filesystem::exists(k.file)) {
      std::fprintf(stderr, "slam_estimator: no checkpoint at %s: starting from scratch\n", k.file.c_str());
    } else {
      try {
        checkpoint_ = slam::read_map_checkpoint(k.file);
        checkpoint_source_ = k.file;
      } catch (const config::ConfigError& e) {
        std::fprintf(stderr, "slam_estimator: checkpoint unusable, starting from scratch: %s\n", e.what());
      }
    }
  }
}

EstimatorNode::~EstimatorNode() {
  stop();
  diagnostics_.reset();
  // Readers first: no callback may run into a half-destroyed node.
  truth_reader_.reset();
  odometry_reader_.reset();
  observation_reader_.reset();
  map_writer_.reset();
  participant_.reset();
}

void EstimatorNode::start() {
  std::lock_guard<std::mutex> lock(run_mutex_);
  if (thread_.joinable() || stopping_) return;
  thread_ = std::thread([this] { filter_loop(); });
}

void EstimatorNode::stop() {
  {
    std::lock_guard<std::mutex> lock(run_mutex_);
    stopping_ = true;
  }
  inbox_.stop();
  if (!thread_.joinable()) return;
  thread_.join();
  {
    std::lock_guard<std::mutex> lock(state_mutex_);
    if (filter_ && !options_.checkpoint.file.empty()) write_checkpoint(true);
  }
  diagnostics_->stop();
}

diagnostics::Snapshot EstimatorNode::diagnostics_snapshot() const {
  const EstimatorCounters c = counters();
  if (c.odometry_received == 0 && c.other_robot_samples > 0 && !warned_other_robot_.exchange(true)) {
    std::fprintf(stderr,
                 "slam_estimator: only other robots' sensor samples arrive (%llu so far), none of robot '%s': is "
                 "dds.robot_id the same as the bridges'?\n",
                 static_cast<unsigned long long>(c.other_robot_samples), options_.dds.robot_id.c_str());
  }
  std::lock_guard<std::mutex> lock(state_mutex_);
  const slam::FilterCounters f = filter_ ? filter_->counters() : slam::FilterCounters{};
  diagnostics::Snapshot s;
  s.counters = {{"odometry_received", c.odometry_received, false},
                {"odometry_lost", c.odometry_lost, true},
                {"observations_received", c.observations_received, false},
                {"observations_lost", c.observations_lost, true},
                {"odometry_malformed", c.odometry_malformed, true},
                {"observations_malformed", c.observations_malformed, true},
                {"seq_jumps", c.seq_jumps, true},
                {"other_robot_samples", c.other_robot_samples, false},
                {"steps", c.steps, false},
                // A late frame is applied at its stamp (frames_late); what could not be
                // warns as odometry_out_of_order / frames_out_of_order.
                {"samples_late", c.samples_late, false},
                {"samples_reordered", c.samples_reordered, false},
                {"samples_ahead", c.samples_ahead, true},
                {"time_rebases", c.time_rebases, true},
                {"samples_flood_dropped", c.samples_flood_dropped, true},
                {"truth_invalid", c.truth_invalid, true},
                {"step_errors", c.step_errors, true},
                {"odometry_invalid", f.odometry_invalid, true},
                {"odometry_out_of_order", f.odometry_out_of_order, true},
                {"odometry_no_data", f.odometry_no_data, true},
                {"control_timeouts", f.control_timeouts, false},
                {"frames_invalid", f.frames_invalid, true},
                {"frames_late", f.frames_late, false},
                {"frames_out_of_order", f.frames_out_of_order, true},
                {"observations_used", f.observations_used, false},
                {"observations_new_landmark", f.observations_new_landmark, false},
                {"observations_gated", f.observations_gated, true},
                {"observations_invalid", f.observations_invalid, true},
                {"observations_over_map_limit", f.observations_over_map_limit, true},
                {"observations_unknown_id", f.observations_unknown_id, true},
                {"landmark_slots_recycled", f.landmark_slots_recycled, false},
                {"resamples", f.resamples, false},
                {"landmarks", map_state_.landmarks().size(), false},
                {"checkpoints_written", c.checkpoints_written, false},
                {"checkpoint_errors", c.checkpoint_errors, true},
                {"resumed_from_checkpoint", c.resumed ? 1u : 0u, false}};
  return s;
}

EstimatorCounters EstimatorNode::counters() const {
  std::lock_guard<std::mutex> lock(state_mutex_);
  EstimatorCounters c = counters_;
  c.odometry_received = odometry_reader_->received();
  c.observations_received = observation_reader_->received();
  c.odometry_lost = odometry_reader_->lost();
  c.observations_lost = observation_reader_->lost();
  c.odometry_malformed = odometry_reader_->malformed() + odometry_reader_->callback_errors();
  c.observations_malformed = observation_reader_->malformed() + observation_reader_->callback_errors();
  c.seq_jumps = odometry_reader_->seq_jumps() + observation_reader_->seq_jumps();
  c.other_robot_samples = odometry_reader_->other_robot() + observation_reader_->other_robot();
  const slam::SensorQueueCounters q = inbox_.queue_counters();
  c.samples_late = q.late;
  c.samples_reordered = q.reordered;
  c.samples_ahead = q.ahead;
  c.time_rebases = q.rebases;
  c.truth_invalid = truth_invalid_.load();
  c.samples_flood_dropped = q.overflow;
  return c;
}

msg::MapState EstimatorNode::latest_map_state() const {
  std::lock_guard<std::mutex> lock(state_mutex_);
  return map_state_;
}

namespace {
// Samples older than the filter time when they came (the status line's "late").
std::uint64_t late_samples(const slam::FilterCounters& f) {
  return f.odometry_out_of_order + f.frames_late + f.frames_out_of_order;
}
}  // namespace

void EstimatorNode::filter_loop() {
  using Clock = std::chrono::steady_clock;
  auto next_status = Clock::now() + std::chrono::duration<double>(options_.status_period_s);
  for (;;) {
    const SensorInbox::Ready ready = inbox_.wait_ready();
    const bool stopping = ready.stopping;
    if (ready.rebased) restart_filter_at_new_time(ready.rebased_to_ns);
    step_each(ready.inputs, [this](const slam::SensorInput& input) { step(input); }, "slam_estimator", state_mutex_,
              counters_.step_errors);

    if (options_.status_period_s > 0.0 && Clock::now() >= next_status) {
      log_status();
      next_status = Clock::now() + std::chrono::duration<double>(options_.status_period_s);
    }
    if (stopping) break;
  }
  {
    std::lock_guard<std::mutex> lock(state_mutex_);
    if (!latest_published_) publish_map_state();  // the last state always goes out
  }
  log_status();
}

void EstimatorNode::step(const slam::SensorInput& input) {
  // Only this thread creates the filter, so filter_ is read without the lock here: the wait for
  // the first ground truth must not hold state_mutex_ (diagnostics and status read under it).
  if (!filter_ && !start_pose_) start_pose_ = initial_pose();
  std::lock_guard<std::mutex> lock(state_mutex_);
  const auto begin = std::chrono::steady_clock::now();
  const bool fresh = !filter_;  // its time is set by this input
  if (fresh) create_filter(slam::input_time(input));
  const double filter_time_s = filter_->time_s();
  if (!fresh && slam::input_time(input) > filter_time_s + options_.queue.max_stamp_jump_s) {
    before_jump_ = slam::checkpoint_of(*filter_, map_state_.header().stamp_ns());
  }
  const slam::FilterCounters late_before = filter_->counters();
  if (const auto* odometry = std::get_if<slam::OdometryInput>(&input)) {
    filter_->add_odometry(odometry->sample);
    last_odometry_seq_ = odometry->seq;
  } else {
    const auto& observation = std::get<slam::ObservationInput>(input);
    filter_->add_observations(observation.frame);
    last_observation_seq_ = observation.seq;
  }
  warn_if_late(input, filter_time_s, late_before);
  warn_if_unknown_id(input, late_before);
  StepInfo info;
  info.epoch_ns = inbox_.epoch_ns();
  info.odometry_seq = last_odometry_seq_;
  info.observation_seq = last_observation_seq_;
  info.samples_late = inbox_.queue_counters().late;
  info.update_time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - begin).count();
  fill_map_state(*filter_, info, options_.published_particle_poses, options_.landmarks == "mixture",
                 map_state_);
  const msg::Pose2D& mean = map_state_.mean_pose();
  if (step_observer_) {
    step_observer_(map_state_.header().stamp_ns(), slam::Pose2(mean.x_m(), mean.y_m(), mean.theta_rad()));
  }
  ++counters_.steps;
  const std::uint64_t stamp = map_state_.header().stamp_ns();
  const auto period_ns = static_cast<std::uint64_t>(options_.map_state_period_s * 1e9);
  latest_published_ = false;
  if (period_ns == 0 || counters_.map_states_published == 0 || stamp >= last_published_ns_ + period_ns) {
    publish_map_state();
  }
  if (!options_.checkpoint.file.empty() &&
      (counters_.checkpoints_written + counters_.checkpoint_errors == 0 ||
       stamp >= last_checkpoint_ns_ + static_cast<std::uint64_t>(options_.checkpoint.period_s * 1e9))) {
    write_checkpoint(false);
  }
}

void EstimatorNode::warn_if_late(const slam::SensorInput& input, double filter_time_s,
                                 const slam::FilterCounters& late_before) {
  const slam::FilterCounters& f = filter_->counters();
  const std::uint64_t n = late_samples(f);
  if (n == late_samples(late_before)) return;
  // The first ten, then every hundredth: a clock step could make every sample late.
  if (n > 10 && n % 100 != 0) return;
  const char* what = "odometry";
  const char* how = "a camera frame was released without it): applied at the filter time";
  if (std::holds_alternative<slam::ObservationInput>(input)) {
    what = "a camera frame";
    how = f.frames_late != late_before.frames_late
              ? "newer odometry was released without it): applied at its stamp"
              : "older than the last frame): applied at the filter time";
  }
  std::fprintf(stderr,
               "slam_estimator: %s stamped %.3f s came after the filter had reached %.3f s (%.3f s late; %s "
               "(%llu so far)\n",
               what, slam::input_time(input), filter_time_s, filter_time_s - slam::input_time(input), how,
               static_cast<unsigned long long>(n));
}

void EstimatorNode::warn_if_unknown_id(const slam::SensorInput& input, const slam::FilterCounters& before) {
  if (unknown_id_logged_ || filter_->counters().observations_unknown_id == before.observations_unknown_id) return;
  const auto* observation = std::get_if<slam::ObservationInput>(&input);
  if (observation == nullptr) return;
  const slam::IdRanges ids = slam::parse_landmark_ids(options_.filter.landmark_ids);
  for (const slam::RangeBearing& d : observation->frame.detections) {
    if (slam::contains_id(ids, d.landmark_id)) continue;
    std::string list;
    for (const std::string& item : options_.filter.landmark_ids) list += (list.empty() ? "" : ", ") + item;
    std::fprintf(stderr,
                 "slam_estimator: WARN: landmark id %d is not in filter.association.landmark_ids [%s]: its sightings "
                 "are dropped and counted (observations_unknown_id); a pole of yours? add its id there (logged "
                 "once)\n",
                 d.landmark_id, list.c_str());
    unknown_id_logged_ = true;
    return;
  }
}

void EstimatorNode::publish_map_state() {
  latest_published_ = true;
  last_published_ns_ = map_state_.header().stamp_ns();
  if (map_writer_->publish(map_state_)) ++counters_.map_states_published;
}

void EstimatorNode::create_filter(double first_t_s) {
  const CheckpointOptions& k = options_.checkpoint;
  if (checkpoint_) {
    const slam::MapCheckpoint& c = *checkpoint_;
    const double gap_s =
        static_cast<double>(static_cast<std::int64_t>(inbox_.epoch_ns() - c.stamp_ns)) * 1e-9 + first_t_s;
    // A checkpoint from the future (another clock, a replayed log) is as unusable as an old one.
    if (gap_s >= -1.0 && gap_s <= k.max_age_s) {
      const slam::PoseGaussian pose =
          slam::resume_pose(c, gap_s, k.max_speed_mps, k.max_turn_rate_radps, options_.filter.control_timeout_s);
      filter_ = std::make_unique<slam::FastSlam2>(options_.filter, pose);
      filter_->set_prior_map(c.landmarks);
      counters_.resumed = true;
      std::fprintf(stderr,
                   "slam_estimator: resumed from %s: %.1f s old, %zu landmarks, pose (%.3f, %.3f, %.3f) "
                   "sd %.2f m / %.2f rad\n",
                   checkpoint_source_.c_str(), gap_s, c.landmarks.size(), pose.mean.x(), pose.mean.y(), pose.mean.z(),
                   std::sqrt(std::max(pose.cov(0, 0), pose.cov(1, 1))), std::sqrt(pose.cov(2, 2)));
    } else {
      std::fprintf(stderr,
                   "slam_estimator: checkpoint %s is %.1f s old (usable: -1 .. %.1f s): starting from scratch\n",
                   k.file.c_str(), gap_s, k.max_age_s);
    }
    checkpoint_.reset();
  }
  if (!filter_) filter_ = std::make_unique<slam::FastSlam2>(options_.filter, *start_pose_);
}

void EstimatorNode::restart_filter_at_new_time(std::uint64_t new_time_ns) {
  std::lock_guard<std::mutex> lock(state_mutex_);
  if (!filter_) return;
  const auto jump_ns = static_cast<std::uint64_t>(options_.queue.max_stamp_jump_s * 1e9);
  const bool stepped_into_future = map_state_.header().stamp_ns() > new_time_ns + jump_ns;
  if (stepped_into_future && before_jump_) {
    // What the filter did after the jump (the held control applied into the
    // future) is dropped with it.
    checkpoint_ = std::move(before_jump_);
  } else {
    checkpoint_ = slam::checkpoint_of(*filter_, new_time_ns);
  }
  before_jump_.reset();
  checkpoint_source_ = stepped_into_future ? "the state before the time jump" : "the state at the time jump";
  filter_.reset();
  last_published_ns_ = 0;  // stamps of the abandoned time: publish and checkpoint at the new one
  last_checkpoint_ns_ = 0;
  std::fprintf(stderr,
               "slam_estimator: WARN: the samples' time went back (after a jump of over max_stamp_jump_s that their "
               "stamps do not follow: a wrong clock or a hostile sender): the filter goes on from %s\n",
               checkpoint_source_.c_str());
}

slam::Pose2 EstimatorNode::initial_pose() {
  if (!truth_reader_) return options_.initial_pose;
  std::unique_lock<std::mutex> lock(truth_mutex_);
  if (truth_cv_.wait_for(lock, std::chrono::duration<double>(options_.initial_pose_wait_s),
                         [this] { return first_truth_.has_value(); })) {
    std::fprintf(stderr, "slam_estimator: start pose from %s's ground truth: (%.3f, %.3f, %.3f)\n",
                 options_.dds.robot_id.c_str(), first_truth_->x(), first_truth_->y(), first_truth_->z());
    return *first_truth_;
  }
  std::fprintf(stderr, "slam_estimator: no ground truth of %s after %.1f s: starting from the configured pose\n",
               options_.dds.robot_id.c_str(), options_.initial_pose_wait_s);
  return options_.initial_pose;
}

void EstimatorNode::write_checkpoint(bool final) {
  const slam::MapCheckpoint c =
      slam::checkpoint_of(*filter_, map_state_.header().stamp_ns());
  try {
    slam::write_map_checkpoint(options_.checkpoint.file, c);
    ++counters_.checkpoints_written;
    last_checkpoint_ns_ = c.stamp_ns;
    if (final) {
      std::fprintf(stderr, "slam_estimator: final checkpoint %s (%zu landmarks)\n",
                   options_.checkpoint.file.c_str(), c.landmarks.size());
    }
  } catch (const std::runtime_error& e) {
    // Logged on the first failure and every 100th after it; the filter goes on.
    if (counters_.checkpoint_errors++ % 100 == 0) std::fprintf(stderr, "slam_estimator: %s\n", e.what());
    last_checkpoint_ns_ = c.stamp_ns;
  }
}

void EstimatorNode::log_status() const {
  const EstimatorCounters c = counters();
  std::lock_guard<std::mutex> lock(state_mutex_);
  const slam::FilterCounters f = filter_ ? filter_->counters() : slam::FilterCounters{};
  std::fprintf(stderr,
               "slam_estimator: odometry %llu (lost %llu), observations %llu (lost %llu), other robots' %llu, "
               "steps %llu, late %llu (frames at their stamp %llu; applied late: odometry %llu, frames %llu), "
               "reordered %llu; detections used %llu, new %llu, gated %llu, "
               "invalid %llu; resamples %llu; landmarks %zu; checkpoints %llu (errors %llu)%s\n",
               static_cast<unsigned long long>(c.odometry_received),
               static_cast<unsigned long long>(c.odometry_lost),
               static_cast<unsigned long long>(c.observations_received),
               static_cast<unsigned long long>(c.observations_lost),
               static_cast<unsigned long long>(c.other_robot_samples),
               static_cast<unsigned long long>(c.steps), static_cast<unsigned long long>(c.samples_late),
               static_cast<unsigned long long>(f.frames_late), static_cast<unsigned long long>(f.odometry_out_of_order),
               static_cast<unsigned long long>(f.frames_out_of_order),
               static_cast<unsigned long long>(c.samples_reordered),
               static_cast<unsigned long long>(f.observations_used),
               static_cast<unsigned long long>(f.observations_new_landmark),
               static_cast<unsigned long long>(f.observations_gated),
               static_cast<unsigned long long>(f.observations_invalid),
               static_cast<unsigned long long>(f.resamples), map_state_.landmarks().size(),
               static_cast<unsigned long long>(c.checkpoints_written),
               static_cast<unsigned long long>(c.checkpoint_errors), c.resumed ? "; resumed" : "");
}

}  // namespace pixyslam::slam_node
