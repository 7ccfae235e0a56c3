#include "pixyslam/slam/fastslam2.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <Eigen/LU>

#include "pixyslam/slam/observation_model.h"
#include "pixyslam/slam/resampling.h"

namespace pixyslam::slam {
namespace {

constexpr double kMinLandmarkDistanceSq = 1e-6;  // (1 mm)^2
// Above this initial heading sd the heading is split across particles.
constexpr double kMaxLinearHeadingSigma = 0.05;

// erf^-1 on (-1, 1) by Newton's method on std::erf (start: Winitzki's approximation).
double inverse_erf(double y) {
  const double a = 0.147;
  const double l = std::log(1.0 - y * y);
  const double t = 2.0 / (M_PI * a) + 0.5 * l;
  double x = std::copysign(std::sqrt(std::sqrt(t * t - l / a) - t), y);
  for (int k = 0; k < 3; ++k) x -= (std::erf(x) - y) / (2.0 / std::sqrt(M_PI) * std::exp(-x * x));
  return x;
}

// Draws x ~ N(g.mean, g.cov); g.cov may be singular (positive semi-definite).
Pose2 sample_pose(const PoseGaussian& g, std::mt19937_64& rng) {
  std::normal_distribution<double> normal(0.0, 1.0);
  const Eigen::Vector3d e(normal(rng), normal(rng), normal(rng));
  Eigen::LDLT<Eigen::Matrix3d> ldlt(g.cov);
  Eigen::Vector3d d = ldlt.vectorD();
  for (int i = 0; i < 3; ++i) d(i) = d(i) > 0.0 ? std::sqrt(d(i)) : 0.0;
  // cov = P^T L D L^T P, so x = P^T L sqrt(D) e.
  const Eigen::Vector3d y = ldlt.matrixL() * (d.asDiagonal() * e);
  Pose2 x = g.mean + (ldlt.transpositionsP().transpose() * y);
  x.z() = wrap_angle(x.z());
  return x;
}

// Landmarks at most considered as anchors (the first ones seen).
constexpr std::size_t kMaxAnchors = 16;
// Odometry steps kept for late frames (2 MB): a longer time without frames
// (16 min of 67 Hz odometry) applies them to the particles, so a dead camera
// does not grow the filter's memory.
constexpr std::size_t kMaxPendingSteps = 65536;

// Particle p's landmark in `slot` (`in_map` its map's entry): one in the
// particle's joint state has its marginal and counters there, the map catches
// up when the state ends.
Landmark landmark_now(const Particle& p, std::uint32_t slot, const Landmark& in_map) {
  const int i = p.joint.active() ? p.joint->find(slot) : -1;
  if (i < 0) return in_map;
  Landmark lm = in_map;
  lm.mean = p.joint->landmark_mean(i);
  lm.cov = p.joint->landmark_cov(i);
  lm.times_observed = p.joint->landmarks[static_cast<std::size_t>(i)].counts.times_observed;
  lm.consecutive_rejections = p.joint->landmarks[static_cast<std::size_t>(i)].counts.consecutive_rejections;
  return lm;
}

// The map takes a landmark of a joint state that ends.
void map_takes(LandmarkMap& map, const ConditionedLandmark& c) {
  Landmark& lm = map.modify(c.slot);
  lm.mean = c.mean;
  lm.cov = c.cov;
  lm.times_observed = c.counts.times_observed;
  lm.consecutive_rejections = c.counts.consecutive_rejections;
}

// Whether a pose covariance exceeds a heading sd or a position sd (worst direction).
bool exceeds(const Eigen::Matrix3d& cov, double heading_sigma, double position_sigma) {
  if (cov(2, 2) > heading_sigma * heading_sigma) return true;
  const double half_trace = 0.5 * (cov(0, 0) + cov(1, 1));
  const double half_diff = 0.5 * (cov(0, 0) - cov(1, 1));
  const double worst = half_trace + std::sqrt(half_diff * half_diff + cov(0, 1) * cov(0, 1));
  return worst > position_sigma * position_sigma;
}

}  // namespace

FastSlam2::FastSlam2(const FilterOptions& options, const Pose2& initial_pose)
    : FastSlam2(options, PoseGaussian{initial_pose, Eigen::Matrix3d::Zero()}) {}

FastSlam2::FastSlam2(const FilterOptions& options, const PoseGaussian& initial_pose)
    : options_(options), gate_d2_(0.0), rng_(options.seed) {
  validate(options_);
  gate_d2_ = gate_mahalanobis2(options_);
  landmark_ids_ = parse_landmark_ids(options_.landmark_ids);
  new_landmark_d2_ = -2.0 * std::log(1.0 - options_.new_landmark_probability);  // chi-square, 2 dof
  if (!initial_pose.mean.allFinite() || !initial_pose.cov.allFinite() ||
      initial_pose.cov.diagonal().minCoeff() < 0.0) {
    throw std::invalid_argument("FastSlam2: the initial pose and its covariance must be finite, variances >= 0");
  }
  Particle p{initial_pose, 0.0, LandmarkMap(&pool_), SharedJointGaussian{}};
  p.pose.mean.z() = wrap_angle(p.pose.mean.z());
  particles_.assign(static_cast<std::size_t>(options_.particles), p);
  const double heading_var = initial_pose.cov(2, 2);
  if (heading_var <= kMaxLinearHeadingSigma * kMaxLinearHeadingSigma) {
    refresh_caches();
    return;
  }
  // A wide heading: the range-bearing proposal is linear only for small heading
  // errors, so the heading is split across the particles at the quantiles of
  // its marginal and each particle keeps the position conditioned on its heading.
  const Eigen::Vector2d gain = initial_pose.cov.block<2, 1>(0, 2) / heading_var;
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  cov.topLeftCorner<2, 2>() =
      initial_pose.cov.topLeftCorner<2, 2>() - gain * initial_pose.cov.block<1, 2>(2, 0);
  cov(2, 2) = kMaxLinearHeadingSigma * kMaxLinearHeadingSigma;
  const std::size_t m = particles_.size();
  for (std::size_t i = 0; i < m; ++i) {
    const double u = (static_cast<double>(i) + 0.5) / static_cast<double>(m);
    const double offset = std::sqrt(heading_var) * std::sqrt(2.0) * inverse_erf(2.0 * u - 1.0);
    PoseGaussian& g = particles_[i].pose;
    g.mean.head<2>() = initial_pose.mean.head<2>() + gain * offset;
    g.mean.z() = wrap_angle(initial_pose.mean.z() + offset);
    g.cov = cov;
  }
  refresh_caches();
}

void FastSlam2::move_particles(bool joint_states_later) {
  moved_until_s_ = time_s_;
  pending_steps_.clear();
  if (pending_.empty()) return;
  if (joint_states_later) {
    for (Particle& p : particles_) {
      if (!p.joint.active()) pending_.apply(p.pose);
    }
    joint_motion_ = pending_;
    pending_.clear();
    return;
  }
  for (std::size_t i = 0; i < particles_.size();) {
    if (particles_[i].joint.active()) {
      i = move_joint_run(i, pending_);
    } else {
      pending_.apply(particles_[i++].pose);
    }
  }
  pending_.clear();
  refresh_caches();
}

std::size_t FastSlam2::move_joint_run(std::size_t first, const ComposedMotion& motion) {
  Particle& p = particles_[first];
  if (!p.joint.active()) return first + 1;
  // Copies of a particle sit side by side (resampling keeps the order) and may
  // share their joint state: it is moved once, in place when they are its only
  // holders, else into a copy that they take.
  const bool share = options_.share_identical_particles;
  std::size_t end = first + 1;
  while (share && end < particles_.size() && particles_[end].joint.same_state(p.joint)) ++end;
  if (motion.empty()) return end;
  if (share && static_cast<long>(end - first) == p.joint.holders()) {
    p.joint.shared().apply_motion(motion);
  } else {
    p.joint.own().apply_motion(motion);
  }
  for (std::size_t k = first; k < end; ++k) {
    particles_[k].joint = p.joint;
    particles_[k].pose = p.joint->pose();
  }
  return end;
}

void FastSlam2::refresh_caches() {
  const std::size_t n = particles_.size();
  heading_cs_.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    heading_cs_[i] = Eigen::Vector2d(std::cos(particles_[i].pose.mean.z()), std::sin(particles_[i].pose.mean.z()));
  }
  weights_ = normalised_particle_weights();
  // The weighted moments pose_estimate() expands its sums into.
  Moments m;
  m.effective_sample_size = effective_sample_size(weights_);
  m.best = best_index();
  for (std::size_t i = 0; i < n; ++i) {
    const double w = weights_[i];
    m.x += w * particles_[i].pose.mean.x();
    m.y += w * particles_[i].pose.mean.y();
    m.c += w * heading_cs_[i].x();
    m.s += w * heading_cs_[i].y();
  }
  m.heading = std::atan2(m.s, m.c);
  for (std::size_t i = 0; i < n; ++i) {
    const double w = weights_[i];
    const Pose2& pose = particles_[i].pose.mean;
    const double x = pose.x() - m.x, y = pose.y() - m.y;
    const double c = heading_cs_[i].x(), s = heading_cs_[i].y();
    const double t = wrap_angle(pose.z() - m.heading);
    m.xx += w * x * x;
    m.xy += w * x * y;
    m.yy += w * y * y;
    m.xc += w * x * c;
    m.xs += w * x * s;
    m.yc += w * y * c;
    m.ys += w * y * s;
    m.cc += w * c * c;
    m.ss += w * s * s;
    m.cs += w * c * s;
    m.t += w * t;
    m.tt += w * t * t;
    m.xt += w * x * t;
    m.yt += w * y * t;
    m.ct += w * c * t;
    m.st += w * s * t;
    const Eigen::Matrix3d& p = particles_[i].pose.cov;
    m.p += w * p;
    m.cp3 += (w * c) * p.col(2);
    m.sp3 += (w * s) * p.col(2);
    m.pcc += w * p(2, 2) * c * c;
    m.pss += w * p(2, 2) * s * s;
    m.pcs += w * p(2, 2) * c * s;
  }
  moments_ = std::move(m);
}

