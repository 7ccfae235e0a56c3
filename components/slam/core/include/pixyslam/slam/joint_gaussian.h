#pragma once

#include <cstdint>
#include <memory>
#include <random>
#include <vector>

#include <Eigen/Core>

#include "pixyslam/slam/motion_model.h"
#include "pixyslam/slam/packed_symmetric.h"
#include "pixyslam/slam/types.h"

namespace pixyslam::slam {

// A landmark's Landmark::times_observed and consecutive_rejections.
struct LandmarkCounts {
  std::uint32_t times_observed = 0;
  std::uint32_t consecutive_rejections = 0;
};

// What a JointGaussian keeps of one of its landmarks besides its mean and covariance.
struct JointLandmark {
  Eigen::Vector2d first = Eigen::Vector2d::Zero();  // first estimate (the FEJ linearisation point)
  std::uint32_t slot = 0;
  // While a landmark is in the state its counters live here, so a frame's
  // bookkeeping does not copy the particle's map tree; the map takes them when
  // the state ends.
  LandmarkCounts counts;
  // First seen in this state (add_new): placed relative to the pose, it turns
  // with it when a mapped landmark corrects the heading.
  bool relative = false;
};

// One particle's pose and the landmarks it saw while its pose was too uncertain
// to sample (delayed sampling, see FastSlam2): a single Gaussian over
// (x, y, theta, m1x, m1y, m2x, ...), updated like EKF-SLAM. Landmarks seen from
// an uncertain pose stay correlated with it, so a later observation of a well
// known landmark moves the pose and those landmarks together (loop closure)
// instead of leaving them in the frame the pose had when they were first seen.
//
// Jacobians follow the first-estimates rule (Huang, Mourikis, Roumeliotis 2008,
// FEJ-EKF): observations are linearised at the landmark's first estimate and the
// pose predicted for the frame, and the motion Jacobian at predicted poses.
// Linearising at ever-updated estimates instead lets relative observations
// "observe" the absolute heading, which is unobservable: the heading covariance
// collapses and the loop closure this state exists for cannot happen. After a
// large correction (over 0.25 m) the motion Jacobian keeps the updated pose.
// Plain data; an empty JointGaussian (no state) is inactive.
struct JointGaussian {
  Eigen::VectorXd mean;
  // The covariance, packed: with thousands of particles the filter waits on
  // memory, and an update streams half the bytes of dense storage.
  PackedSymmetric cov;
  // What the state keeps of landmark i besides its mean and covariance (block 3 + 2i).
  std::vector<JointLandmark> landmarks;
  Eigen::Vector3d frame_pose = Eigen::Vector3d::Zero();  // pose predicted for the frame

  bool active() const { return mean.size() != 0; }
  // Finite, with non-negative and bounded variances.
  bool healthy() const;
  int landmark_count() const { return static_cast<int>(landmarks.size()); }
  // Block index of a landmark slot, -1 when it is not in the state.
  int find(std::uint32_t slot) const;
  PoseGaussian pose() const;
  Eigen::Vector2d landmark_mean(int i) const { return mean.segment<2>(3 + 2 * i); }
  Eigen::Matrix3d pose_cov() const { return cov.diagonal_block<3>(0); }
  Eigen::Matrix2d landmark_cov(int i) const { return cov.diagonal_block<2>(3 + 2 * i); }
  // Cov(pose, landmark i), 3 x 2.
  Eigen::Matrix<double, 3, 2> pose_landmark_cov(int i) const;
  double heading_variance() const { return cov.lower(2, 2); }

  // Starts from a pose Gaussian with no landmarks.
  void begin(const PoseGaussian& pose);
  void clear();
  // Pose block moved through motion_step(); cross-covariances multiplied by F.
  void propagate(double v_mps, double w_radps, double dt_s, const MotionNoise& noise);
  // The same for several steps at once (ComposedMotion): one 3 x n product.
  void apply_motion(const ComposedMotion& motion);
  // P <- F P F^T + Q with F and Q on the pose block only.
  void move_pose(const Eigen::Matrix3d& f, const Eigen::Matrix3d& q);
  // Brackets the observations of one frame. end_frame() re-linearises the motion
  // Jacobian at the predicted pose: with c the position correction of the frame,
  // P <- Fc P Fc^T, Fc = I + [0 0 -c_y; 0 0 c_x; 0 0 0] (the unicycle Jacobians
  // are unipotent and compose by adding displacements).
  void begin_frame() { frame_pose = mean.head<3>(); }
  void end_frame();
  // Appends a mapped landmark, independent of the rest (FastSLAM's factorisation).
  int add_known(std::uint32_t slot, const Eigen::Vector2d& landmark_mean, const Eigen::Matrix2d& landmark_cov,
                LandmarkCounts landmark_counts = {});
  // Appends a first sighting through the inverse observation model at the frame
  // pose, with its correlation to the pose: P_ll = Gx Pxx Gx^T + Gz R Gz^T,
  // P_l* = Gx P_x*. Add new landmarks before the frame's updates.
  int add_new(std::uint32_t slot, const Eigen::Vector2d& z, const Eigen::Matrix2d& r);
};

// A particle's joint state, shared by the copies resampling makes of the
// particle (copy on write). Copies in delayed sampling stay identical, their
// updates draw no random numbers, so FastSlam2 moves and updates a shared state
// once for all its holders; own() gives a holder that changes alone its copy.
class SharedJointGaussian {
 public:
  bool active() const { return state_ != nullptr && state_->active(); }
  // The state; active() must be true.
  const JointGaussian& operator*() const { return *state_; }
  const JointGaussian* operator->() const { return state_.get(); }
  // A new state for this holder alone.
  JointGaussian& begin(const PoseGaussian& pose);
  // This holder's state, copied first if another holds it too.
  JointGaussian& own();
  // The state as every holder sees it: a change here changes it for all.
  JointGaussian& shared() { return *state_; }
  // How many hold the state, this one included.
  long holders() const { return state_.use_count(); }
  bool same_state(const SharedJointGaussian& other) const { return state_ == other.state_; }
  void clear() { state_.reset(); }

