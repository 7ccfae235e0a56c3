#include "pixyslam/slam/slam_options.h"

#include <cmath>
#include <sstream>
#include <stdexcept>

namespace pixyslam::slam {
namespace {

void require(bool ok, const char* field, double value, const char* rule) {
  if (ok) return;
  std::ostringstream os;
  os << "filter option '" << field << "' = " << value << ": " << rule;
  throw std::invalid_argument(os.str());
}

void require_non_negative(double v, const char* field) {
  require(std::isfinite(v) && v >= 0.0, field, v, "must be a finite number >= 0");
}

void require_positive(double v, const char* field) {
  require(std::isfinite(v) && v > 0.0, field, v, "must be a finite number > 0");
}

}  // namespace

void validate(const FilterOptions& o) {
  require(o.particles >= 1 && o.particles <= 1000000, "particles", o.particles, "must be in [1, 1000000]");
  require_non_negative(o.motion.v_sigma_m_per_sqrt_s, "motion.v_sigma_m_per_sqrt_s");
  require_non_negative(o.motion.w_sigma_rad_per_sqrt_s, "motion.w_sigma_rad_per_sqrt_s");
  require_non_negative(o.motion.distance_sigma_per_sqrt_m, "motion.distance_sigma_per_sqrt_m");
  require_non_negative(o.motion.heading_sigma_rad_per_sqrt_m, "motion.heading_sigma_rad_per_sqrt_m");
  require_non_negative(o.motion.rotation_sigma_per_sqrt_rad, "motion.rotation_sigma_per_sqrt_rad");
  require_positive(o.max_speed_mps, "max_speed_mps");
  require_positive(o.max_turn_rate_radps, "max_turn_rate_radps");
  require_positive(o.control_timeout_s, "control_timeout_s");
  require_positive(o.range_sigma_m, "range_sigma_m");
  require_non_negative(o.range_sigma_per_m, "range_sigma_per_m");
  require_positive(o.bearing_sigma_rad, "bearing_sigma_rad");
  require(std::isfinite(o.error_correlation_s) && o.error_correlation_s >= 0.0 && o.error_correlation_s <= 100.0,
          "error_correlation_s", o.error_correlation_s, "must be in [0, 100] s");
  require(o.error_correlation_s == 0.0 || o.association == Association::kKnownId, "error_correlation_s",
          o.error_correlation_s, "needs association known_id (a landmark's last sighting is tracked by its id)");
  require_non_negative(o.min_range_m, "min_range_m");
  require(std::isfinite(o.max_range_m) && o.max_range_m > o.min_range_m, "max_range_m", o.max_range_m,
          "must be finite and greater than min_range_m");
  require(o.gate_probability > 0.0 && o.gate_probability < 1.0, "gate_probability", o.gate_probability,
          "must be in (0, 1)");
  require(o.new_landmark_probability > 0.0 && o.new_landmark_probability < 1.0, "new_landmark_probability",
          o.new_landmark_probability, "must be in (0, 1)");
  require(o.gate_readmit_after >= 1, "gate_readmit_after", o.gate_readmit_after, "must be >= 1");
  require(o.resample_neff_fraction > 0.0 && o.resample_neff_fraction <= 1.0, "resample_neff_fraction",
          o.resample_neff_fraction, "must be in (0, 1]");
  const DelayedSamplingOptions& d = o.delayed_sampling;
  require_positive(d.enter_heading_sigma_rad, "delayed_sampling.enter_heading_sigma_rad");
  require_positive(d.enter_position_sigma_m, "delayed_sampling.enter_position_sigma_m");
  require(std::isfinite(d.exit_heading_sigma_rad) && d.exit_heading_sigma_rad > 0.0 &&
              d.exit_heading_sigma_rad <= d.enter_heading_sigma_rad,
          "delayed_sampling.exit_heading_sigma_rad", d.exit_heading_sigma_rad,
          "must be > 0 and <= enter_heading_sigma_rad");
  require(std::isfinite(d.exit_position_sigma_m) && d.exit_position_sigma_m > 0.0 &&
              d.exit_position_sigma_m <= d.enter_position_sigma_m,
          "delayed_sampling.exit_position_sigma_m", d.exit_position_sigma_m,
          "must be > 0 and <= enter_position_sigma_m");
  require(d.max_landmarks >= 1 && d.max_landmarks <= 1000, "delayed_sampling.max_landmarks", d.max_landmarks,
          "must be in [1, 1000]");
  const AnchorFrameOptions& a = o.anchor_frame;
  require(a.min_landmarks >= 2 && a.min_landmarks <= 64, "anchor_frame.min_landmarks", a.min_landmarks,
          "must be in [2, 64] (a rotation needs two points)");
  require(a.min_observations >= 1, "anchor_frame.min_observations", a.min_observations, "must be >= 1");
  require(std::isfinite(a.min_spread_m) && a.min_spread_m > 0.0, "anchor_frame.min_spread_m", a.min_spread_m,
          "must be a finite number > 0");
}

double gate_mahalanobis2(const FilterOptions& o) {
  // Chi-square with 2 degrees of freedom: P(d2 <= x) = 1 - exp(-x / 2).
  return -2.0 * std::log(1.0 - o.gate_probability);
}

std::string to_string(Association association) {
  return association == Association::kKnownId ? "known_id" : "maximum_likelihood";
}

std::string to_string(ResampleMode mode) {
  return mode == ResampleMode::kEveryFrame ? "every_frame" : "effective_sample_size";
}

}  // namespace pixyslam::slam