Pose2 FastSlam2::particle_pose(std::size_t i) const {
  if (pending_.empty()) return particles_[i].pose.mean;
  return pending_.moved_mean(particles_[i].pose.mean, heading_cs_[i].x(), heading_cs_[i].y());
}

void FastSlam2::advance_to(double t_s) {
  if (!has_time_) {
    has_time_ = true;
    time_s_ = t_s;
    moved_until_s_ = t_s;
    return;
  }
  if (t_s <= time_s_) return;
  // The held control expires control_timeout_s after it was received.
  const double control_end = control_time_s_ + options_.control_timeout_s;
  const double moving_until = std::min(t_s, control_end);
  if (moving_until > time_s_ && (control_.v_mps != 0.0 || control_.w_radps != 0.0)) {
    add_pending({control_.v_mps, control_.w_radps, time_s_, moving_until});
  }
  if (t_s > control_end && time_s_ <= control_end && (control_.v_mps != 0.0 || control_.w_radps != 0.0)) {
    ++counters_.control_timeouts;
  }
  time_s_ = t_s;
}

void FastSlam2::add_pending(const MotionStep& step) {
  if (pending_steps_.size() >= kMaxPendingSteps) {
    move_particles();
    moved_until_s_ = step.from_s;
  }
  pending_.add(step.v_mps, step.w_radps, step.to_s - step.from_s, options_.motion);
  pending_steps_.push_back(step);
}

std::vector<FastSlam2::MotionStep> FastSlam2::split_pending_at(double t_s) {
  std::vector<MotionStep> steps;
  steps.swap(pending_steps_);
  pending_.clear();
  std::vector<MotionStep> later;
  // The same steps, of the same lengths, as input in time order would have made.
  for (const MotionStep& s : steps) {
    if (s.to_s <= t_s) {
      add_pending(s);
    } else if (s.from_s >= t_s) {
      later.push_back(s);
    } else {
      add_pending({s.v_mps, s.w_radps, s.from_s, t_s});
      later.push_back({s.v_mps, s.w_radps, t_s, s.to_s});
    }
  }
  return later;
}

void FastSlam2::add_odometry(const OdometrySample& sample) {
  ++counters_.odometry_samples;
  if (!std::isfinite(sample.t_s) || !std::isfinite(sample.v_mps) || !std::isfinite(sample.w_radps) ||
      std::abs(sample.v_mps) > options_.max_speed_mps || std::abs(sample.w_radps) > options_.max_turn_rate_radps) {
    ++counters_.odometry_invalid;
    return;
  }
  if (has_time_ && sample.t_s < time_s_) ++counters_.odometry_out_of_order;
  advance_to(sample.t_s);
  if (!sample.measured) {
    ++counters_.odometry_no_data;
    return;
  }
  control_ = sample;
  control_time_s_ = std::max(sample.t_s, time_s_);
}

std::uint32_t FastSlam2::slot_for(int landmark_id) {
  if (const auto it = slot_of_id_.find(landmark_id); it != slot_of_id_.end()) return it->second;
  std::uint32_t slot = static_cast<std::uint32_t>(id_of_slot_.size());
  if (free_slots_.empty()) {
    id_of_slot_.push_back(landmark_id);
  } else {
    // A recycled slot starts as new: no sighting, no spread.
    slot = free_slots_.back();
    free_slots_.pop_back();
    id_of_slot_[slot] = landmark_id;
    if (slot < last_sighting_s_.size()) last_sighting_s_[slot] = std::numeric_limits<double>::quiet_NaN();
    if (slot < mapped_spread_.size()) {
      mapped_spread_[slot] = Eigen::Matrix2d::Constant(std::numeric_limits<double>::quiet_NaN());
    }
  }
  slot_of_id_.emplace(landmark_id, slot);
  return slot;
}

void FastSlam2::recycle_slots() {
  std::vector<char> held(id_of_slot_.size(), 0);
  for (const std::uint32_t s : free_slots_) held[s] = 1;  // free already
  for (const Particle& p : particles_) {
    p.map.for_each([&held](std::uint32_t slot, const Landmark&) { held[slot] = 1; });
    if (p.joint.active()) {
      for (const JointLandmark& l : p.joint->landmarks) held[l.slot] = 1;
    }
  }
  for (const Anchor& a : anchors_) held[a.slot] = 1;
  for (std::uint32_t s = 0; s < held.size(); ++s) {
    if (held[s] != 0) continue;
    slot_of_id_.erase(id_of_slot_[s]);
    id_of_slot_[s] = kFreeSlot;
    free_slots_.push_back(s);
    ++counters_.landmark_slots_recycled;
  }
}

