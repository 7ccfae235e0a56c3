#pragma once

#include <cstddef>
#include <cstdint>
#include <limits>
#include <random>
#include <unordered_map>
#include <vector>

#include <Eigen/Core>

#include "pixyslam/slam/joint_gaussian.h"
#include "pixyslam/slam/landmark_map.h"
#include "pixyslam/slam/motion_model.h"
#include "pixyslam/slam/slam_options.h"
#include "pixyslam/slam/types.h"

namespace pixyslam::slam {

// One hypothesis: the pose Gaussian accumulated since its last sampled pose
// (zero covariance right after sampling), a log importance weight, and its map.
// While sampling is delayed, joint holds the pose and the landmarks seen since;
// pose is then its pose marginal, and a landmark in joint has its current mean
// and covariance there (the map's entry keeps its id and counts, and takes the
// values when the joint state ends).
struct Particle {
  PoseGaussian pose;
  double log_weight = 0.0;
  LandmarkMap map;
  SharedJointGaussian joint;
};

struct LandmarkEstimate {
  int id = 0;
  Eigen::Vector2d mean = Eigen::Vector2d::Zero();
  Eigen::Matrix2d cov = Eigen::Matrix2d::Zero();
  std::uint32_t times_observed = 0;
};

struct PoseEstimate {
  double t_s = 0.0;
  Pose2 mean = Pose2::Zero();                        // weighted mean (circular for theta)
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();     // spread of particles + their own covariance
  Pose2 best = Pose2::Zero();                        // highest-weight particle
  double effective_sample_size = 0.0;
  int particles = 0;
};

// Cumulative counts over the run. An observation counts as gated when more than
// half of the particles rejected it.
struct FilterCounters {
  std::uint64_t odometry_samples = 0;
  std::uint64_t odometry_invalid = 0;  // non-finite, or faster than max_speed / max_turn_rate: dropped
  std::uint64_t odometry_out_of_order = 0;
  std::uint64_t odometry_no_data = 0;  // samples without wheel data: the held control goes on
  std::uint64_t control_timeouts = 0;
  std::uint64_t frames = 0;
  std::uint64_t frames_invalid = 0;  // non-finite time: dropped with their detections
  std::uint64_t frames_late = 0;  // older than the filter time, newer than the last frame: applied at their stamp
  std::uint64_t frames_out_of_order = 0;  // older than the last frame: applied at the filter time
  std::uint64_t observations_used = 0;
  std::uint64_t observations_new_landmark = 0;
  std::uint64_t observations_gated = 0;
  std::uint64_t observations_invalid = 0;
  std::uint64_t observations_over_map_limit = 0;  // would start a landmark beyond max_map_landmarks: dropped
  std::uint64_t observations_unknown_id = 0;  // an id outside association.landmark_ids: dropped
  std::uint64_t landmark_slots_recycled = 0;  // maximum likelihood: landmarks no particle held any more, freed
  std::uint64_t resamples = 0;
  std::uint64_t delayed_sampling_starts = 0;  // particle-frames that began a joint state
  std::uint64_t joint_breakdowns = 0;  // joint-state updates refused as numerically broken
  std::uint64_t joint_iterated_updates = 0;  // outside the gate linearised once, inside re-linearised
  std::uint64_t joint_heading_splits = 0;  // joint states re-drawn along their heading at a return
};

// FastSLAM 2.0 (Montemerlo, Thrun, Koller, Wegbreit 2003) with known data
// association by landmark id, as adapted in the seed paper (low-variance
// resampling, unicycle odometry, range-bearing camera observations).
//
// Between camera frames each particle carries a pose Gaussian propagated through
// the odometry. At a frame, every observation of an already mapped landmark is
// folded into that Gaussian (the FastSLAM 2.0 proposal), the pose is SAMPLED from
// the result, landmark EKFs are updated (or initialised) with the sampled pose and
// the weight is multiplied by the observations' marginal likelihood (computed in
// the same sequential pass, in log space). Time is passed in with the samples.
// A frame older than the filter time but not older than the last frame (a camera
// delivered behind the odometry) is applied at its stamp, with the same result as
// in time order; older samples are counted and applied at the filter time.
// Same options, seed and input give bit-identical output. Thread-compatible.
class FastSlam2 {
 public:
  // Landmarks started by maximum-likelihood association get ids from here up
  // (the camera's ids are at most 1,000,000).
  static constexpr int kFirstUnlabelledId = 2000000;

