#pragma once

#include <cstdint>
#include <deque>
#include <functional>
#include <future>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <utility>

#include "landmark_observation.h"
#include "map_state.h"
#include "odometry.h"
#include "optimised_map.h"
#include "pixyslam/dds/endpoints.h"
#include "pixyslam/diagnostics/diagnostics_publisher.h"
#include "pixyslam/map_optimizer/map_optimizer.h"
#include "pixyslam/slam/sensor_queue.h"
#include "pixyslam/slam_node/sensor_inbox.h"

namespace pixyslam::map_optimizer_node {

// Everything the map_optimizer process is configured with (config/map_optimizer.yaml).
struct OptimizerNodeOptions {
  map_optimizer::MapOptimizerOptions optimizer;  // motion and observation noise from the filter's config
  slam::Pose2 initial_pose = slam::Pose2::Zero();  // the estimator's start pose (its config)
  slam::SensorQueueOptions queue;                // the estimator's delays
  bool use_detection_sigmas = true;              // as the estimator
  map_optimizer::SolveScheduleOptions schedule;  // window and whole-problem solves as the data come
  int published_keyframes = 2000;                // OptimisedMap.keyframes at most (<= 8192)
  // `optimizer.max_keyframes`: a problem that reaches this many keyframes is
  // solved a last time and replaced by a new one that starts at the current
  // pose with every landmark as a Gaussian prior (its marginal), so a station
  // that runs for days holds a bounded problem (~13 KB a keyframe). 0: unbounded.
  std::size_t max_keyframes = 20000;
  double status_period_s = 10.0;                 // counters to the log every so often (0: never)
  dds::DdsOptions dds;
};

// The node's own `optimizer:` keys (beside map_optimizer_parameters()).
const parameters::Table<OptimizerNodeOptions>& optimizer_node_parameters();

// `--set` assignments "optimizer.KEY=V", "dds.KEY=V" applied and validated;
// the DDS settings resolved (the environment, then these). Throws
// std::invalid_argument / config::ConfigError naming the assignment.
void apply_overrides(OptimizerNodeOptions& options, const std::vector<std::string>& assignments);

// The `optimizer:` and `dds:` parameters, for --help.
std::string help_text();
// The `optimizer:` and `dds:` settings as YAML, for --verbose (the noise models
// are the filter_config's).
std::string to_yaml(const OptimizerNodeOptions& options);

// Reads the file: `filter_config` (the estimator's config, relative to this
// file: its `filter:` noise and limits, `estimator.initial_pose`, delays and
// detection sigmas, so both solve the same models), `optimizer:` and `dds:`.
// Errors are config::ConfigError naming the file and key.
OptimizerNodeOptions read_optimizer_node_options_file(const std::string& path);

struct OptimizerNodeCounters {
  std::uint64_t odometry_received = 0;
  std::uint64_t observations_received = 0;
  std::uint64_t map_states_received = 0;
  std::uint64_t malformed = 0;          // samples that did not decode (dropped), all readers
  std::uint64_t seq_jumps = 0;
  std::uint64_t window_solves = 0;
  std::uint64_t whole_solves = 0;
  std::uint64_t maps_published = 0;
  std::uint64_t guesses_from_filter = 0;  // keyframes started from the filter's pose
  std::uint64_t step_errors = 0;          // inputs the optimiser threw on: dropped
  std::uint64_t segments = 0;             // problems begun anew at max_keyframes
  double cpu_time_s = 0.0;                // the optimiser thread's CPU time
  double solve_time_s = 0.0;              // Ceres' time over all solves
};

// The map optimiser process: Odometry, LandmarkObservation and the estimator's
// MapState in; OptimisedMap out. One thread feeds the core in stamp order
// (SensorQueue, as the estimator) and solves the newest window every
// window_period_s of data; every whole_period_s a copy of the whole problem
// (MapOptimizer::snapshot) is solved in the background, with the landmarks'
// marginal covariances, while the windows go on, and adopted when done (one due
// while the last still runs starts at the first input after it; whole_max_duty
// spaces them as they grow); at the end the whole problem once more, unless a
// background solve already covered every input. It publishes after each solve.
// MapStates give the keyframes' starting poses (the filter's pose at a frame's
// stamp, when it has arrived) and new landmarks' starting positions.
class OptimizerNode {
 public:
  explicit OptimizerNode(const OptimizerNodeOptions& options);
  ~OptimizerNode();
  OptimizerNode(const OptimizerNode&) = delete;
  OptimizerNode& operator=(const OptimizerNode&) = delete;

  void start();
  // Drains what is queued, solves the whole problem, publishes and joins.
  void stop();