void FastSlam2::add_observations(const ObservationFrame& frame) {
  ++counters_.frames;
  if (!std::isfinite(frame.t_s)) {
    ++counters_.frames_invalid;
    counters_.observations_invalid += frame.detections.size();
    return;
  }
  const bool late = has_time_ && frame.t_s < time_s_;
  if (!late || frame.t_s < moved_until_s_) {
    if (late) ++counters_.frames_out_of_order;
    advance_to(frame.t_s);
    move_particles(true);
    update_with_frame(frame);
    return;
  }
  // Late, but not older than the particles: the motion up to the stamp, the
  // update, then the rest of the motion again.
  ++counters_.frames_late;
  const std::vector<MotionStep> later = split_pending_at(frame.t_s);
  move_particles(true);
  moved_until_s_ = frame.t_s;
  update_with_frame(frame);
  for (const MotionStep& step : later) add_pending(step);
}

void FastSlam2::update_with_frame(const ObservationFrame& frame) {
  const std::size_t n = frame.detections.size();
  z_.resize(n);
  r_.resize(n);
  slots_.resize(n);
  new_log_likelihood_.resize(n);
  gated_votes_.assign(n, 0);
  std::vector<RangeBearing> valid;
  valid.reserve(n);
  for (const RangeBearing& d : frame.detections) {
    const bool ok = std::isfinite(d.range_m) && std::isfinite(d.bearing_rad) &&
                    d.range_m >= options_.min_range_m && d.range_m <= options_.max_range_m &&
                    std::abs(d.bearing_rad) <= M_PI && plausible_sigma(d.range_sigma_m) &&
                    plausible_sigma(d.bearing_sigma_rad);
    if (!ok) {
      ++counters_.observations_invalid;
      continue;
    }
    if (options_.association == Association::kKnownId && !landmark_ids_.empty() &&
        !contains_id(landmark_ids_, d.landmark_id)) {
      ++counters_.observations_unknown_id;
      continue;
    }
    if (options_.association == Association::kKnownId && slot_of_id_.count(d.landmark_id) == 0 &&
        id_of_slot_.size() >= static_cast<std::size_t>(options_.max_map_landmarks)) {
      ++counters_.observations_over_map_limit;
      continue;
    }
    const std::size_t k = valid.size();
    valid.push_back(d);
    z_[k] = Eigen::Vector2d(d.range_m, d.bearing_rad);
    const double sr = d.range_sigma_m > 0.0 ? d.range_sigma_m
                                            : options_.range_sigma_m + options_.range_sigma_per_m * d.range_m;
    const double sb = d.bearing_sigma_rad > 0.0 ? d.bearing_sigma_rad : options_.bearing_sigma_rad;
    r_[k] = Eigen::Vector2d(sr * sr, sb * sb).asDiagonal();
    if (options_.association == Association::kKnownId) slots_[k] = slot_for(d.landmark_id);
    if (options_.error_correlation_s > 0.0) r_[k] *= correlated_error_factor(slots_[k], frame.t_s);
    new_log_likelihood_[k] = 0.0;  // associate() sets it per particle
  }
  // With maximum likelihood every detection of the frame may start a landmark.
  const auto max_slots = static_cast<std::size_t>(options_.max_map_landmarks);
  if (options_.association == Association::kMaximumLikelihood && slots_in_use() + valid.size() > max_slots) {
    recycle_slots();
    if (slots_in_use() + valid.size() > max_slots) {
      counters_.observations_over_map_limit += valid.size();
      valid.clear();
    }
  }
  if (valid.empty()) {
    if (joint_motion_.empty()) return;
    for (std::size_t i = 0; i < particles_.size();) i = move_joint_run(i, joint_motion_);
    joint_motion_.clear();
    refresh_caches();
    return;
  }

  // Which detections are new is the same for every particle only with known
  // association; decide per particle anyway.
  any_new_.assign(valid.size(), 0);
  new_slots_.assign(valid.size(), -1);
  for (std::size_t i = 0; i < particles_.size();) {
    // A joint state is moved just before its update: one pass over its memory.
    const std::size_t moved_end = move_joint_run(i, joint_motion_);
    while (i < moved_end) {
      const std::size_t end = copies_end(i);
      if (end - i > 1) {
        update_copies(i, end, valid.size());
        i = end;
        continue;
      }
      Particle& p = particles_[i++];
      if (options_.association == Association::kMaximumLikelihood) associate(p);
      update_particle(p, valid);
      count_votes();
    }
  }
  joint_motion_.clear();
  for (std::size_t k = 0; k < valid.size(); ++k) {
    if (2 * gated_votes_[k] > options_.particles) {
      ++counters_.observations_gated;
    } else if (any_new_[k] != 0) {
      ++counters_.observations_new_landmark;
    } else {
      ++counters_.observations_used;
    }
  }
  const bool landmark_floor = options_.landmark_uncertainty && options_.association == Association::kKnownId;
  const std::vector<double> weights = normalised_particle_weights();
  if (landmark_floor) capture_mapped_spread(valid, weights);
  resample_if_needed(weights);
  refresh_caches();
  update_output_frame();
  if (landmark_floor) update_landmark_floor(valid);
}

double FastSlam2::correlated_error_factor(std::uint32_t slot, double t_s) {
  if (last_sighting_s_.size() <= slot) last_sighting_s_.resize(slot + 1, std::numeric_limits<double>::quiet_NaN());
  const double last = last_sighting_s_[slot];
  last_sighting_s_[slot] = t_s;
  if (std::isnan(last)) return 1.0;
  // Two sightings in one frame (or out of order) count as 1 ms apart: bounded.
  const double rho = std::exp(-std::max(t_s - last, 1e-3) / options_.error_correlation_s);
  return (1.0 + rho) / (1.0 - rho);
}

std::vector<double> FastSlam2::normalised_particle_weights() const {
  std::vector<double> log_w(particles_.size());
  for (std::size_t i = 0; i < particles_.size(); ++i) log_w[i] = particles_[i].log_weight;
  return normalised_weights(log_w);
}

void FastSlam2::capture_mapped_spread(const std::vector<RangeBearing>& valid, const std::vector<double>& w) {
  // Before resampling: the spread of each newly mapped landmark over all particles.
  mapped_spread_.resize(id_of_slot_.size(), Eigen::Matrix2d::Constant(std::numeric_limits<double>::quiet_NaN()));
  for (std::size_t k = 0; k < valid.size(); ++k) {
    const std::uint32_t slot = slots_[k];
    if (!std::isnan(mapped_spread_[slot](0, 0))) continue;
    double total = 0.0;
    Eigen::Vector2d m = Eigen::Vector2d::Zero();
    Eigen::Matrix2d second = Eigen::Matrix2d::Zero();
    for (std::size_t i = 0; i < particles_.size(); ++i) {
      const Landmark* in_map = particles_[i].map.find(slot);
      if (in_map == nullptr) continue;
      const Eigen::Vector2d mean = landmark_now(particles_[i], slot, *in_map).mean;
      total += w[i];
      m += w[i] * mean;
      second += w[i] * mean * mean.transpose();  // the means' spread: the pose's part, not the sensor's
    }
    // Mapped once most particles hold it (the rest still carry it in their joint state).
    if (total < 0.5) continue;
    m /= total;
    mapped_spread_[slot] = second / total - m * m.transpose();
  }
}

