#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "pixyslam/eval/trajectory_metrics.h"

namespace pixyslam::mrclam {

// The robots of an MRCLAM data set are subjects kFirstRobot..kLastRobot.
constexpr int kFirstRobot = 1;
constexpr int kLastRobot = 5;
// Robot `robot`'s name on the topics (MessageHeader robot_id): "robot<N>".
inline std::string robot_id(int robot) { return "robot" + std::to_string(robot); }
// std::invalid_argument naming `what` unless every robot is kFirstRobot..kLastRobot and none is given twice.
void check_robot_list(const std::vector<int>& robots, const std::string& what);

// Reader for the UTIAS Multi-Robot Cooperative Localization and Mapping
// (MRCLAM) data sets: one folder per data set with whitespace-separated text
// files, times in unix seconds, positions in metres, angles in radians
// counter-clockwise, all ground truth in the motion-capture world frame.
// Subjects 1..5 are the robots, higher subject numbers are landmarks.

// Odometry command at time t_s: forward velocity (m/s) and yaw rate (rad/s).
struct OdometryRow {
  double t_s;
  double v_mps;
  double w_radps;
};

// One landmark seen by the camera: subject number (barcode already mapped),
// range (m) and bearing (rad, counter-clockwise from the robot's heading).
struct Detection {
  int subject;
  double range_m;
  double bearing_rad;
};

// All landmark detections sharing one timestamp (one camera image).
struct MeasurementFrame {
  double t_s;
  std::vector<Detection> detections;
};

// Bookkeeping of the measurement file: measurement_rows data rows in total, of
// which robot_rows saw another robot (subject 1..5 and not in the landmark
// file), unknown_barcode_rows had a barcode absent from Barcodes.dat (spurious),
// and landmark_rows were kept as detections (a subject the landmark file lists,
// or any mapped subject above 5, even one missing from the landmark file).
// measurement_rows = robot_rows + unknown_barcode_rows + landmark_rows.
struct ReadCounts {
  std::size_t measurement_rows = 0, robot_rows = 0, unknown_barcode_rows = 0, landmark_rows = 0;
};

// Everything one robot contributes, sorted by time (stable sorts, so rows with
// equal times keep their file order). Frames hold landmark detections only;
// frames that saw no landmark are omitted; robot_sightings hold the rows that
// saw another robot, grouped by time the same way. groundtruth is empty if
// RobotN_Groundtruth.dat is absent. landmarks come from
// Landmark_Groundtruth_fixed_11_17.dat when that file exists (Dataset1's
// original file has landmarks 11 and 17 swapped), else from
// Landmark_Groundtruth.dat; landmark_file holds the file name used (empty, and
// no landmarks, when neither exists: a recording without surveyed landmarks).
struct RobotData {
  int robot = 0;
  std::vector<OdometryRow> odometry;
  std::vector<MeasurementFrame> frames;
  std::vector<MeasurementFrame> robot_sightings;  // the other robots seen (subjects 1..5), same layout
  std::vector<eval::TimedPose> groundtruth;
  std::vector<eval::LandmarkPoint> landmarks;
  std::string landmark_file;
  ReadCounts counts;
};

// Loads robot `robot` (1..5) from the data set folder `dataset_dir`. Files may
// use LF or CRLF line ends; lines starting with '#' and blank lines are skipped.
// Throws std::runtime_error for: robot out of 1..5, a missing folder or required
// file (naming the path), a line with the wrong number of columns, a non-number
// or a non-finite number ("path:line: ... in line '<text>'"), a barcode mapped
// to two subjects, or a landmark listed twice. Prints nothing.
RobotData load_robot(const std::string& dataset_dir, int robot);

// Writes `data` as robot data.robot (1..5) of an MRCLAM data set in the folder
// `dataset_dir` (created if missing): its odometry, measurement and ground
// truth files, Landmark_Groundtruth.dat (standard deviations 0) and
// Barcodes.dat (barcode = subject number; robots 1..5 and every landmark).
// Landmark subjects must be above 5; numbers are written with round-trip
// precision, so load_robot reads back what was written. Throws
// std::runtime_error naming the file that cannot be written or the bad subject.
void write_robot(const std::string& dataset_dir, const RobotData& data);

}  // namespace pixyslam::mrclam
