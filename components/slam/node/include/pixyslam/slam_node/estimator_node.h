#pragma once

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <utility>
#include <variant>
#include <vector>

#include "landmark_observation.h"
#include "map_state.h"
#include "odometry.h"
#include "pixyslam/dds/endpoints.h"
#include "pixyslam/diagnostics/diagnostics_publisher.h"
#include "pixyslam/slam/fastslam2.h"
#include "pixyslam/slam/sensor_queue.h"
#include "pixyslam/slam_node/estimator_options.h"
#include "pixyslam/slam/map_checkpoint.h"
#include "pixyslam/slam_node/sensor_inbox.h"

namespace pixyslam::slam_node {

struct EstimatorCounters {
  std::uint64_t odometry_received = 0;
  std::uint64_t observations_received = 0;
  std::uint64_t odometry_lost = 0;       // seq gaps seen by the readers
  std::uint64_t observations_lost = 0;
  std::uint64_t odometry_malformed = 0;  // samples that did not decode (dropped)
  std::uint64_t observations_malformed = 0;
  std::uint64_t seq_jumps = 0;           // implausible seq jumps (restart, hostile writer)
  std::uint64_t other_robot_samples = 0; // sensor samples of other robots (header.robot_id), ignored
  std::uint64_t steps = 0;               // filter steps (= MapStates published)
  std::uint64_t map_states_published = 0;
  std::uint64_t samples_late = 0;
  std::uint64_t samples_reordered = 0;
  std::uint64_t samples_ahead = 0;          // dropped: a stamp jump (max_stamp_jump_s) no sample confirmed
  std::uint64_t time_rebases = 0;           // the time went back to the samples' (a wrong jump undone):
                                            // the filter restarted from its estimate
  std::uint64_t samples_flood_dropped = 0;  // dropped: max_held_samples were waiting
  std::uint64_t truth_invalid = 0;          // GroundTruth poses not finite or beyond 1e6 m: not a start pose
  std::uint64_t step_errors = 0;            // filter steps that threw: the sample is dropped
  std::uint64_t checkpoints_written = 0;
  std::uint64_t checkpoint_errors = 0;
  bool resumed = false;                  // started from a checkpoint
};

// The SLAM estimator process: subscribes to Odometry and LandmarkObservation,
// feeds the FastSLAM 2.0 core in timestamp order from ONE filter thread (DDS
// callbacks only enqueue) and publishes a MapState after every filter step.
// The filter clock starts at the first sample's stamp. start() runs the filter
// thread; stop() drains what is queued, publishes the last state and joins.
// Thread-safe.
class EstimatorNode {
 public:
  explicit EstimatorNode(const EstimatorOptions& options);
  ~EstimatorNode();
  EstimatorNode(const EstimatorNode&) = delete;
  EstimatorNode& operator=(const EstimatorNode&) = delete;

  void start();
  void stop();

  EstimatorCounters counters() const;
  // A copy of the latest MapState (for the status line and for tests).
  msg::MapState latest_map_state() const;
  // Called on the filter thread after every step with the MapState's stamp (ns)
  // and mean pose; nothing is kept here (slam_estimator --out-dir streams them to
  // trajectory.csv). Set before start(); it must not throw.
  using StepObserver = std::function<void(std::uint64_t stamp_ns, const slam::Pose2& mean)>;
  void set_step_observer(StepObserver observer) { step_observer_ = std::move(observer); }

 private:
  void filter_loop();
  void step(const slam::SensorInput& input);
  // Names a sample older than the filter time (FilterCounters::odometry_out_of_order,
  // frames_late, frames_out_of_order; their counts before the step in late_before) and how it
  // was applied: the first ten, then every hundredth.
  void warn_if_late(const slam::SensorInput& input, double filter_time_s, const slam::FilterCounters& late_before);
  // Logs the first detection dropped for an id outside filter.association.landmark_ids
  // (a pole added to the pixy bridge's table but not here loses every sighting).
  void warn_if_unknown_id(const slam::SensorInput& input, const slam::FilterCounters& before);
  // The filter, from the checkpoint when there is a fresh one (state_mutex_ held).
  void create_filter(double first_t_s);
  // After SensorInbox's rebase to new_time_ns: the filter again, its time set
  // by the next input, from its state before the jump when it had stepped into
  // the future (its pose moved on by the time since, as a checkpoint resume),
  // else from its state now (the jump never reached it).
  void restart_filter_at_new_time(std::uint64_t new_time_ns);
  // The configured start pose, or the robot's first ground truth (estimator.initial_pose.source).
  slam::Pose2 initial_pose();
  void publish_map_state();  // state_mutex_ held
  void write_checkpoint(bool final);
  void log_status() const;
  diagnostics::Snapshot diagnostics_snapshot() const;

  EstimatorOptions options_;
  std::unique_ptr<dds::Participant> participant_;
  std::unique_ptr<dds::Writer<msg::MapState>> map_writer_;
  mutable std::atomic<bool> warned_other_robot_{false};
  // initial_pose.source ground_truth: the first GroundTruth's pose.
  std::mutex truth_mutex_;
  std::condition_variable truth_cv_;
  std::optional<slam::Pose2> first_truth_;
  std::atomic<std::uint64_t> truth_invalid_{0};
  std::optional<slam::Pose2> start_pose_;  // filter thread only
  std::unique_ptr<dds::Reader<msg::GroundTruth>> truth_reader_;
  std::unique_ptr<dds::Reader<msg::Odometry>> odometry_reader_;
  std::unique_ptr<dds::Reader<msg::LandmarkObservation>> observation_reader_;
  std::unique_ptr<diagnostics::DiagnosticsPublisher> diagnostics_;

  SensorInbox inbox_;  // DDS callbacks -> the filter thread, in stamp order
  std::mutex run_mutex_;
  bool stopping_ = false;
  std::thread thread_;

  // Filter-thread state (read by others under state_mutex_).
  mutable std::mutex state_mutex_;
  std::unique_ptr<slam::FastSlam2> filter_;
  std::uint64_t last_odometry_seq_ = 0;
  std::uint64_t last_observation_seq_ = 0;
  msg::MapState map_state_;
  StepObserver step_observer_;
  EstimatorCounters counters_;
  std::optional<slam::MapCheckpoint> checkpoint_;  // read at start, used by create_filter()
  std::string checkpoint_source_;                  // where checkpoint_ came from, for the log
  // The filter before its last step that moved the time on by more than
  // max_stamp_jump_s: what a rebase (that jump undone) restarts from.
  std::optional<slam::MapCheckpoint> before_jump_;
  std::uint64_t last_checkpoint_ns_ = 0;
  std::uint64_t last_published_ns_ = 0;
  bool latest_published_ = true;  // map_state_ went out (map_state_period_s)
  bool unknown_id_logged_ = false;
};

}  // namespace pixyslam::slam_node