void FastSlam2::update_landmark_floor(const std::vector<RangeBearing>& valid) {
  // The pose as the landmarks seen now pin it, by their spread at mapping alone.
  const Pose2 pose = particle_frame_estimate().mean;
  Eigen::Matrix3d information = Eigen::Matrix3d::Zero();
  int landmarks = 0;
  for (std::size_t k = 0; k < valid.size(); ++k) {
    const Eigen::Matrix2d& spread = mapped_spread_[slots_[k]];
    if (std::isnan(spread(0, 0))) continue;
    const Particle& best = particles_[best_index()];
    const Landmark* in_map = best.map.find(slots_[k]);
    if (in_map == nullptr) continue;
    const PredictedObservation p = predict_observation(pose, landmark_now(best, slots_[k], *in_map).mean);
    const Eigen::Matrix2d a = p.h_landmark * spread * p.h_landmark.transpose() + 1e-12 * Eigen::Matrix2d::Identity();
    information += p.h_pose.transpose() * a.inverse() * p.h_pose;
    ++landmarks;
  }
  if (landmarks < 2) return;
  const Eigen::FullPivLU<Eigen::Matrix3d> lu(information);
  if (!lu.isInvertible()) return;
  landmark_floor_ = lu.inverse();
  landmark_floor_ = 0.5 * (landmark_floor_ + landmark_floor_.transpose());
}

void FastSlam2::associate(const Particle& p) {
  // Every (detection, mapped landmark) pair within the new-landmark gate, then
  // the most likely pairs first, each detection and landmark used once per
  // frame (two poles seen together are two landmarks).
  struct Candidate {
    double log_likelihood;
    std::size_t k;
    std::uint32_t slot;
  };
  std::vector<Candidate> candidates;
  p.map.for_each([&](std::uint32_t slot, const Landmark& in_map) {
    const Landmark lm = landmark_now(p, slot, in_map);
    if ((lm.mean - p.pose.mean.head<2>()).squaredNorm() < kMinLandmarkDistanceSq) return;
    // A landmark in the particle's joint state moves with its pose: its fit
    // must use their cross-covariance, or its predicted spread counts the pose
    // uncertainty twice and an old landmark out-scores it.
    const int joint_index = p.joint.active() ? p.joint->find(slot) : -1;
    for (std::size_t k = 0; k < new_slots_.size(); ++k) {
      double m2 = 0.0, log_likelihood = 0.0;
      if (joint_index >= 0) {
        const JointFit fit = fit_observation(*p.joint, joint_index, z_[k], r_[k]);
        m2 = fit.mahalanobis2;
        log_likelihood = fit.log_likelihood;
      } else {
        const ObservationFit fit = fit_observation(p.pose, lm.mean, lm.cov, z_[k], r_[k]);
        m2 = fit.mahalanobis2;
        log_likelihood = fit.log_likelihood;
      }
      if (std::isfinite(log_likelihood) && m2 <= new_landmark_d2_) candidates.push_back({log_likelihood, k, slot});
    }
  });
  std::sort(candidates.begin(), candidates.end(),
            [](const Candidate& a, const Candidate& b) { return a.log_likelihood > b.log_likelihood; });
  std::vector<bool> assigned(new_slots_.size(), false);
  std::vector<std::uint32_t> used_slots;
  for (const Candidate& c : candidates) {
    if (assigned[c.k] || std::find(used_slots.begin(), used_slots.end(), c.slot) != used_slots.end()) continue;
    assigned[c.k] = true;
    used_slots.push_back(c.slot);
    slots_[c.k] = c.slot;
  }
  for (std::size_t k = 0; k < new_slots_.size(); ++k) {
    new_log_likelihood_[k] = 0.0;
    if (assigned[k]) continue;
    // A new landmark explains the detection with the likelihood of a fit at the
    // gate boundary (Montemerlo's p0), spread by the particle's pose uncertainty
    // as a landmark there would be: a particle that starts a duplicate then gains
    // nothing over one that associates the detection with its old landmark.
    const double heading = p.pose.mean.z() + z_[k].y();
    const Eigen::Vector2d at = p.pose.mean.head<2>() + z_[k].x() * Eigen::Vector2d(std::cos(heading), std::sin(heading));
    const Eigen::Matrix<double, 2, 3> h = predict_observation(p.pose.mean, at).h_pose;
    const Eigen::Matrix2d s0 = h * p.pose.cov * h.transpose() + r_[k];
    new_log_likelihood_[k] = -0.5 * new_landmark_d2_ - std::log(2.0 * M_PI) - 0.5 * std::log(s0.determinant());
    if (new_slots_[k] < 0) new_slots_[k] = slot_for(next_unlabelled_id_++);
    slots_[k] = static_cast<std::uint32_t>(new_slots_[k]);
  }
}

void FastSlam2::count_votes() {
  for (std::size_t k = 0; k < decision_.size(); ++k) {
    if (decision_[k] == Decision::kGated) ++gated_votes_[k];
    if (decision_[k] == Decision::kNew) any_new_[k] = 1;
  }
}

std::size_t FastSlam2::copies_end(std::size_t first) const {
  const Particle& p = particles_[first];
  if (!options_.share_identical_particles || !options_.delayed_sampling.enabled || !p.joint.active()) {
    return first + 1;
  }
  // A heading split draws a random number in the middle of the update.
  const double spacing = options_.delayed_sampling.enter_heading_sigma_rad;
  if (options_.delayed_sampling.split_heading && std::sqrt(p.joint->heading_variance()) > spacing) return first + 1;
  std::size_t end = first + 1;
  for (; end < particles_.size(); ++end) {
    const Particle& q = particles_[end];
    if (!q.joint.same_state(p.joint) || !q.map.same_tree_as(p.map) || q.log_weight != p.log_weight ||
        q.pose.mean != p.pose.mean || q.pose.cov != p.pose.cov) {
      break;
    }
  }
  // Updated in place only when no one else holds the state.
  return static_cast<long>(end - first) == p.joint.holders() ? end : first + 1;
}

void FastSlam2::update_copies(std::size_t first, std::size_t end, std::size_t detections) {
  Particle& leader = particles_[first];
  if (options_.association == Association::kMaximumLikelihood) associate(leader);  // the same for every copy
  JointGaussian& g = leader.joint.shared();
  const PoseGaussian before = g.pose();
  const std::uint64_t iterated = counters_.joint_iterated_updates;
  const std::uint64_t breakdowns = counters_.joint_breakdowns;
  const JointOutcome outcome = update_joint_state(leader, g, detections);
  const Particle updated = leader;
  copy_decisions_ = decision_;
  const std::uint64_t more_iterated = counters_.joint_iterated_updates - iterated;
  const std::uint64_t more_breakdowns = counters_.joint_breakdowns - breakdowns;
  // The random part (a pose sampled when the state ends) stays each copy's own.
  end_joint_update(leader, outcome, before);
  count_votes();
  for (std::size_t k = first + 1; k < end; ++k) {
    Particle& p = particles_[k];
    p = updated;
    decision_ = copy_decisions_;
    counters_.joint_iterated_updates += more_iterated;
    counters_.joint_breakdowns += more_breakdowns;
    end_joint_update(p, outcome, before);
    count_votes();
  }
}