  FastSlam2(const FilterOptions& options, const Pose2& initial_pose);
  // Every particle starts with this pose Gaussian (not sampled: the first
  // frame's proposal folds its observations into it), e.g. a restart whose
  // pose is only roughly known. A heading sd above 0.05 rad is split across
  // the particles (quantiles of its marginal, position conditioned on it).
  FastSlam2(const FilterOptions& options, const PoseGaussian& initial_pose);
  FastSlam2(const FastSlam2&) = delete;
  FastSlam2& operator=(const FastSlam2&) = delete;

  // Moves to sample.t_s with the previous control, then holds the new one.
  void add_odometry(const OdometrySample& sample);
  // Moves to frame.t_s, then runs the FastSLAM 2.0 update for the frame.
  void add_observations(const ObservationFrame& frame);

  // Gives every particle the same known landmarks (one shared tree, no copies):
  // localisation in a prior map, or a restart from a saved map. Replaces the maps.
  void set_prior_map(const std::vector<LandmarkEstimate>& landmarks);

  // Outputs are in the anchored frame (FilterOptions::anchor_frame; without it
  // the particles' own frame).
  PoseEstimate pose_estimate() const;
  // Landmarks of the highest-weight particle.
  std::vector<LandmarkEstimate> landmarks_of_best() const;
  // Landmarks as a weighted mixture over all particles: mean of means, covariance
  // = mean covariance + spread of the means. O(M K).
  std::vector<LandmarkEstimate> landmarks_mixture() const;

  // In the particles' own frame: to_output() moves a pose into the output frame.
  // Odometry is composed and applied to the particles at the next frame
  // (ComposedMotion); particles() applies it first, particle_pose() reads the
  // moved pose without changing the particles.
  const std::vector<Particle>& particles() {
    move_particles();
    return particles_;
  }
  std::size_t particle_count() const { return particles_.size(); }
  Pose2 particle_pose(std::size_t i) const;
  Pose2 to_output(const Pose2& pose) const;
  // Rigid transform from the particles' frame to the output frame (identity
  // until anchored), and the anchored landmark ids (empty until anchored).
  double output_rotation_rad() const { return output_rotation_rad_; }
  const Eigen::Vector2d& output_translation_m() const { return output_translation_m_; }
  std::vector<int> anchor_ids() const;
  const FilterCounters& counters() const { return counters_; }
  const FilterOptions& options() const { return options_; }
  double time_s() const { return time_s_; }
  // The odometry command held now (applied until the next sample or for
  // control_timeout_s) and the filter time it was taken at.
  const OdometrySample& held_control() const { return control_; }
  double held_control_since_s() const { return control_time_s_; }
  const LandmarkMapPool& pool() const { return pool_; }

 private:
  // kNewDone: a first sighting already added to a joint state this frame.
  enum class Decision : std::uint8_t { kUsed, kGated, kNew, kInvalid, kNewDone };