 private:
  std::shared_ptr<JointGaussian> state_;
};

// How an observation of state landmark i fits the joint Gaussian: innovation
// nu = z - h(mean), S = H P H^T + R with H = [H_pose, H_landmark] on its blocks,
// evaluated at the frame pose and the landmark's first estimate.
struct JointFit {
  int index = -1;
  Eigen::Vector2d innovation = Eigen::Vector2d::Zero();
  Eigen::Matrix<double, 2, 3> h_pose = Eigen::Matrix<double, 2, 3>::Zero();
  Eigen::Matrix2d h_landmark = Eigen::Matrix2d::Zero();
  Eigen::Matrix2d s = Eigen::Matrix2d::Identity();
  double mahalanobis2 = 0.0;
  double log_likelihood = 0.0;
};
JointFit fit_observation(const JointGaussian& g, int index, const Eigen::Vector2d& z, const Eigen::Matrix2d& r);
// The same fit re-linearised at the updated state (iterated EKF, Gauss-Newton on
// the MAP of this one observation): from x_0 = mean, x_{k+1} = mean + K_k nu_k
// with H_k at x_k, nu_k = z - h(x_k) - H_k (mean - x_k), until the pose and
// landmark move less than 1e-9 or after max_iterations. The fit holds the last
// H_k and nu_k, so apply_observation() makes the iterated update. For a large
// innovation (a landmark seen again after the heading drifted by tens of
// degrees) the single linearisation at the frame pose under-corrects and
// exaggerates the Mahalanobis distance; this one does not.
JointFit fit_observation_iterated(const JointGaussian& g, int index, const Eigen::Vector2d& z,
                                  const Eigen::Matrix2d& r, int max_iterations = 10);
// EKF update with a fit: K = P H^T S^-1, mean += K nu, P -= K S K^T. Returns
// false and leaves g unchanged when the result would not be healthy().
[[nodiscard]] bool apply_observation(JointGaussian& g, const JointFit& fit);
// The state as a Gaussian mixture along its heading, for an observation too
// nonlinear for one linearisation (a mapped landmark seen again after the
// heading drifted by tens of degrees while blind). In robot-centred coordinates
// for the relative landmarks, m_R = R(theta)^T (m - p) (Castellanos et al.
// 2007, robocentric EKF-SLAM), so each component turns them about the pose on
// their arcs rather than along the tangent: component k has its heading moved
// by delta_k = k spacing (|delta| up to 3 sd), the rest of the state by its
// regression on the heading, covariance P - (s^2 - c^2) b b^T with heading
// variance c^2 = (spacing / 2)^2, and prior weight N(delta_k; 0, s^2 - c^2)
// (normalised); back in world coordinates with its linearisation points (first
// estimates, frame pose) moved rigidly with the pose. Empty when the heading sd
// is not above spacing / 2.
struct HeadingComponent {
  double weight = 0.0;
  JointGaussian state;
};
std::vector<HeadingComponent> split_heading(const JointGaussian& g, double spacing_rad);

// The landmarks given a pose drawn from the state's pose marginal: mean_i +
// P_ix Pxx^-1 (x - mean_x), covariance P_ii - P_ix Pxx^-1 P_xi. The landmarks'
// correlations with each other given the pose are dropped (FastSLAM's factorised
// map); they come only from motion noise between their sightings.
struct ConditionedLandmark {
  std::uint32_t slot = 0;
  Eigen::Vector2d mean = Eigen::Vector2d::Zero();
  Eigen::Matrix2d cov = Eigen::Matrix2d::Zero();
  LandmarkCounts counts;
};
std::vector<ConditionedLandmark> condition_on_pose(const JointGaussian& g, const Pose2& pose);

}  // namespace pixyslam::slam