void FastSlam2::update_particle(Particle& p, const std::vector<RangeBearing>& detections) {
  const DelayedSamplingOptions& delayed = options_.delayed_sampling;
  if (delayed.enabled &&
      (p.joint.active() ||
       exceeds(p.pose.cov, delayed.enter_heading_sigma_rad, delayed.enter_position_sigma_m))) {
    update_particle_joint(p, detections);
    return;
  }
  const std::size_t n = detections.size();
  decision_.assign(n, Decision::kNew);
  PoseGaussian proposal = p.pose;
  double log_w = 0.0;

  // Proposal: fold each observation of a mapped landmark into the pose Gaussian;
  // the product of the sequential predictive densities is the FastSLAM 2.0 weight.
  // The landmarks are unshared right away: every outcome below writes to them.
  landmarks_.assign(n, nullptr);
  for (std::size_t k = 0; k < n; ++k) {
    Landmark* lm = p.map.modify_if_present(slots_[k]);
    landmarks_[k] = lm;
    if (!lm) continue;
    if ((lm->mean - proposal.mean.head<2>()).squaredNorm() < kMinLandmarkDistanceSq) {
      // The particle sits on the landmark: range-bearing is undefined there.
      decision_[k] = Decision::kInvalid;
      continue;
    }
    const ObservationFit fit = fit_observation(proposal, lm->mean, lm->cov, z_[k], r_[k]);
    if (!std::isfinite(fit.mahalanobis2) || !std::isfinite(fit.log_likelihood)) {
      decision_[k] = Decision::kInvalid;
      continue;
    }
    const bool readmit = lm->consecutive_rejections >= static_cast<std::uint32_t>(options_.gate_readmit_after);
    if (options_.gate_enabled && fit.mahalanobis2 > gate_d2_ && !readmit) {
      decision_[k] = Decision::kGated;
      log_w += outlier_log_likelihood(fit.log_likelihood, fit.mahalanobis2);
      continue;
    }
    decision_[k] = Decision::kUsed;
    log_w += fit.log_likelihood;
    fold_into_proposal(proposal, fit);
  }

  for (std::size_t k = 0; k < n; ++k) {
    if (decision_[k] == Decision::kNew) log_w += new_log_likelihood_[k];
  }
  const Pose2 x = sample_pose(proposal, rng_);
  p.pose.mean = x;
  p.pose.cov.setZero();
  p.log_weight += log_w;

  for (std::size_t k = 0; k < n; ++k) {
    switch (decision_[k]) {
      case Decision::kGated:
        ++landmarks_[k]->consecutive_rejections;
        break;
      case Decision::kUsed: {
        Landmark& lm = *landmarks_[k];
        update_landmark(x, z_[k], r_[k], lm.mean, lm.cov);
        ++lm.times_observed;
        lm.consecutive_rejections = 0;
        break;
      }
      case Decision::kNew: {
        const bool seen_this_frame = p.map.find(slots_[k]) != nullptr;
        Landmark& lm = p.map.modify(slots_[k]);
        if (seen_this_frame) {
          update_landmark(x, z_[k], r_[k], lm.mean, lm.cov);
        } else {
          initialise_landmark(x, z_[k], r_[k], lm.mean, lm.cov);
          lm.id = id_of_slot_[slots_[k]];
        }
        ++lm.times_observed;
        break;
      }
      case Decision::kInvalid:
      case Decision::kNewDone:
        break;
    }
  }
}

void FastSlam2::update_particle_joint(Particle& p, const std::vector<RangeBearing>& detections) {
  if (!p.joint.active()) ++counters_.delayed_sampling_starts;
  JointGaussian& g = p.joint.active() ? p.joint.own() : p.joint.begin(p.pose);
  const PoseGaussian before = g.pose();
  end_joint_update(p, update_joint_state(p, g, detections.size()), before);
}

FastSlam2::JointOutcome FastSlam2::update_joint_state(Particle& p, JointGaussian& g, std::size_t n) {
  // The map holds the state's landmarks only from its end on: the state before
  // the frame is kept for a breakdown. One sequential copy: reading just the
  // landmarks' blocks would wait on a cache miss for each.
  mean_before_ = g.mean;
  cov_before_ = g.cov;
  const int landmarks_before = g.landmark_count();
  g.begin_frame();
  decision_.assign(n, Decision::kNew);
  // First sightings join the state first, at the frame pose; they carry no weight.
  for (std::size_t k = 0; k < n; ++k) {
    if (g.find(slots_[k]) >= 0 || p.map.find(slots_[k]) != nullptr) continue;
    g.add_new(slots_[k], z_[k], r_[k]);
    decision_[k] = Decision::kNewDone;
  }
  double log_w = 0.0;
  for (std::size_t k = 0; k < n; ++k) {
    if (decision_[k] == Decision::kNewDone) log_w += new_log_likelihood_[k];
  }
  bool end_joint = false;
  if (options_.delayed_sampling.split_heading) log_w += draw_heading_at_return(p, g);
  for (std::size_t k = 0; k < n; ++k) {
    if (decision_[k] == Decision::kNewDone) continue;
    const int i = joint_index(p, g, k);
    if ((g.landmark_mean(i) - g.mean.head<2>()).squaredNorm() < kMinLandmarkDistanceSq) {
      decision_[k] = Decision::kInvalid;
      continue;
    }
    JointFit fit = fit_observation(g, i, z_[k], r_[k]);
    if (!std::isfinite(fit.mahalanobis2) || !std::isfinite(fit.log_likelihood)) {
      decision_[k] = Decision::kInvalid;
      continue;
    }
    if (options_.gate_enabled && fit.mahalanobis2 > gate_d2_) {
      // Outside the gate at the frame's linearisation: maybe only because a
      // large correction (the heading drifted while blind) is not linear. The
      // re-linearised fit decides; an outlier stays outside.
      const JointFit iterated = fit_observation_iterated(g, i, z_[k], r_[k]);
      if (std::isfinite(iterated.mahalanobis2) && std::isfinite(iterated.log_likelihood) &&
          iterated.mahalanobis2 <= gate_d2_) {
        fit = iterated;
        ++counters_.joint_iterated_updates;
      }
    }
    if (options_.gate_enabled && fit.mahalanobis2 > gate_d2_) {
      // No readmission inside the joint state (one EKF update far outside its
      // linear range can wreck it): a landmark due for readmission ends the
      // joint state instead, and plain FastSLAM 2.0 re-admits it next frame.
      decision_[k] = Decision::kGated;
      log_w += outlier_log_likelihood(fit.log_likelihood, fit.mahalanobis2);
      if (g.landmarks[static_cast<std::size_t>(i)].counts.consecutive_rejections + 1 >=
          static_cast<std::uint32_t>(options_.gate_readmit_after)) {
        end_joint = true;
      }
      continue;
    }
    if (!apply_observation(g, fit)) {
      // Numerical breakdown: the observation is dropped and the particle goes
      // back to plain FastSLAM 2.0 after this frame.
      ++counters_.joint_breakdowns;
      decision_[k] = Decision::kInvalid;
      end_joint = true;
      continue;
    }
    decision_[k] = Decision::kUsed;
    log_w += fit.log_likelihood;
  }
  g.end_frame();
  if (!g.healthy()) {
    // A breakdown no single update showed (a first sighting from a wild pose):
    // the frame is dropped (this frame has not written to the map yet).
    ++counters_.joint_breakdowns;
    decision_.assign(n, Decision::kInvalid);
    marginals_before_.clear();
    for (int i = 0; i < landmarks_before; ++i) {
      const auto u = static_cast<std::size_t>(i);
      const Eigen::Index j = 3 + 2 * i;
      marginals_before_.push_back(
          {g.landmarks[u].slot, mean_before_.segment<2>(j), cov_before_.diagonal_block<2>(j), g.landmarks[u].counts});
    }
    return JointOutcome::kBrokeDown;
  }
  // The counters live in the state (JointGaussian::counts); the map gets an
  // entry for a first sighting only, so that later frames know it is mapped.
  for (std::size_t k = 0; k < n; ++k) {
    if (decision_[k] == Decision::kNew || decision_[k] == Decision::kInvalid) continue;
    LandmarkCounts& counts = g.landmarks[static_cast<std::size_t>(g.find(slots_[k]))].counts;
    switch (decision_[k]) {
      case Decision::kNewDone:
        p.map.modify(slots_[k]).id = id_of_slot_[slots_[k]];
        ++counts.times_observed;
        decision_[k] = Decision::kNew;
        break;
      case Decision::kUsed:
        ++counts.times_observed;
        counts.consecutive_rejections = 0;
        break;
      case Decision::kGated:
        ++counts.consecutive_rejections;
        break;
      case Decision::kNew:
      case Decision::kInvalid:
        break;
    }
  }
  p.log_weight += log_w;
  p.pose = g.pose();
  const DelayedSamplingOptions& delayed = options_.delayed_sampling;
  if (end_joint || !exceeds(p.pose.cov, delayed.exit_heading_sigma_rad, delayed.exit_position_sigma_m) ||
      g.landmark_count() >= delayed.max_landmarks) {
    return JointOutcome::kEnds;
  }
  return JointOutcome::kStays;
}

