#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>

// Several robots' landmark maps fused into one (the fleet map). Landmarks are
// identified by id (colour code), so robots' maps meet on the ids they share.
// Pure: no DDS, no clock.
namespace pixyslam::fleet_map {

struct LandmarkEstimate {
  int id = 0;
  Eigen::Vector2d mean = Eigen::Vector2d::Zero();
  Eigen::Matrix2d cov = Eigen::Matrix2d::Identity();  // m^2
};

// One robot's newest map.
struct RobotMap {
  std::string robot_id;
  std::uint64_t stamp_ns = 0;
  std::vector<LandmarkEstimate> landmarks;
};

struct FusionOptions {
  // A robot's frame is checked against the others' fused map on the landmarks
  // they share, when there are at least this many (>= 3: the test needs
  // degrees of freedom left after a rigid fit).
  int min_common_landmarks = 4;
  // The check: does a rigid motion (rotation and shift) explain a significant
  // part of the differences between this robot's landmarks and the others'?
  // F test of the weighted least-squares fit with the motion against the fit
  // without (3 and 2n - 3 degrees of freedom; weights 1 / trace of the summed
  // covariance). It needs no trust in the covariances' scale (FastSLAM's
  // landmark covariances leave out the pose and frame uncertainty), only in
  // their relative sizes. Frames agree below the F quantile at this probability.
  double agreement_probability = 0.999;
  // What to do with robots whose frames disagree:
  // - kAlign (map merging): every robot with enough shared landmarks is moved
  //   by the rigid motion that puts its map on the fleet's, the fleet's frame
  //   being the mean of the robots' (each robot's frame error, e.g. its
  //   heading drift before it first saw a landmark, is its own: their mean is
  //   nearer the true frame than most of them);
  // - kSetAside: the worst is set aside until the rest agree (for robots that
  //   must be in one frame, e.g. all started from surveyed poses).
  enum class Disagreement { kAlign, kSetAside } disagreement = Disagreement::kAlign;
};

enum class FrameVerdict { kAgrees, kDisagrees, kUnchecked };
const char* to_string(FrameVerdict verdict);

// What the fusion found about one robot's frame.
struct FrameCheck {
  std::string robot_id;
  std::size_t landmarks = 0;    // in its map
  std::size_t common = 0;       // shared with the others' fused map
  double f_statistic = 0.0;     // the test above (0 when unchecked)
  double threshold = 0.0;       // its quantile for `common` landmarks
  double residual_m = 0.0;      // weighted RMS difference of the shared landmarks after the rigid fit
  // How far apart the frames are on the shared landmarks (weights 1 / trace
  // of the summed covariance): the distance between the two weighted
  // centroids, and the rotation of the least-squares rigid fit of this robot's
  // landmarks onto the others' (0 with fewer than two shared).
  double offset_m = 0.0;
  double rotation_rad = 0.0;
  FrameVerdict verdict = FrameVerdict::kUnchecked;
  bool fused = true;               // its landmarks are in the fleet map
  double moved_rotation_rad = 0.0;  // kAlign: the motion applied to its map
  double moved_shift_m = 0.0;       // ... (the shift of its landmarks' centroid)
};

struct FusedLandmark {
  int id = 0;
  Eigen::Vector2d mean = Eigen::Vector2d::Zero();
  Eigen::Matrix2d cov = Eigen::Matrix2d::Zero();
  std::size_t robots = 0;  // maps it was fused from
};

struct FleetMap {
  std::vector<FusedLandmark> landmarks;  // by id
  std::vector<FrameCheck> robots;        // in the order of the input maps
};

// Fuses the robots' maps: every landmark's estimates in information form
// (P = (sum P_i^-1)^-1, m = P sum P_i^-1 m_i), treating the robots' maps as
// independent. Each robot's frame is first checked against the fusion of all
// others as they came (leave one out), then FusionOptions::disagreement
// decides. kSetAside: while some disagree, the worst (largest f_statistic /
// threshold) is set aside and the rest checked again, so one robot in a wrong
// frame cannot pull the others' check; of two that disagree only with each
// other the one with fewer landmarks goes. kAlign: alternately fuse and fit
// each robot's rigid motion onto the fusion, the motions' mean held at zero.
// Robots with too few shared landmarks are unchecked and fused as they are.
// Landmarks with a covariance that is not symmetric positive definite or not
// finite are skipped. Throws std::invalid_argument for bad options or a robot
// listed twice.
FleetMap fuse_maps(const std::vector<RobotMap>& maps, const FusionOptions& options = {});

// The quantile of the F distribution with (d1, d2) degrees of freedom at
// `probability` (bisection on the regularised incomplete beta function).
double f_quantile(double probability, int d1, int d2);

}  // namespace pixyslam::fleet_map