  OptimizerNodeCounters counters() const;
  // The last published map: its keyframes thinned to published_keyframes.
  msg::OptimisedMap latest_map() const;

  // Every keyframe of a finished problem, in time order, once, on the node's
  // thread: those of a segment when the next begins (max_keyframes), the last
  // problem's at stop() after its final solve. Set before start().
  using KeyframeSink = std::function<void(std::uint64_t stamp_ns, const slam::Pose2& pose)>;
  void set_keyframe_sink(KeyframeSink sink) { keyframe_sink_ = std::move(sink); }

 private:
  void on_map_state(const msg::MapState& m);
  void loop();
  void step(const slam::SensorInput& input);
  void solve(bool whole);
  // The background whole solve, if one is running: adopted and published when
  // done (or, with `wait`, once done).
  void collect_whole(bool wait);
  // At max_keyframes: the whole problem solved and published a last time, then
  // a new one from the current pose at `odometry`'s time, the landmarks as priors.
  void start_segment(const slam::OdometrySample& odometry);
  // The problem solved a last time, its keyframes emitted (if `emit`), its pose
  // and landmarks kept for the next; optimizer_ empty.
  void end_problem(bool emit = true);
  // A new problem at t_s from what end_problem() kept, the landmarks as priors.
  void begin_problem(double t_s);
  // After SensorInbox's rebase: the next input begins a new problem.
  void restart_at_new_time();
  // That new problem, at the first input's time t_s.
  void begin_problem_after_rebase(double t_s);
  // The current problem's keyframes after the last emitted to the sink (a new
  // problem begins with a keyframe at the time the last one ended).
  void emit_keyframes();
  // One keyframe to the sink; it is the last emitted.
  void emit_keyframe(std::uint64_t stamp_ns, const slam::Pose2& pose);
  // The core's counters over every segment.
  map_optimizer::OptimizerCounters optimizer_counters() const;
  void publish(const map_optimizer::SolveSummary& s, bool whole);
  void log_status() const;
  diagnostics::Snapshot diagnostics_snapshot() const;

  OptimizerNodeOptions options_;
  std::unique_ptr<dds::Participant> participant_;
  std::unique_ptr<dds::Writer<msg::OptimisedMap>> writer_;
  std::unique_ptr<dds::Reader<msg::Odometry>> odometry_reader_;
  std::unique_ptr<dds::Reader<msg::LandmarkObservation>> observation_reader_;
  std::unique_ptr<dds::Reader<msg::MapState>> map_state_reader_;
  std::unique_ptr<diagnostics::DiagnosticsPublisher> diagnostics_;

  slam_node::SensorInbox inbox_;  // DDS callbacks -> the optimiser thread, in stamp order
  std::mutex run_mutex_;
  bool stopping_ = false;
  std::thread thread_;

  // The filter's recent poses by stamp and its newest map (DDS thread -> loop).
  mutable std::mutex filter_mutex_;
  std::deque<std::pair<std::uint64_t, slam::Pose2>> filter_poses_;
  std::vector<std::pair<int, Eigen::Vector2d>> filter_landmarks_;

  // Loop state (read by others under state_mutex_).
  mutable std::mutex state_mutex_;
  std::unique_ptr<map_optimizer::MapOptimizer> optimizer_;
  KeyframeSink keyframe_sink_;
  slam::Pose2 next_pose_ = slam::Pose2::Zero();                  // end_problem() -> begin_problem()
  std::vector<map_optimizer::LandmarkSolution> next_landmarks_;
  std::size_t next_priors_ = 0;
  bool rebase_pending_ = false;                              // restart_at_new_time() -> step()
  std::vector<map_optimizer::Keyframe> rebase_keyframes_;     // the ended problem's, to the new time
  std::optional<std::uint64_t> last_emitted_ns_;
  map_optimizer::OptimizerCounters earlier_segments_;  // the counters of the problems before optimizer_
  std::uint64_t epoch_ns_ = 0;  // the inbox's, from the first input on
  double last_t_s_ = 0.0;
  std::optional<map_optimizer::SolveSchedule> schedule_;  // from the first input's time
  bool dirty_ = false;  // input since the last whole solve began (in the background or not)
  struct BackgroundWhole {
    map_optimizer::WholeSolution solution;
    double cpu_s = 0.0;
    double due_t_s = 0.0;
  };
  std::future<BackgroundWhole> whole_job_;
  double background_cpu_s_ = 0.0;  // the background solves' CPU time
  std::uint64_t last_odometry_seq_ = 0;
  std::uint64_t last_observation_seq_ = 0;
  double cpu_start_s_ = 0.0;
  msg::OptimisedMap map_;
  OptimizerNodeCounters counters_;
};

}  // namespace pixyslam::map_optimizer_node