void FastSlam2::end_joint_update(Particle& p, JointOutcome outcome, const PoseGaussian& before) {
  switch (outcome) {
    case JointOutcome::kStays:
      break;
    case JointOutcome::kEnds:
      finish_joint(p);
      break;
    case JointOutcome::kBrokeDown:
      // The frame is dropped for this particle, which goes on in plain FastSLAM
      // 2.0 from its pose and the state's marginals before the frame.
      for (const ConditionedLandmark& c : marginals_before_) map_takes(p.map, c);
      p.joint.clear();
      p.pose.mean = sample_pose(before, rng_);
      p.pose.cov.setZero();
      break;
  }
}

int FastSlam2::joint_index(const Particle& p, JointGaussian& g, std::size_t k) {
  const int i = g.find(slots_[k]);
  if (i >= 0) return i;
  const Landmark* lm = p.map.find(slots_[k]);
  return g.add_known(slots_[k], lm->mean, lm->cov, {lm->times_observed, lm->consecutive_rejections});
}

double FastSlam2::draw_heading_at_return(Particle& p, JointGaussian& g) {
  // Split only a heading too uncertain to sample from (the joint state's own
  // threshold), into components that narrow.
  const double spacing = options_.delayed_sampling.enter_heading_sigma_rad;
  if (!(std::sqrt(g.heading_variance()) > spacing)) return 0.0;
  // The frame's detections of landmarks mapped outside this state (absolute
  // references); the relative ones turn with the pose and cannot tell.
  known_.clear();
  for (std::size_t k = 0; k < decision_.size(); ++k) {
    if (decision_[k] == Decision::kNewDone) continue;
    if (!g.landmarks[static_cast<std::size_t>(joint_index(p, g, k))].relative) known_.push_back(k);
  }
  if (known_.empty()) return 0.0;
  std::vector<HeadingComponent> components = split_heading(g, spacing);
  if (components.size() < 2) return 0.0;
  std::vector<double> log_likelihood(components.size(), 0.0);
  std::vector<double> log_posterior(components.size(), 0.0);
  double best = -std::numeric_limits<double>::infinity();
  for (std::size_t c = 0; c < components.size(); ++c) {
    JointGaussian s = components[c].state;
    s.begin_frame();
    double ll = 0.0;
    for (const std::size_t k : known_) {
      const int i = s.find(slots_[k]);
      if ((s.landmark_mean(i) - s.mean.head<2>()).squaredNorm() < kMinLandmarkDistanceSq) continue;
      const JointFit fit = fit_observation(s, i, z_[k], r_[k]);
      if (!std::isfinite(fit.mahalanobis2) || !std::isfinite(fit.log_likelihood)) continue;
      if (options_.gate_enabled && fit.mahalanobis2 > gate_d2_) {
        ll += outlier_log_likelihood(fit.log_likelihood, fit.mahalanobis2);
        continue;
      }
      ll += fit.log_likelihood;
      if (!apply_observation(s, fit)) break;
    }
    log_likelihood[c] = ll;
    log_posterior[c] = std::log(components[c].weight) + ll;
    best = std::max(best, log_posterior[c]);
  }
  double total = 0.0;
  for (const double l : log_posterior) total += std::exp(l - best);
  std::uniform_real_distribution<double> uniform(0.0, total);
  double u = uniform(rng_);
  std::size_t chosen = 0;
  for (; chosen + 1 < components.size(); ++chosen) {
    u -= std::exp(log_posterior[chosen] - best);
    if (u <= 0.0) break;
  }
  ++counters_.joint_heading_splits;
  g = std::move(components[chosen].state);
  g.begin_frame();
  return best + std::log(total) - log_likelihood[chosen];
}

void FastSlam2::finish_joint(Particle& p) {
  const Pose2 x = sample_pose(p.joint->pose(), rng_);
  for (const ConditionedLandmark& c : condition_on_pose(*p.joint, x)) map_takes(p.map, c);
  p.pose.mean = x;
  p.pose.cov.setZero();
  p.joint.clear();
}

void FastSlam2::resample_if_needed(const std::vector<double>& w) {
  const double n_eff = effective_sample_size(w);
  const bool resample = options_.resample_mode == ResampleMode::kEveryFrame ||
                        n_eff < options_.resample_neff_fraction * static_cast<double>(particles_.size());
  if (!resample) {
    // Keep log weights bounded: shift so the best is 0.
    double max_log = -std::numeric_limits<double>::infinity();
    for (const Particle& p : particles_) max_log = std::max(max_log, p.log_weight);
    for (Particle& p : particles_) p.log_weight -= max_log;
    return;
  }
  ++counters_.resamples;
  const std::vector<std::size_t> picks = systematic_resample(w, rng_);
  scratch_.clear();
  scratch_.reserve(particles_.size());
  for (std::size_t i : picks) {
    scratch_.push_back(particles_[i]);
    scratch_.back().log_weight = 0.0;
  }
  particles_.swap(scratch_);
  scratch_.clear();  // drops the old maps' references
}