  void advance_to(double t_s);
  // The odometry composed in pending_, step by step, so that a late frame can
  // split it at its stamp.
  struct MotionStep {
    double v_mps, w_radps, from_s, to_s;
  };
  void add_pending(const MotionStep& step);
  // Leaves in pending_ the motion up to t_s and returns the steps after it.
  std::vector<MotionStep> split_pending_at(double t_s);
  // The FastSLAM 2.0 update for a frame at the particles' time.
  void update_with_frame(const ObservationFrame& frame);
  // Applies the odometry composed since the last frame to every particle; with
  // joint_states_later, the joint states are left to the frame's update, which
  // moves each (joint_motion_) just before updating it.
  void move_particles(bool joint_states_later = false);
  // Moves the run of particles side by side that hold particle `first`'s joint
  // state (once for all); returns the run's end (first + 1 without one).
  std::size_t move_joint_run(std::size_t first, const ComposedMotion& motion);
  // cos and sin of each particle's heading (for pending_), and weights_.
  void refresh_caches();
  std::uint32_t slot_for(int landmark_id);
  // Association::kMaximumLikelihood: slots_ for particle p (a mapped landmark,
  // or a new slot shared by every particle that starts one for that detection).
  void associate(const Particle& p);
  void update_particle(Particle& p, const std::vector<RangeBearing>& detections);
  void update_particle_joint(Particle& p, const std::vector<RangeBearing>& detections);
  void finish_joint(Particle& p);
  // The deterministic part of a joint-state update, on g: p's own state, or
  // the state p's copies share. end_joint_update() then does the random part
  // (the pose sampled when the state ends or broke down) for each particle.
  enum class JointOutcome : std::uint8_t { kStays, kEnds, kBrokeDown };
  JointOutcome update_joint_state(Particle& p, JointGaussian& g, std::size_t detections);
  void end_joint_update(Particle& p, JointOutcome outcome, const PoseGaussian& before);
  // Copies of one particle in delayed sampling (resampling puts them side by
  // side: the same joint state, map, pose and weight) stay identical through a
  // frame's deterministic update: it is made once, on their shared state, and
  // the others take the result (FilterOptions::share_identical_particles).
  // copies_end(i) is the end of particle i's run of such copies (i + 1 when it
  // has none, or its update may draw a random number in the middle).
  std::size_t copies_end(std::size_t first) const;
  void update_copies(std::size_t first, std::size_t end, std::size_t detections);
  // Adds decision_ to gated_votes_ and any_new_.
  void count_votes();
  // DelayedSamplingOptions::split_heading: at a frame that sees landmarks mapped
  // outside the joint state, the state is split along its heading
  // (split_heading()) and one component drawn by prior weight times the
  // likelihood of those detections. Returns the log weight to add beyond what
  // the frame's updates of the drawn component add (log of the mixture's
  // likelihood minus the component's).
  double draw_heading_at_return(Particle& p, JointGaussian& g);
  // Detection k's block in the particle's joint state g; a mapped landmark not
  // in it yet joins as known (independent of the rest).
  int joint_index(const Particle& p, JointGaussian& g, std::size_t k);
  // An outlier costs the likelihood at the gate boundary, so particles that
  // reject it are not favoured over those that explain it.
  double outlier_log_likelihood(double log_likelihood, double mahalanobis2) const {
    return log_likelihood + 0.5 * (mahalanobis2 - gate_d2_);
  }
  // The particles' weights normalised (from their log weights).
  std::vector<double> normalised_particle_weights() const;
  void resample_if_needed(const std::vector<double>& weights);
  std::size_t best_index() const;
  const std::vector<double>& weights() const { return weights_; }  // normalised importance weights
  // Anchors the output frame once the first landmarks pin it, then keeps the
  // output transform up to date (AnchorFrameOptions).
  void update_output_frame();
  // FilterOptions::frame_uncertainty: the frame covariance from the first
  // mapped landmark until the frame is pinned.
  void track_frame_uncertainty();
  bool frame_pinned(std::vector<std::uint32_t>* slots) const;
  // The pose estimate in the particles' frame (before to_output).
  PoseEstimate particle_frame_estimate() const;
  // Weighted mean position of each slot over the particles that map it; false
  // where no particle does.
  void mean_positions(const std::vector<std::uint32_t>& slots, std::vector<Eigen::Vector2d>& means,
                      std::vector<bool>& found) const;
  LandmarkEstimate to_output(const LandmarkEstimate& landmark) const;

