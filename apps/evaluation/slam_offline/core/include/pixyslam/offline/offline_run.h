#pragma once

#include <algorithm>
#include <functional>
#include <string>
#include <vector>

#include "pixyslam/eval/csv_io.h"
#include "pixyslam/eval/trajectory_metrics.h"
#include "pixyslam/parameters/parameters.h"
#include "pixyslam/slam/fastslam2.h"
#include "pixyslam/slam/map_checkpoint.h"
#include "pixyslam/offline/segment_eval.h"

namespace pixyslam::offline {

// Input of one offline run: odometry and frames in any order (merged by time,
// odometry first on equal stamps), the start pose and time, and evaluation truth.
struct RunInput {
  slam::Pose2 initial_pose = slam::Pose2::Zero();
  Eigen::Matrix3d initial_pose_cov = Eigen::Matrix3d::Zero();  // a resume's widened pose (resume_pose)
  std::vector<slam::LandmarkEstimate> prior_map;               // a resume's map (FastSlam2::set_prior_map)
  double start_time_s = 0.0;
  std::vector<slam::OdometrySample> odometry;
  std::vector<slam::ObservationFrame> frames;
  std::vector<eval::TimedPose> truth;           // may be empty
  std::vector<eval::LandmarkPoint> landmarks;   // may be empty
};

struct RunResult {
  std::vector<eval::TimedPose> trajectory;        // after every filter step
  std::vector<Eigen::Matrix3d> covariance;        // pose covariance, one per trajectory step
  std::vector<eval::TimedPose> dead_reckoning;    // odometry alone, same steps
  std::vector<eval::LandmarkRow> landmarks;       // best particle
  slam::FilterCounters counters;
  double wall_time_s = 0.0;
  double cpu_time_s = 0.0;  // this thread's CPU time over the same span (steadier on a shared machine)
  double final_effective_sample_size = 0.0;
};

// This thread's CPU time in seconds (steadier than wall time on a shared machine).
double thread_cpu_seconds();

// Feeds the filter in time order, skipping samples before start_time_s;
// `after_step` (optional) sees the filter after every step.
using StepHook = std::function<void(const slam::FastSlam2& filter, double t_s)>;
RunResult run_filter(const slam::FilterOptions& options, const RunInput& input, const StepHook& after_step = {});

// The input in the filter's order (odometry first on equal stamps): odometry
// before start_time_s becomes the control held at the start (on_odometry with
// step false), frames before it are skipped; every other call is one filter
// step (step true, frames always), after which run_filter records a pose.
void for_each_step(const RunInput& input, const std::function<void(const slam::OdometrySample&, bool step)>& on_odometry,
                   const std::function<void(const slam::ObservationFrame&)>& on_frame);

// Prints the evaluation (ATE, heading, landmarks, counts) and returns the pose
// ATE RMSE (or -1 when there is no truth).
struct Report {
  bool has_truth = false;
  eval::TrajectoryErrors filter;
  eval::TrajectoryErrors dead_reckoning;
  NeesStats nees;  // pose NEES of the filter against the truth
  bool has_landmarks = false;
  eval::LandmarkErrors landmarks;
};
Report evaluate(const RunInput& input, const RunResult& result);

// What the data leave to any online estimator (needs ground truth):
// - blind_drift: dead reckoning through the run's odometry, reset to the ground
//   truth at every camera frame: an estimator exact whenever it sees a landmark,
//   so what remains is the drift between frames;
// - the dead-reckoning heading error at the first frame and 30 s later: a map
//   started then is rotated by it, and no later observation sees the rotation
//   (only the start pose and the odometry up to then tie the map to the world).
struct DataLimits {
  eval::TrajectoryErrors blind_drift;
  double first_frame_t_s = 0.0;  // since start_time_s
  double heading_error_first_frame_rad = 0.0;
  double heading_error_30s_later_rad = 0.0;
};
// Throws std::invalid_argument without truth or frames.
DataLimits data_limits(const RunInput& input);
void print_report(const std::string& title, const Report& report, const RunResult& result);
// The accuracy lines of print_report only (no filter counters; NEES only when
// some step had a covariance).
void print_accuracy(const std::string& title, const Report& report);

// The run restarted at start_s from the truth pose then (interpolated): what a
// segment of mrclam_eval --segments runs, from start_s to the end of the input.
// Throws std::invalid_argument when the truth does not cover start_s.
RunInput restart_at_truth(const RunInput& input, double start_s);

// An estimator restarted `gap_s` after it saved `checkpoint` (slam_estimator
// killed, checkpoint.file): its pose widened for the gap (resume_pose, with
// the robot's speed bounds) and its map as a prior, from checkpoint time +
// gap_s on. What the robot did in the gap is unknown to it: the odometry of
// the gap is dropped, and no control is held before the first sample after it.
RunInput resumed_after(const RunInput& input, double checkpoint_t_s, const slam::MapCheckpoint& checkpoint,
                       double gap_s, double max_speed_mps, double max_turn_rate_radps, double control_timeout_s);

}  // namespace pixyslam::offline

namespace pixyslam::mrclam {
struct RobotData;
struct MeasurementFrame;
}
namespace pixyslam::config {
class YamlReader;
}
namespace pixyslam::offline {

// How the MRCLAM robots' sensors differ from the ideal models (config `mrclam:`).
// Measured on Dataset6 against Vicon, all five robots pooled (docs/mrclam.md):
// - the camera's range behaves like depth along the optical axis with lens
//   distortion: range_true = range / (range_scale * cos(bearing)^cos_exponent);
// - the robots start to move about 0.15 s after a velocity command is logged;
// - they drive slower while turning: forward speed = commanded speed *
//   (speed_scale - speed_loss_per_radps * |commanded turn rate|), at least 0.
struct MrclamSensorModel {
  double range_scale = 1.0;
  double range_cos_bearing_exponent = 0.0;
  double odometry_delay_s = 0.0;
  double speed_scale = 1.0;
  double speed_loss_per_radps = 0.0;
};
// The keys of `mrclam:` (ranges, units, help).
const parameters::Table<MrclamSensorModel>& mrclam_sensor_parameters();
// Reads the optional `mrclam:` mapping of a config file's root (defaults: ideal sensors).
MrclamSensorModel read_mrclam_sensor_model(config::YamlReader& root);

// MRCLAM robot data as filter input: started at the first ground-truth pose when
// there is one, else at the origin at the first odometry time.
RunInput mrclam_input(const mrclam::RobotData& data, const MrclamSensorModel& model = {});
// Keeps the first `duration_s` seconds of `input` from its start_time_s (the
// truth, odometry and frames stamped after that go); <= 0 keeps everything.
void keep_first_seconds(RunInput& input, double duration_s);
// Erases the items stamped (`t_s`) after `end_s`.
template <class Stamped>
void erase_after(std::vector<Stamped>& items, double end_s) {
  items.erase(std::remove_if(items.begin(), items.end(), [end_s](const Stamped& s) { return s.t_s > end_s; }),
              items.end());
}
// One camera image's detections with the model's range correction (subject as landmark_id).
slam::ObservationFrame mrclam_frame(const mrclam::MeasurementFrame& frame, const MrclamSensorModel& model);
}  // namespace pixyslam::offline