void FastSlam2::set_prior_map(const std::vector<LandmarkEstimate>& landmarks) {
  LandmarkMap map(&pool_);
  for (const LandmarkEstimate& e : landmarks) {
    Landmark& lm = map.modify(slot_for(e.id));
    lm.id = e.id;
    lm.mean = e.mean;
    lm.cov = e.cov;
    lm.times_observed = e.times_observed;
    lm.consecutive_rejections = 0;
  }
  for (Particle& p : particles_) {
    p.map = map;
    p.joint.clear();  // its landmarks belonged to the replaced map
  }
  // The prior map is in the output frame: the particles' frame is that frame now.
  anchors_.clear();
  frame_ = FrameUncertainty();
  frame_.pinned = true;  // the prior map's own uncertainty is in its landmarks
  output_rotation_rad_ = 0.0;
  output_translation_m_.setZero();
}

std::size_t FastSlam2::best_index() const {
  std::size_t best = 0;
  for (std::size_t i = 1; i < particles_.size(); ++i) {
    if (particles_[i].log_weight > particles_[best].log_weight) best = i;
  }
  return best;
}

// The smallest covariance (in the positive semi-definite order) at least `a`
// that is also at least `b`'s excess over it: a + positive part of (b - a).
Eigen::Matrix3d psd_max(const Eigen::Matrix3d& a, const Eigen::Matrix3d& b) {
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig;
  eig.computeDirect(b - a);
  const Eigen::Vector3d positive = eig.eigenvalues().cwiseMax(0.0);
  if (positive.isZero(0.0)) return a;
  return a + eig.eigenvectors() * positive.asDiagonal() * eig.eigenvectors().transpose();
}

PoseEstimate FastSlam2::pose_estimate() const {
  PoseEstimate e = particle_frame_estimate();
  if (frame_.started) {
    // The frame's covariance moved from its pivot to the current position: a
    // frame rotation d theta moves the pose by d theta x (p - pivot).
    Eigen::Matrix3d j = Eigen::Matrix3d::Identity();
    j(0, 2) = -(e.mean.y() - frame_.pivot.y());
    j(1, 2) = e.mean.x() - frame_.pivot.x();
    e.cov = psd_max(e.cov, j * frame_.cov * j.transpose());
  }
  if (options_.landmark_uncertainty && landmark_floor_.allFinite()) e.cov = psd_max(e.cov, landmark_floor_);
  e.best = to_output(e.best);
  e.mean = to_output(e.mean);
  Eigen::Matrix3d r = Eigen::Matrix3d::Identity();
  r.topLeftCorner<2, 2>() = Eigen::Rotation2Dd(output_rotation_rad_).toRotationMatrix();
  e.cov = r * e.cov * r.transpose();
  return e;
}

PoseEstimate FastSlam2::particle_frame_estimate() const {
  // From the particle moments of the last frame (refresh_caches) and the
  // odometry since (pending_): a particle's position is x_i + R_i delta, its
  // heading theta_i + rotation, so every sum over the particles expands into
  // weighted sums of x_i, cos theta_i, sin theta_i and their products.
  const Moments& m = moments_;
  const Eigen::Vector2d delta = pending_.displacement();
  const double a = delta.x(), b = delta.y();
  PoseEstimate e;
  e.t_s = time_s_;
  e.particles = static_cast<int>(particles_.size());
  e.effective_sample_size = m.effective_sample_size;
  const Eigen::Vector2d mean_xy(m.x + m.c * a - m.s * b, m.y + m.s * a + m.c * b);
  e.mean = Pose2(mean_xy.x(), mean_xy.y(), wrap_angle(m.heading + pending_.rotation()));
  // Positions relative to m.x, m.y: sum w p p^T - pbar pbar^T.
  const Eigen::Vector2d mean_rel = mean_xy - Eigen::Vector2d(m.x, m.y);
  Eigen::Matrix2d pp;
  pp(0, 0) = m.xx + 2.0 * (a * m.xc - b * m.xs) + (m.cc * a * a - 2.0 * m.cs * a * b + m.ss * b * b);
  pp(1, 1) = m.yy + 2.0 * (a * m.ys + b * m.yc) + (m.ss * a * a + 2.0 * m.cs * a * b + m.cc * b * b);
  pp(0, 1) = m.xy + (a * m.xs + b * m.xc) + (a * m.yc - b * m.ys) + (m.cs * (a * a - b * b) + (m.cc - m.ss) * a * b);
  pp(1, 0) = pp(0, 1);
  e.cov.topLeftCorner<2, 2>() = pp - mean_rel * mean_rel.transpose();
  // Heading differences to the mean heading do not depend on the pending rotation.
  const Eigen::Vector2d pt(m.xt + a * m.ct - b * m.st, m.yt + a * m.st + b * m.ct);
  e.cov.block<2, 1>(0, 2) = pt - mean_rel * m.t;
  e.cov.block<1, 2>(2, 0) = e.cov.block<2, 1>(0, 2).transpose();
  e.cov(2, 2) = m.tt;
  // sum w F_i P_i F_i^T, F_i = I + u_i e3^T with u_i = R_i (-b, a, 0):
  // P_i + u_i p3_i^T + p3_i u_i^T + P_i(2,2) u_i u_i^T.
  const double g0 = -b, g1 = a;
  Eigen::Matrix<double, 2, 3> up3;
  up3.row(0) = g0 * m.cp3.transpose() - g1 * m.sp3.transpose();
  up3.row(1) = g0 * m.sp3.transpose() + g1 * m.cp3.transpose();
  Eigen::Matrix3d fpf = m.p;
  fpf.topRows<2>() += up3;
  fpf.leftCols<2>() += up3.transpose();
  fpf(0, 0) += m.pcc * g0 * g0 - 2.0 * m.pcs * g0 * g1 + m.pss * g1 * g1;
  fpf(1, 1) += m.pss * g0 * g0 + 2.0 * m.pcs * g0 * g1 + m.pcc * g1 * g1;
  const double off = m.pcs * (g0 * g0 - g1 * g1) + (m.pcc - m.pss) * g0 * g1;
  fpf(0, 1) += off;
  fpf(1, 0) += off;
  e.cov += fpf;
  if (!pending_.empty()) e.cov += pending_.mean_noise(m.c, m.s, m.cc, m.ss, m.cs);
  e.best = particle_pose(m.best);
  return e;
}

Pose2 FastSlam2::to_output(const Pose2& pose) const {
  const Eigen::Vector2d p = Eigen::Rotation2Dd(output_rotation_rad_) * pose.head<2>() + output_translation_m_;
  return Pose2(p.x(), p.y(), wrap_angle(pose.z() + output_rotation_rad_));
}

LandmarkEstimate FastSlam2::to_output(const LandmarkEstimate& landmark) const {
  const Eigen::Matrix2d r = Eigen::Rotation2Dd(output_rotation_rad_).toRotationMatrix();
  LandmarkEstimate out = landmark;
  out.mean = r * landmark.mean + output_translation_m_;
  out.cov = r * landmark.cov * r.transpose();
  return out;
}