  FilterOptions options_;
  IdRanges landmark_ids_;  // options_.landmark_ids parsed (empty: every id)
  double gate_d2_;
  std::mt19937_64 rng_;
  LandmarkMapPool pool_;  // declared before particles_: outlives their maps
  std::vector<Particle> particles_;
  std::vector<Particle> scratch_;
  ComposedMotion pending_;                   // odometry not yet applied to the particles
  ComposedMotion joint_motion_;              // odometry due to the joint states in update_with_frame
  std::vector<MotionStep> pending_steps_;    // what pending_ composes
  double moved_until_s_ = 0.0;               // the particles' time: pending_ starts here
  std::vector<Eigen::Vector2d> heading_cs_;  // per particle: cos, sin of its heading
  std::vector<double> weights_;              // normalised importance weights
  // Weighted particle moments at the last frame (positions relative to x, y;
  // t: heading minus the mean heading), for pose_estimate() in O(1).
  struct Moments {
    double x = 0, y = 0, c = 0, s = 0, heading = 0;
    double xx = 0, xy = 0, yy = 0, xc = 0, xs = 0, yc = 0, ys = 0, cc = 0, ss = 0, cs = 0;
    double t = 0, tt = 0, xt = 0, yt = 0, ct = 0, st = 0;
    // The particles' own pose covariances P_i: sum w P_i, sum w cos P_i e3,
    // sum w sin P_i e3, sum w P_i(2,2) {cos^2, sin^2, cos sin}.
    Eigen::Matrix3d p = Eigen::Matrix3d::Zero();
    Eigen::Vector3d cp3 = Eigen::Vector3d::Zero(), sp3 = Eigen::Vector3d::Zero();
    double pcc = 0, pss = 0, pcs = 0;
    double effective_sample_size = 0;
    std::size_t best = 0;
  };
  Moments moments_;

  struct Anchor {
    std::uint32_t slot;
    Eigen::Vector2d position;  // in the output frame, fixed when anchored
  };
  std::vector<Anchor> anchors_;
  struct FrameUncertainty {
    bool started = false, pinned = false;
    Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();  // pose covariance, pivot at `pivot`
    Eigen::Vector2d pivot = Eigen::Vector2d::Zero();
  };
  FrameUncertainty frame_;
  // FilterOptions::landmark_uncertainty: per slot the landmark's spread over the
  // particles when first mapped (NaN until then), and the pose floor it implies.
  std::vector<Eigen::Matrix2d> mapped_spread_;
  Eigen::Matrix3d landmark_floor_ = Eigen::Matrix3d::Zero();
  void capture_mapped_spread(const std::vector<RangeBearing>& valid, const std::vector<double>& weights);
  void update_landmark_floor(const std::vector<RangeBearing>& valid);
  double output_rotation_rad_ = 0.0;
  Eigen::Vector2d output_translation_m_ = Eigen::Vector2d::Zero();

  bool has_time_ = false;
  double time_s_ = 0.0;
  OdometrySample control_;
  double control_time_s_ = 0.0;

  std::unordered_map<int, std::uint32_t> slot_of_id_;
  static constexpr int kFreeSlot = std::numeric_limits<int>::min();
  std::vector<int> id_of_slot_;  // kFreeSlot: free (free_slots_)
  std::vector<std::uint32_t> free_slots_;
  std::size_t slots_in_use() const { return id_of_slot_.size() - free_slots_.size(); }
  // Association::kMaximumLikelihood: frees the slots no particle holds any more
  // (a landmark some particles started, all of them since resampled away), so
  // a run of days does not run out of max_map_landmarks. Between frames only.
  void recycle_slots();
  // FilterOptions::error_correlation_s: per slot the time of its last sighting
  // (NaN: never), and the factor on R of a sighting after it.
  std::vector<double> last_sighting_s_;
  double correlated_error_factor(std::uint32_t slot, double t_s);

  // Per-frame working memory (reused to avoid allocation).
  std::vector<Eigen::Vector2d> z_;
  std::vector<Eigen::Matrix2d> r_;
  std::vector<std::int64_t> new_slots_;  // per detection of the frame, -1 until a particle needs it
  int next_unlabelled_id_ = kFirstUnlabelledId;
  double new_landmark_d2_ = 0.0;
  std::vector<std::uint32_t> slots_;
  std::vector<double> new_log_likelihood_;  // per detection: log weight if it starts a landmark
  std::vector<Decision> decision_;
  std::vector<std::size_t> known_;  // detections of landmarks mapped outside the joint state
  std::vector<Landmark*> landmarks_;
  std::vector<int> gated_votes_;
  std::vector<char> any_new_;            // per detection: some particle started a landmark with it
  std::vector<Decision> copy_decisions_;  // update_copies: the decisions of the first copy
  // update_joint_state: the state before the frame, and on a breakdown its landmarks.
  Eigen::VectorXd mean_before_;
  PackedSymmetric cov_before_;
  std::vector<ConditionedLandmark> marginals_before_;
  FilterCounters counters_;
};

}  // namespace pixyslam::slam
