#pragma once

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "pixyslam/parameters/parameters.h"
#include "pixyslam/slam/motion_model.h"

namespace pixyslam::slam {

// How a detection finds its landmark.
enum class Association {
  kKnownId,            // by the detection's landmark id (the Pixy colour code)
  kMaximumLikelihood,  // ids ignored: per particle, the mapped landmark most likely
                       // to have made it, or a new one when none is likely enough
                       // (FastSLAM with unknown data association)
};

enum class ResampleMode {
  kEffectiveSampleSize,  // when N_eff < resample_neff_fraction * N
  kEveryFrame,           // after every observation frame (the seed paper)
};

// Delayed sampling: a particle whose pose has become more uncertain than the
// "enter" limits since it was last sampled (a long stretch without landmarks) is
// not sampled at the next frame. Its pose and the landmarks it then sees are kept
// in one Gaussian (JointGaussian) until the pose is pinned below the "exit"
// limits again (typically by re-observing a well known landmark: loop closure),
// or the state holds max_landmarks; then the pose is sampled and the landmarks
// are conditioned on it. Sigmas: heading sd, and sd of position along its worst
// direction.
struct DelayedSamplingOptions {
  bool enabled = false;
  double enter_heading_sigma_rad = 0.15;
  double enter_position_sigma_m = 0.3;
  double exit_heading_sigma_rad = 0.08;
  double exit_position_sigma_m = 0.2;
  int max_landmarks = 16;
  // Mapped landmarks seen again while the joint state's heading sd exceeds
  // enter_heading_sigma_rad: each particle's state is split along its heading
  // (robot-centred, components enter_heading_sigma_rad apart) and one component
  // drawn by how well it explains them, instead of one linearised update at a
  // heading that may be tens of degrees off. The particles then hold different
  // headings, which decides associations when the ids are withheld
  // (docs/mrclam.md, "Heading split at a return").
  bool split_heading = false;
};

// Output frame anchoring. The map's frame is tied to the world only by the start
// pose and the odometry up to the first landmarks; later observations are all
// relative, so a rigid motion of the whole map and path is unobservable (a gauge
// freedom). In a particle filter the particle set's consensus on that frame
// still wanders as lineages die out: each run settles on a random frame near
// the true one. With anchoring, once the first landmarks pin the frame (at
// least min_landmarks, each observed min_observations times in the best
// particle, spread at least min_spread_m RMS around their centroid), their
// weighted mean positions are kept as anchors, and every output (poses,
// landmarks) is moved by the rigid transform that puts the particles' current
// mean anchors back on them (least squares). The particles are not changed.
// Known-id association only (with maximum likelihood a landmark slot is not the
// same pole in every particle).
struct AnchorFrameOptions {
  bool enabled = false;
  int min_landmarks = 2;
  int min_observations = 5;
  double min_spread_m = 0.5;
};

// Everything that configures FastSlam2. Units in the names; ranges in
// filter_parameters().
struct FilterOptions {
  int particles = 100;
  std::uint64_t seed = 1;

  MotionNoise motion;
  // Odometry beyond these is physically impossible for the robot: dropped and
  // counted (FilterCounters::odometry_invalid), like non-finite values.
  double max_speed_mps = 10.0;
  double max_turn_rate_radps = 20.0;
  // Control held longer than this (no new odometry) is treated as stopped.
  double control_timeout_s = 5.0;

  // Default observation noise, used when a detection carries no sigmas:
  // range sd = range_sigma_m + range_sigma_per_m * range (size-based ranging
  // degrades with distance).
  double range_sigma_m = 0.07;
  double range_sigma_per_m = 0.0;
  double bearing_sigma_rad = 0.027;
  // Time constant of each landmark's measurement errors (first-order
  // Gauss-Markov; 0: white, the paper's model). Real cameras repeat much of
  // an error from frame to frame, so a landmark seen again after dt carries
  // less news: its R is scaled by (1 + rho) / (1 - rho), rho = exp(-dt / tau),
  // the variance of the mean of such errors. The information per second then
  // no longer grows with the frame rate. Known-id association only.
  double error_correlation_s = 0.0;
  // Detections outside [min_range_m, max_range_m] are rejected as invalid.
  double min_range_m = 0.05;
  double max_range_m = 50.0;
  // Landmarks the map may hold (a MapState carries up to 4096): detections that
  // would start more are dropped and counted (observations_over_map_limit); with
  // maximum likelihood, where any detection may start one, the landmarks no
  // particle holds any more are freed first (landmark_slots_recycled), and a
  // frame that could still pass the limit is dropped whole.
  int max_map_landmarks = 4096;