std::vector<int> FastSlam2::anchor_ids() const {
  std::vector<int> ids;
  for (const Anchor& a : anchors_) ids.push_back(id_of_slot_[a.slot]);
  return ids;
}

void FastSlam2::mean_positions(const std::vector<std::uint32_t>& slots, std::vector<Eigen::Vector2d>& means,
                               std::vector<bool>& found) const {
  const std::vector<double>& w = weights();
  std::vector<double> total(slots.size(), 0.0);
  means.assign(slots.size(), Eigen::Vector2d::Zero());
  for (std::size_t i = 0; i < particles_.size(); ++i) {
    for (std::size_t k = 0; k < slots.size(); ++k) {
      if (const Landmark* lm = particles_[i].map.find(slots[k])) {
        means[k] += w[i] * landmark_now(particles_[i], slots[k], *lm).mean;
        total[k] += w[i];
      }
    }
  }
  found.assign(slots.size(), false);
  for (std::size_t k = 0; k < slots.size(); ++k) {
    if (total[k] <= 0.0) continue;
    means[k] /= total[k];
    found[k] = true;
  }
}

bool FastSlam2::frame_pinned(std::vector<std::uint32_t>* anchor_slots) const {
  const AnchorFrameOptions& a = options_.anchor_frame;
  // Candidates: the first landmarks the best particle has seen often enough.
  std::vector<std::uint32_t> slots;
  const Particle& best = particles_[best_index()];
  best.map.for_each([&](std::uint32_t slot, const Landmark& in_map) {
    if (landmark_now(best, slot, in_map).times_observed >= static_cast<std::uint32_t>(a.min_observations)) {
      slots.push_back(slot);
    }
  });
  std::sort(slots.begin(), slots.end());
  if (slots.size() > kMaxAnchors) slots.resize(kMaxAnchors);
  if (slots.size() < static_cast<std::size_t>(a.min_landmarks)) return false;
  std::vector<Eigen::Vector2d> means;
  std::vector<bool> found;
  mean_positions(slots, means, found);
  Eigen::Vector2d centroid = Eigen::Vector2d::Zero();
  for (const Eigen::Vector2d& m : means) centroid += m;
  centroid /= static_cast<double>(means.size());
  double spread2 = 0.0;
  for (const Eigen::Vector2d& m : means) spread2 += (m - centroid).squaredNorm();
  if (spread2 / static_cast<double>(means.size()) < a.min_spread_m * a.min_spread_m) return false;
  if (anchor_slots != nullptr) *anchor_slots = std::move(slots);
  return true;
}

void FastSlam2::track_frame_uncertainty() {
  // With maximum-likelihood association the first landmarks are not the same
  // poles in every particle; a prior map (set_prior_map) gives the frame.
  if (!options_.frame_uncertainty || frame_.pinned || options_.association != Association::kKnownId) return;
  if (!frame_.started) {
    if (particles_[best_index()].map.size() == 0) return;
    frame_.started = true;
    frame_.pivot = particle_frame_estimate().mean.head<2>();
  }
  const PoseEstimate e = particle_frame_estimate();
  Eigen::Matrix3d j = Eigen::Matrix3d::Identity();  // from the current position back to the pivot
  j(0, 2) = e.mean.y() - frame_.pivot.y();
  j(1, 2) = -(e.mean.x() - frame_.pivot.x());
  frame_.cov = psd_max(frame_.cov, j * e.cov * j.transpose());
  frame_.pinned = frame_pinned(nullptr);
}

void FastSlam2::update_output_frame() {
  track_frame_uncertainty();
  const AnchorFrameOptions& a = options_.anchor_frame;
  // With maximum-likelihood association a slot is not the same pole in every
  // particle, so its mean over the particles is no anchor.
  if (!a.enabled || options_.association != Association::kKnownId) return;
  std::vector<Eigen::Vector2d> means;
  std::vector<bool> found;
  if (anchors_.empty()) {
    std::vector<std::uint32_t> slots;
    if (!frame_pinned(&slots)) return;
    mean_positions(slots, means, found);
    // Until anchored the output frame is the particles' frame.
    for (std::size_t k = 0; k < slots.size(); ++k) anchors_.push_back({slots[k], means[k]});
    return;
  }
  // Least-squares rigid transform (2-D Procrustes) from the particles' current
  // mean anchors onto the anchored positions.
  std::vector<std::uint32_t> slots;
  for (const Anchor& anchor : anchors_) slots.push_back(anchor.slot);
  mean_positions(slots, means, found);
  Eigen::Vector2d from_c = Eigen::Vector2d::Zero(), to_c = Eigen::Vector2d::Zero();
  int n = 0;
  for (std::size_t k = 0; k < slots.size(); ++k) {
    if (!found[k]) continue;
    from_c += means[k];
    to_c += anchors_[k].position;
    ++n;
  }
  if (n < 2) return;
  from_c /= n;
  to_c /= n;
  double dot = 0.0, cross = 0.0;
  for (std::size_t k = 0; k < slots.size(); ++k) {
    if (!found[k]) continue;
    const Eigen::Vector2d u = means[k] - from_c, v = anchors_[k].position - to_c;
    dot += u.dot(v);
    cross += u.x() * v.y() - u.y() * v.x();
  }
  output_rotation_rad_ = std::atan2(cross, dot);
  output_translation_m_ = to_c - Eigen::Rotation2Dd(output_rotation_rad_) * from_c;
}

std::vector<LandmarkEstimate> FastSlam2::landmarks_of_best() const {
  std::vector<LandmarkEstimate> out;
  const Particle& best = particles_[best_index()];
  best.map.for_each([&](std::uint32_t slot, const Landmark& in_map) {
    const Landmark lm = landmark_now(best, slot, in_map);
    out.push_back(to_output(LandmarkEstimate{lm.id, lm.mean, lm.cov, lm.times_observed}));
  });
  return out;
}

std::vector<LandmarkEstimate> FastSlam2::landmarks_mixture() const {
  const std::vector<double>& w = weights();
  struct Sum {
    double weight = 0.0;
    Eigen::Vector2d m = Eigen::Vector2d::Zero();
    Eigen::Matrix2d second = Eigen::Matrix2d::Zero();  // E[cov + m m^T]
    std::uint32_t times = 0;
  };
  std::vector<Sum> sums(id_of_slot_.size());
  for (std::size_t i = 0; i < particles_.size(); ++i) {
    particles_[i].map.for_each([&](std::uint32_t slot, const Landmark& in_map) {
      const Landmark lm = landmark_now(particles_[i], slot, in_map);
      Sum& s = sums[slot];
      s.weight += w[i];
      s.m += w[i] * lm.mean;
      s.second += w[i] * (lm.cov + lm.mean * lm.mean.transpose());
      s.times = std::max(s.times, lm.times_observed);
    });
  }
  std::vector<LandmarkEstimate> out;
  for (std::size_t slot = 0; slot < sums.size(); ++slot) {
    const Sum& s = sums[slot];
    if (s.weight <= 0.0) continue;
    const Eigen::Vector2d mean = s.m / s.weight;
    out.push_back(to_output(LandmarkEstimate{id_of_slot_[slot], mean, s.second / s.weight - mean * mean.transpose(), s.times}));
  }
  return out;
}

}  // namespace pixyslam::slam