  // Mahalanobis gate on observations of mapped landmarks, per particle.
  bool gate_enabled = true;
  double gate_probability = 0.999;  // chi-square (2 dof) quantile of the gate
  // After this many consecutive rejections of one landmark, the next observation
  // is accepted anyway so that a drifted particle can recover.
  int gate_readmit_after = 3;

  Association association = Association::kKnownId;
  // kKnownId: the landmark ids there are (the pixy bridge's colour-code table),
  // each item an id ("7") or an inclusive range ("1-20"). A detection with
  // another id is dropped and counted (observations_unknown_id): ids a faulty
  // or hostile sender invents cannot fill max_map_landmarks. Empty: every id.
  // kMaximumLikelihood does not read the ids, nor this list.
  std::vector<std::string> landmark_ids;
  // kMaximumLikelihood: a detection starts a new landmark when no mapped one is
  // within this chi-square (2 dof) quantile of its predicted observation.
  double new_landmark_probability = 0.99;

  ResampleMode resample_mode = ResampleMode::kEffectiveSampleSize;
  double resample_neff_fraction = 0.667;
  DelayedSamplingOptions delayed_sampling;
  AnchorFrameOptions anchor_frame;
  // The map's frame (where the map is and how it is turned in the world) is
  // only as good as the pose when the first landmarks were mapped: later
  // observations are relative and cannot reduce that uncertainty, but
  // resampling loses it from the particle spread. When enabled, the output pose
  // covariance never falls below the pose covariance from the first mapped
  // landmark until the frame is pinned (anchor_frame's thresholds), moved to the
  // current position. The estimates themselves are unchanged.
  bool frame_uncertainty = false;
  // The same for every landmark (with frame_uncertainty): a landmark's world
  // position is only as good as its spread over the particles when it was first
  // mapped (the pose uncertainty then, which resampling later loses). The output
  // pose covariance never falls below what the mapped landmarks of the last
  // frame that saw two or more imply by that uncertainty alone
  // ((sum H_x^T (H_m W_j H_m^T)^-1 H_x)^-1, W_j the spread at mapping).
  bool landmark_uncertainty = false;
  // Not a YAML key: results are bit-identical either way. Resampled copies of
  // a particle in delayed sampling share one joint state, moved and updated
  // once for all; off measures what that saves (bench_mrclam_frame).
  bool share_identical_particles = true;
};

// Every parameter of FilterOptions, once: YAML key below `filter:`, range,
// unit, help (pixyslam/parameters/parameters.h). Reading, validate(), the
// effective configuration and `--set filter.KEY=VALUE` all use it.
const parameters::Table<FilterOptions>& filter_parameters();

// The table's ranges, then the rules between parameters; throws
// std::invalid_argument naming the parameter ("filter.<path> = v: ...").
void validate(const FilterOptions& options);

// Applies "filter.KEY=VALUE" assignments (command-line overrides) in order,
// then validate(); throws std::invalid_argument naming the first bad one.
void apply_overrides(FilterOptions& options, const std::vector<std::string>& assignments);

// FilterOptions::landmark_ids as inclusive [first, last] ranges, sorted;
// throws std::invalid_argument naming a bad item. Empty: every id.
using IdRanges = std::vector<std::pair<int, int>>;
IdRanges parse_landmark_ids(const std::vector<std::string>& items);
bool contains_id(const IdRanges& ranges, int id);

// Squared Mahalanobis distance of the gate: chi-square quantile with 2 dof.
double gate_mahalanobis2(const FilterOptions& options);

std::string to_string(ResampleMode mode);
std::string to_string(Association association);

}  // namespace pixyslam::slam
