// Tests of the FastSlam2 filter as a whole: determinism, statistical consistency
// and accuracy on the simulated world, option validation, input robustness
// (invalid and out-of-order samples), the Mahalanobis gate, and the importance
// weights.

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <limits>
#include <memory>
#include <numeric>
#include <random>
#include <stdexcept>
#include <set>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/LU>
#include <Eigen/Eigenvalues>
#include <gtest/gtest.h>

#include "pixyslam/eval/trajectory_metrics.h"
#include "pixyslam/sim/sim_world.h"
#include "pixyslam/slam/fastslam2.h"
#include "pixyslam/slam/motion_model.h"
#include "pixyslam/slam/slam_options.h"
#include "pixyslam/slam/types.h"

namespace pixyslam::slam {
namespace {

// Filter noise densities matching a world whose odometry samples (held for one
// odometry period) carry white v, w errors: sigma_density = sigma_sample * sqrt(period).
FilterOptions options_for_world(const sim::WorldOptions& w, int particles, std::uint64_t seed) {
  FilterOptions o;
  o.particles = particles;
  o.seed = seed;
  const double root_period = std::sqrt(1.0 / w.odometry_rate_hz);
  o.motion.v_sigma_m_per_sqrt_s = w.v_sigma_mps * root_period;
  o.motion.w_sigma_rad_per_sqrt_s = w.w_sigma_radps * root_period;
  o.range_sigma_m = w.range_sigma_m;
  o.bearing_sigma_rad = w.bearing_sigma_rad;
  return o;
}

// Feeds a simulated run in time order (odometry first on equal stamps, as the
// offline runner does). After each odometry sample i, `on_odometry(i)` is called:
// the filter is then at run.truth[i].t_s.
void feed(FastSlam2& f, const sim::WorldRun& run, const std::function<void(std::size_t)>& on_odometry = {},
          const std::function<void()>& on_frame = {}) {
  std::size_t i = 0, k = 0;
  while (i < run.odometry.size() || k < run.frames.size()) {
    const bool take_odometry =
        k == run.frames.size() || (i < run.odometry.size() && run.odometry[i].t_s <= run.frames[k].t_s);
    if (take_odometry) {
      f.add_odometry(run.odometry[i]);
      if (on_odometry) on_odometry(i);
      ++i;
    } else {
      f.add_observations(run.frames[k++]);
      if (on_frame) on_frame();
    }
  }
}

// Odometry alone, sampled at the odometry times.
std::vector<eval::TimedPose> dead_reckoning(const sim::WorldRun& run) {
  std::vector<eval::TimedPose> out;
  Pose2 p = run.initial_pose;
  double t = run.odometry.empty() ? 0.0 : run.odometry.front().t_s;
  OdometrySample control{t, 0.0, 0.0};
  for (const OdometrySample& s : run.odometry) {
    p = move(p, control.v_mps, control.w_radps, s.t_s - t);
    t = s.t_s;
    control = s;
    out.push_back({t, p.x(), p.y(), p.z()});
  }
  return out;
}

void expect_same_estimate(const PoseEstimate& a, const PoseEstimate& b) {
  EXPECT_EQ(a.t_s, b.t_s);
  EXPECT_TRUE(a.mean == b.mean) << a.mean.transpose() << " vs " << b.mean.transpose();
  EXPECT_TRUE(a.cov == b.cov) << a.cov << "\nvs\n" << b.cov;
  EXPECT_TRUE(a.best == b.best);
  EXPECT_EQ(a.effective_sample_size, b.effective_sample_size);
}

void expect_same_landmarks(const std::vector<LandmarkEstimate>& a, const std::vector<LandmarkEstimate>& b) {
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i].id, b[i].id);
    EXPECT_TRUE(a[i].mean == b[i].mean) << "landmark " << a[i].id;
    EXPECT_TRUE(a[i].cov == b[i].cov) << "landmark " << a[i].id;
    EXPECT_EQ(a[i].times_observed, b[i].times_observed);
  }
}

// ------------------------------------------------------------- (a) determinism

TEST(FastSlam2, SameSeedAndInputGiveBitIdenticalResults) {
  sim::WorldOptions w;
  w.duration_s = 40.0;
  const sim::WorldRun run = sim::simulate(w);
  ASSERT_FALSE(run.frames.empty());
  const FilterOptions o = options_for_world(w, 100, 1234);
  FastSlam2 a(o, run.initial_pose);
  FastSlam2 b(o, run.initial_pose);

  // Fed in lockstep, the estimates agree bit for bit after every frame.
  std::size_t i = 0, k = 0;
  while (i < run.odometry.size() || k < run.frames.size()) {
    const bool take_odometry =
        k == run.frames.size() || (i < run.odometry.size() && run.odometry[i].t_s <= run.frames[k].t_s);
    if (take_odometry) {
      a.add_odometry(run.odometry[i]);
      b.add_odometry(run.odometry[i]);
      ++i;
    } else {
      a.add_observations(run.frames[k]);
      b.add_observations(run.frames[k]);
      ++k;
      if (k % 25 == 0) expect_same_estimate(a.pose_estimate(), b.pose_estimate());
    }
  }
  expect_same_estimate(a.pose_estimate(), b.pose_estimate());
  expect_same_landmarks(a.landmarks_of_best(), b.landmarks_of_best());
  expect_same_landmarks(a.landmarks_mixture(), b.landmarks_mixture());
  EXPECT_EQ(a.counters().resamples, b.counters().resamples);
  EXPECT_EQ(a.counters().observations_used, b.counters().observations_used);
  EXPECT_GT(a.counters().resamples, 0u);
  EXPECT_GT(a.landmarks_of_best().size(), 3u);

  // A different filter seed gives a different result on the same input.
  FastSlam2 c(options_for_world(w, 100, 4321), run.initial_pose);
  feed(c, run);
  const PoseEstimate ea = a.pose_estimate(), ec = c.pose_estimate();
  EXPECT_FALSE(ea.mean == ec.mean);
  EXPECT_FALSE(ea.cov == ec.cov);
  // ... but not a wildly different one (both track the same robot).
  EXPECT_LT((ea.mean.head<2>() - ec.mean.head<2>()).norm(), 0.5);
}

// ----------------------------------------------------- (b) consistency, accuracy

// Pose NEES (3 dof, heading error wrapped) of the filter on the simulated world.
//
// Setup and bounds (calibrated on 30 world/filter seed pairs, see below):
//  * Large odometry noise (0.1 m/s and 0.2 rad/s per 10 Hz sample, 3x and 6x the
//    paper's), so that the pose proposal matters: motion alone is far less
//    precise than the observations.
//  * NEES only over t in [2 s, 40 s]: half a lap, before the first loop closure.
//    FastSLAM is known to become overconfident over long runs (path degeneracy,
//    Bailey et al. 2006); with this filter the full 150 s run reaches average
//    NEES 50..400 (200 particles) even when correct, so a long-run bound would
//    not be meaningful.
//  * 1000 particles.
//  * For a consistent filter each step's NEES ~ chi-square(3), mean 3. Errors are
//    strongly autocorrelated in time, so a run's average behaves like a handful
//    of independent chi-square samples, not hundreds: per-run averages of the
//    correct filter ranged 1.5 .. 8.4 over 30 seeds (mean 3.4). Bounds: every
//    run's average in [0.5, 9] (9 ~ 97% quantile of chi-square(3)) and the mean
//    over the runs in [1, 6]. The six runs below give 5.7 1.9 2.5 3.6 1.7 2.3.
//  * What fails: without the proposal (poses sampled from the motion model, a
//    FastSLAM 1.0 proposal with these noises) the mean is ~12 (up to ~46 per run);
//    a wrong sign of d(bearing)/d(theta), a wrong landmark Jacobian or S without
//    the pose term give non-positive-definite covariances or NEES in the 100s+.
//    (A sign error in d(bearing)/d(x, y) alone stays consistent-looking here; it
//    is caught by the Jacobian unit tests and by the ATE test below.)
TEST(FastSlam2, PoseNeesIsConsistentInTheFirstHalfLap) {
  const int kRuns = 6;
  std::vector<double> run_nees;
  for (int r = 1; r <= kRuns; ++r) {
    sim::WorldOptions w;
    w.seed = 100 + r;
    w.duration_s = 40.0;
    w.v_sigma_mps = 0.1;
    w.w_sigma_radps = 0.2;
    const sim::WorldRun run = sim::simulate(w);
    FastSlam2 f(options_for_world(w, 1000, static_cast<std::uint64_t>(r)), run.initial_pose);
    double sum = 0.0;
    int n = 0;
    feed(f, run, [&](std::size_t i) {
      const eval::TimedPose& truth = run.truth[i];
      if (truth.t_s < 2.0) return;
      const PoseEstimate e = f.pose_estimate();
      const Eigen::Vector3d err(truth.x_m - e.mean.x(), truth.y_m - e.mean.y(),
                                wrap_angle(truth.theta_rad - e.mean.z()));
      const double nees = err.dot(e.cov.inverse() * err);
      ASSERT_TRUE(std::isfinite(nees) && nees >= 0.0) << "run " << r << " t " << truth.t_s << " cov\n" << e.cov;
      sum += nees;
      ++n;
    });
    if (HasFatalFailure()) return;
    ASSERT_GT(n, 300);
    run_nees.push_back(sum / n);
    EXPECT_GE(run_nees.back(), 0.5) << "run " << r;
    EXPECT_LE(run_nees.back(), 9.0) << "run " << r;
  }
  const double mean = std::accumulate(run_nees.begin(), run_nees.end(), 0.0) / kRuns;
  EXPECT_GE(mean, 1.0);
  EXPECT_LE(mean, 6.0);
  std::string per_run;
  for (double v : run_nees) per_run += std::to_string(v) + " ";
  RecordProperty("average_nees_per_run", per_run);
}

// A 150 s simulated run with the given odometry noise per sample.
sim::WorldRun noisy_world(std::uint64_t seed, double v_sigma_mps, double w_sigma_radps, sim::WorldOptions& w) {
  w.seed = seed;
  w.duration_s = 150.0;
  w.v_sigma_mps = v_sigma_mps;
  w.w_sigma_radps = w_sigma_radps;
  return sim::simulate(w);
}

// Drops the camera frames of [from_s, to_s] (a blind stretch).
void blind_camera(sim::WorldRun& run, double from_s, double to_s) {
  std::vector<ObservationFrame> kept;
  for (const ObservationFrame& f : run.frames) {
    if (f.t_s < from_s || f.t_s > to_s) kept.push_back(f);
  }
  run.frames = std::move(kept);
}

// The filter's mean pose after every odometry sample of the run.
std::vector<eval::TimedPose> estimated_trajectory(FastSlam2& f, const sim::WorldRun& run) {
  std::vector<eval::TimedPose> est;
  feed(f, run, [&](std::size_t i) {
    const PoseEstimate e = f.pose_estimate();
    est.push_back({run.odometry[i].t_s, e.mean.x(), e.mean.y(), e.mean.z()});
  });
  return est;
}

// With large odometry noise (0.2 m/s, 0.2 rad/s per sample), over ~2 laps, the
// filter's pose error is far below dead reckoning: for the correct filter the
// ATE is ~0.11 of dead reckoning in total (0.28 m at worst per run on x86-64;
// 0.42 m on armhf, whose fused multiply-adds give other random trajectories).
TEST(FastSlam2, PoseErrorFarBelowDeadReckoning) {
  double ate_sum = 0.0, dr_sum = 0.0;
  for (int r = 1; r <= 5; ++r) {
    sim::WorldOptions w;
    const sim::WorldRun run = noisy_world(100 + r, 0.2, 0.2, w);
    FastSlam2 f(options_for_world(w, 100, static_cast<std::uint64_t>(r)), run.initial_pose);
    const eval::TrajectoryErrors slam = eval::compare_trajectory(estimated_trajectory(f, run), run.truth);
    const eval::TrajectoryErrors dr = eval::compare_trajectory(dead_reckoning(run), run.truth);
    ASSERT_GT(slam.samples, 1000u);
    EXPECT_LT(slam.ate_rmse_m, 0.5 * dr.ate_rmse_m) << "run " << r;
    EXPECT_LT(slam.ate_rmse_m, 0.5) << "run " << r;
    EXPECT_LT(slam.heading_rmse_rad, dr.heading_rmse_rad) << "run " << r;
    ate_sum += slam.ate_rmse_m;
    dr_sum += dr.ate_rmse_m;
  }
  EXPECT_LT(ate_sum, 0.25 * dr_sum) << "SLAM " << ate_sum / 5 << " m vs dead reckoning " << dr_sum / 5 << " m";
}

// Ids withheld (maximum-likelihood association), simulated world with
// moderate odometry noise: every pole seen is in the map (none merged into
// another), no landmark lies away from a pole (no phantom), duplicates stay
// few (a pole re-seen after drift beyond the gate starts a second landmark;
// nothing removes it yet), and the pose error is within 1.5 times that of the
// known-id filter.
TEST(FastSlam2, MaximumLikelihoodAssociationMapsEveryPoleWithoutPhantoms) {
  double known_sum = 0.0, unknown_sum = 0.0;
  for (int r = 1; r <= 3; ++r) {
    sim::WorldOptions w;
    const sim::WorldRun run = noisy_world(300 + r, 0.05, 0.05, w);
    FilterOptions options = options_for_world(w, 100, static_cast<std::uint64_t>(r));
    FastSlam2 known(options, run.initial_pose);
    known_sum += eval::compare_trajectory(estimated_trajectory(known, run), run.truth).ate_rmse_m;
    options.association = Association::kMaximumLikelihood;
    options.new_landmark_probability = 0.999;
    FastSlam2 unknown(options, run.initial_pose);
    unknown_sum += eval::compare_trajectory(estimated_trajectory(unknown, run), run.truth).ate_rmse_m;
    std::set<int> seen, mapped_poles;
    for (const ObservationFrame& f : run.frames) {
      for (const RangeBearing& d : f.detections) seen.insert(d.landmark_id);
    }
    const std::vector<LandmarkEstimate> map = unknown.landmarks_of_best();
    for (const LandmarkEstimate& l : map) {
      EXPECT_GE(l.id, FastSlam2::kFirstUnlabelledId);
      const sim::Pole* nearest = nullptr;
      double distance = 1e9;
      for (const sim::Pole& pole : run.poles) {
        const double d = std::hypot(pole.x_m - l.mean.x(), pole.y_m - l.mean.y());
        if (d < distance) {
          distance = d;
          nearest = &pole;
        }
      }
      // Duplicates born while the pose had drifted sit up to ~0.4 m off.
      EXPECT_LT(distance, 0.5) << "run " << r << ": landmark " << l.id << " is no pole";
      if (distance < 0.5) mapped_poles.insert(nearest->id);
    }
    EXPECT_EQ(mapped_poles, seen) << "run " << r;
    EXPECT_LE(map.size(), seen.size() * 3 / 2) << "run " << r;
    RecordProperty("landmarks_run_" + std::to_string(r), static_cast<int>(map.size()));
  }
  EXPECT_LT(unknown_sum, 1.5 * known_sum) << "ATE ids withheld " << unknown_sum / 3 << " m, known " << known_sum / 3;
}

// Ids withheld: every detection some particle cannot associate takes a
// landmark slot, and most such landmarks are resampled away with their
// particles. Their slots are freed for new ones, so a map limit just above
// the world's poles is not reached in a long run (it was after ~6 h at 4096),
// and the estimate is the one without a limit.
TEST(FastSlam2, MaximumLikelihoodFreesTheSlotsOfLandmarksNoParticleHolds) {
  sim::WorldOptions w;
  const sim::WorldRun run = noisy_world(301, 0.05, 0.05, w);
  std::set<int> seen;
  for (const ObservationFrame& f : run.frames) {
    for (const RangeBearing& d : f.detections) seen.insert(d.landmark_id);
  }
  FilterOptions options = options_for_world(w, 100, 1);
  options.association = Association::kMaximumLikelihood;
  options.new_landmark_probability = 0.999;
  FastSlam2 unlimited(options, run.initial_pose);
  const double unlimited_ate = eval::compare_trajectory(estimated_trajectory(unlimited, run), run.truth).ate_rmse_m;
  options.max_map_landmarks = static_cast<int>(2 * seen.size());
  FastSlam2 limited(options, run.initial_pose);
  const double limited_ate = eval::compare_trajectory(estimated_trajectory(limited, run), run.truth).ate_rmse_m;
  std::printf("%zu poles, limit %d: slots freed %llu, observations over the limit %llu; ATE %.3f m (no limit %.3f m)\n",
              seen.size(), options.max_map_landmarks,
              static_cast<unsigned long long>(limited.counters().landmark_slots_recycled),
              static_cast<unsigned long long>(limited.counters().observations_over_map_limit), limited_ate,
              unlimited_ate);
  EXPECT_GT(limited.counters().landmark_slots_recycled, 0u);
  EXPECT_EQ(limited.counters().observations_over_map_limit, 0u);
  EXPECT_LT(limited_ate, 1.25 * unlimited_ate + 0.02);
  EXPECT_LE(limited.landmarks_of_best().size(), 2 * seen.size());
}

// Ids withheld, a known landmark re-seen from an uncertain heading (spread
// across the particles): particles near the true heading associate it, those
// far off start a second landmark. A new landmark is weighted as a fit at the
// gate boundary, so the associating particles must come out ahead, even with
// noise so wide that every fit's likelihood density is below 1.
TEST(FastSlam2, MaximumLikelihoodFavoursAssociatingOverStartingADuplicate) {
  FilterOptions options;
  options.particles = 50;
  options.association = Association::kMaximumLikelihood;
  options.new_landmark_probability = 0.99;
  options.range_sigma_m = 1.0;
  options.bearing_sigma_rad = 0.3;
  options.resample_neff_fraction = 0.01;  // N_eff >= 1 > 0.5: never resample, so the weights stay
  PoseGaussian start;
  start.cov(2, 2) = 0.6 * 0.6;  // split into headings from about -1.4 to +1.4 rad
  FastSlam2 filter(options, start);
  filter.set_prior_map({{FastSlam2::kFirstUnlabelledId - 1, Eigen::Vector2d(3.0, 0.0), 0.01 * Eigen::Matrix2d::Identity(), 5}});
  filter.add_observations({0.0, {{0, 3.0, 0.0, 0.0, 0.0}}});
  int associating = 0;
  for (const Particle& p : filter.particles()) associating += p.map.size() == 1 ? 1 : 0;
  ASSERT_GT(associating, 0);
  ASSERT_LT(associating, options.particles) << "every particle associated: the test sees no choice";
  const std::vector<LandmarkEstimate> best = filter.landmarks_of_best();
  ASSERT_EQ(best.size(), 1u) << "the best particle started a duplicate";
  EXPECT_EQ(best[0].id, FastSlam2::kFirstUnlabelledId - 1);
}

void expect_finite(const PoseEstimate& e);

// The camera is blind for 40 s (frames dropped) while odometry is noisy: the
// pose is far more uncertain than a frame's proposal when landmarks come back.
// Delayed sampling keeps the pose and the landmarks then seen in one Gaussian
// until the loop closes. It must engage, stay finite and deterministic, and
// beat plain FastSLAM 2.0 over the runs.
TEST(FastSlam2, DelayedSamplingThroughACameraGap) {
  double ate_plain = 0.0, ate_delayed = 0.0, dr_sum = 0.0;
  for (int r = 1; r <= 5; ++r) {
    sim::WorldOptions w;
    sim::WorldRun run = noisy_world(200 + r, 0.1, 0.15, w);
    blind_camera(run, 20.0, 60.0);
    auto ate_of = [&](bool delayed, FilterCounters* counters, PoseEstimate* last) {
      FilterOptions o = options_for_world(w, 100, static_cast<std::uint64_t>(r));
      o.delayed_sampling.enabled = delayed;
      FastSlam2 f(o, run.initial_pose);
      const std::vector<eval::TimedPose> est = estimated_trajectory(f, run);
      if (counters) *counters = f.counters();
      if (last) *last = f.pose_estimate();
      return eval::compare_trajectory(est, run.truth).ate_rmse_m;
    };
    FilterCounters counters;
    PoseEstimate last, again;
    const double delayed = ate_of(true, &counters, &last);
    EXPECT_GT(counters.delayed_sampling_starts, 0u) << "run " << r;
    expect_finite(last);
    EXPECT_EQ(ate_of(true, nullptr, &again), delayed) << "run " << r;
    expect_same_estimate(last, again);
    const double dr = eval::compare_trajectory(dead_reckoning(run), run.truth).ate_rmse_m;
    EXPECT_LT(delayed, dr) << "run " << r;
    ate_delayed += delayed;
    const double plain = ate_of(false, nullptr, nullptr);
    ate_plain += plain;
    dr_sum += dr;
  }
  RecordProperty("ate_plain_delayed_deadreckoning",
                 std::to_string(ate_plain / 5) + " " + std::to_string(ate_delayed / 5) + " " +
                     std::to_string(dr_sum / 5));
  // Measured: 0.54 m delayed vs 0.70 m plain on x86-64 (dead reckoning 1.13 m); on armhf,
  // whose fused multiply-adds give other random draws, 0.55 m vs 0.56 m.
  EXPECT_LT(ate_delayed, ate_plain) << "delayed " << ate_delayed / 5 << " m vs plain " << ate_plain / 5 << " m";
}

// The camera is blind for the first 30 s of noisy odometry, so the first
// landmarks are mapped from an uncertain pose: the map's frame is off by about
// that uncertainty for the rest of the run, which later (relative)
// observations cannot reduce but resampling removes from the particle spread.
// frame_uncertainty keeps it as a floor under the output covariance: the
// estimates stay bit-identical, the covariance never shrinks, and the pose NEES
// against the truth falls inside its 95 % bound more often.
// Feeds a run to two filters that differ only in an output option: their
// estimates must stay bit-identical and `with`'s covariance never below
// `without`'s. Counts the steps from from_s on whose pose NEES is under its 95 %
// bound; before_frame runs before every camera frame.
struct NeesBelowBound {
  int with = 0, without = 0, steps = 0;
};
void run_side_by_side(FastSlam2& with, FastSlam2& without, const sim::WorldRun& run, double from_s,
                      NeesBelowBound& count, const std::function<void()>& before_frame = {}) {
  std::size_t i = 0, k = 0;
  while (i < run.odometry.size() || k < run.frames.size()) {
    if (k == run.frames.size() || (i < run.odometry.size() && run.odometry[i].t_s <= run.frames[k].t_s)) {
      with.add_odometry(run.odometry[i]);
      without.add_odometry(run.odometry[i]);
      ++i;
    } else {
      if (before_frame) before_frame();
      with.add_observations(run.frames[k]);
      without.add_observations(run.frames[k]);
      ++k;
    }
    const PoseEstimate a = with.pose_estimate(), b = without.pose_estimate();
    ASSERT_TRUE(a.mean == b.mean && a.best == b.best) << "step " << i + k;
    const Eigen::Matrix3d excess = a.cov - b.cov;
    ASSERT_GE(Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(excess).eigenvalues().minCoeff(),
              -1e-12 * (1.0 + b.cov.norm()))
        << "step " << i + k;
    if (i == 0 || run.odometry[i - 1].t_s < from_s) continue;
    const eval::TimedPose& truth = run.truth[i - 1];
    const Eigen::Vector3d err(truth.x_m - a.mean.x(), truth.y_m - a.mean.y(),
                              wrap_angle(truth.theta_rad - a.mean.z()));
    count.with += err.dot(a.cov.inverse() * err) < 9.3484 ? 1 : 0;
    count.without += err.dot(b.cov.inverse() * err) < 9.3484 ? 1 : 0;
    ++count.steps;
  }
}

// With the option, more than `margin` more steps under the bound.
void expect_more_below_bound(const NeesBelowBound& count, int margin) {
  ASSERT_GT(count.steps, 1000);
  std::printf("NEES below its 95 %% bound: %d with, %d without, of %d steps\n", count.with, count.without,
              count.steps);
  EXPECT_GT(count.with, count.without + margin) << count.with << " vs " << count.without << " of " << count.steps;
}

TEST(FastSlam2, FrameUncertaintyFloorsTheCovarianceAndLeavesTheEstimatesAlone) {
  NeesBelowBound count;
  for (int r = 1; r <= 3; ++r) {
    sim::WorldOptions w;
    sim::WorldRun run = noisy_world(300 + r, 0.05, 0.1, w);
    blind_camera(run, 0.0, 30.0);
    FilterOptions o = options_for_world(w, 100, static_cast<std::uint64_t>(r));
    FastSlam2 without(o, run.initial_pose);
    o.frame_uncertainty = true;
    FastSlam2 with(o, run.initial_pose);
    double heading_var_at_first_map = -1.0;
    run_side_by_side(with, without, run, 40.0, count, [&] {
      if (heading_var_at_first_map < 0.0) heading_var_at_first_map = without.pose_estimate().cov(2, 2);
    });
    // The frame's heading uncertainty from the first mapping stays to the end.
    ASSERT_GT(heading_var_at_first_map, 0.0);
    EXPECT_GE(with.pose_estimate().cov(2, 2), 0.5 * heading_var_at_first_map) << "run " << r;
    EXPECT_LT(without.pose_estimate().cov(2, 2), 0.5 * heading_var_at_first_map) << "run " << r;
  }
  expect_more_below_bound(count, count.steps / 10);
}

// FilterOptions::landmark_uncertainty: the camera is blind from 15 to 45 s, so
// the landmarks first seen after it are mapped from a pose tens of centimetres
// and degrees off; resampling soon forgets that spread. With the option the
// estimates stay bit-identical, the covariance never shrinks, and after the
// blind stretch the pose NEES falls under its 95 % bound more often.
TEST(FastSlam2, LandmarkUncertaintyFloorsTheCovarianceAndLeavesTheEstimatesAlone) {
  NeesBelowBound count;
  for (int r = 1; r <= 3; ++r) {
    sim::WorldOptions w;
    sim::WorldRun run = noisy_world(310 + r, 0.05, 0.1, w);
    blind_camera(run, 15.0, 45.0);
    FilterOptions o = options_for_world(w, 100, static_cast<std::uint64_t>(r));
    o.frame_uncertainty = true;
    FastSlam2 without(o, run.initial_pose);
    o.landmark_uncertainty = true;
    FastSlam2 with(o, run.initial_pose);
    run_side_by_side(with, without, run, 50.0, count);
  }
  expect_more_below_bound(count, count.steps / 20);
}

// FilterOptions::error_correlation_s: a 30 Hz camera whose errors persist for
// about a second (first-order Gauss-Markov, tau = 1 s). Treated as white, each
// frame counts as news and the pose covariance collapses (NEES under its 95 %
// bound at 0 of 1201 steps, seed 321, 70 s); with tau at 66 % of them, and the
// error stays below dead reckoning's (0.165 m, white the same, dead reckoning
// 0.271 m; seeds 321-322 over 60 s: 0.100 against white 0.123 m, but with 50
// particles 0.153 against 0.113 m, and on armhf 0.137 against 0.112 m).
TEST(FastSlam2, CorrelatedErrorsKeepThePoseConsistentAtHighFrameRates) {
  NeesBelowBound count;
  double error_white = 0.0, error_correlated = 0.0, error_dead_reckoning = 0.0;
  for (int r = 1; r <= 1; ++r) {
    sim::WorldOptions w;
    w.seed = 320 + static_cast<std::uint64_t>(r);
    w.duration_s = 70.0;
    w.odometry_rate_hz = 20.0;
    w.camera_rate_hz = 30.0;
    w.v_sigma_mps = 0.03;
    w.w_sigma_radps = 0.1;
    w.range_sigma_m = 0.08;
    w.bearing_sigma_rad = 0.014;
    w.error_correlation_s = 1.0;
    const sim::WorldRun run = sim::simulate(w);
    FilterOptions o = options_for_world(w, 100, static_cast<std::uint64_t>(r));
    FastSlam2 white(o, run.initial_pose);
    o.error_correlation_s = 1.0;
    FastSlam2 correlated(o, run.initial_pose);
    Pose2 dead_reckoning = run.initial_pose;
    for (std::size_t i = 0, k = 0; i < run.odometry.size() || k < run.frames.size();) {
      if (k == run.frames.size() || (i < run.odometry.size() && run.odometry[i].t_s <= run.frames[k].t_s)) {
        const OdometrySample& s = run.odometry[i++];
        white.add_odometry(s);
        correlated.add_odometry(s);
        if (i < run.odometry.size()) dead_reckoning = move(dead_reckoning, s.v_mps, s.w_radps, run.odometry[i].t_s - s.t_s);
        if (s.t_s < 10.0) continue;
        const eval::TimedPose& truth = run.truth[i - 1];
        const auto nees_and_error = [&](const PoseEstimate& e) {
          const Eigen::Vector3d err(truth.x_m - e.mean.x(), truth.y_m - e.mean.y(), wrap_angle(truth.theta_rad - e.mean.z()));
          return std::make_pair(err.dot(e.cov.inverse() * err), err.head<2>().squaredNorm());
        };
        const auto [nees_white, sq_white] = nees_and_error(white.pose_estimate());
        const auto [nees_correlated, sq_correlated] = nees_and_error(correlated.pose_estimate());
        count.without += nees_white < 9.3484 ? 1 : 0;
        count.with += nees_correlated < 9.3484 ? 1 : 0;
        ++count.steps;
        error_white += sq_white;
        error_correlated += sq_correlated;
        error_dead_reckoning += (Eigen::Vector2d(truth.x_m, truth.y_m) - dead_reckoning.head<2>()).squaredNorm();
      } else {
        white.add_observations(run.frames[k]);
        correlated.add_observations(run.frames[k++]);
      }
    }
  }
  expect_more_below_bound(count, count.steps / 5);
  const double n = static_cast<double>(count.steps);
  const double rmse_white = std::sqrt(error_white / n), rmse_correlated = std::sqrt(error_correlated / n),
               rmse_dead_reckoning = std::sqrt(error_dead_reckoning / n);
  std::printf("position RMSE: white %.3f m, with tau %.3f m, dead reckoning %.3f m\n", rmse_white, rmse_correlated,
              rmse_dead_reckoning);
  // Accuracy is not what tau buys: below dead reckoning (armhf's libm takes
  // another random path: 0.137 m against white 0.112 m there).
  EXPECT_LT(rmse_correlated, 0.8 * rmse_dead_reckoning);
}

TEST(FastSlam2, ErrorCorrelationNeedsKnownIds) {
  FilterOptions o;
  o.error_correlation_s = 0.5;
  EXPECT_NO_THROW(validate(o));
  o.association = Association::kMaximumLikelihood;
  EXPECT_THROW(validate(o), std::invalid_argument);
  o.association = Association::kKnownId;
  o.error_correlation_s = -1.0;
  EXPECT_THROW(validate(o), std::invalid_argument);
}

// Odometry is composed and applied to the particles at the next frame;
// pose_estimate() in between expands its sums from the last frame's moments.
// It must equal the estimate of the same particles moved one by one
// (particles() moves them), with and without joint (delayed-sampling) states.
TEST(FastSlam2, EstimateBetweenFramesEqualsTheMovedParticles) {
  for (const bool delayed : {false, true}) {
    sim::WorldOptions w;
    sim::WorldRun run = noisy_world(301, 0.1, 0.15, w);
    std::vector<ObservationFrame> kept;
    for (const ObservationFrame& f : run.frames) {
      if (f.t_s < 10.0 || f.t_s > 30.0) kept.push_back(f);
    }
    run.frames = kept;
    FilterOptions o = options_for_world(w, 50, 3);
    o.delayed_sampling.enabled = delayed;
    FastSlam2 f(o, run.initial_pose);
    double worst_mean = 0.0, worst_cov = 0.0;
    int compared = 0, with_joint = 0;
    feed(f, run, [&](std::size_t i) {
      if (i % 7 != 0) return;
      const PoseEstimate lazy = f.pose_estimate();
      std::vector<Pose2> lazy_poses;
      for (std::size_t k = 0; k < f.particle_count(); ++k) lazy_poses.push_back(f.particle_pose(k));
      bool joint = false;
      for (const Particle& p : f.particles()) joint = joint || p.joint.active();  // moves them
      with_joint += joint ? 1 : 0;
      const PoseEstimate moved = f.pose_estimate();
      for (std::size_t k = 0; k < f.particle_count(); ++k) {
        EXPECT_LT((lazy_poses[k] - f.particles()[k].pose.mean).head<2>().norm(), 1e-9);
      }
      worst_mean = std::max(worst_mean, (lazy.mean.head<2>() - moved.mean.head<2>()).norm());
      worst_mean = std::max(worst_mean, std::abs(wrap_angle(lazy.mean.z() - moved.mean.z())));
      worst_cov = std::max(worst_cov, (lazy.cov - moved.cov).norm() / std::max(1e-12, moved.cov.norm()));
      EXPECT_EQ(lazy.effective_sample_size, moved.effective_sample_size);
      ++compared;
    });
    EXPECT_GT(compared, 50);
    if (delayed) {
      EXPECT_GT(with_joint, 5);
    }
    EXPECT_LT(worst_mean, 1e-9) << "delayed " << delayed;
    EXPECT_LT(worst_cov, 1e-9) << "delayed " << delayed;
  }
}

// ------------------------------------------------------- (c) option validation

std::string invalid_argument_of(const FilterOptions& o) {
  try {
    validate(o);
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  ADD_FAILURE() << "validate() accepted invalid options";
  return "";
}

TEST(FastSlam2, ValidateNamesTheOffendingField) {
  EXPECT_NO_THROW(validate(FilterOptions{}));
  {
    FilterOptions o;
    o.particles = 0;
    EXPECT_NE(invalid_argument_of(o).find("particles"), std::string::npos);
  }
  {
    FilterOptions o;
    o.motion.v_sigma_m_per_sqrt_s = -0.01;
    EXPECT_NE(invalid_argument_of(o).find("motion.v_sigma_m_per_sqrt_s"), std::string::npos);
  }
  {
    FilterOptions o;
    o.motion.w_sigma_rad_per_sqrt_s = -1.0;
    EXPECT_NE(invalid_argument_of(o).find("motion.w_sigma_rad_per_sqrt_s"), std::string::npos);
  }
  {
    FilterOptions o;
    o.range_sigma_m = -0.07;
    EXPECT_NE(invalid_argument_of(o).find("range_sigma_m"), std::string::npos);
  }
  {
    FilterOptions o;
    o.bearing_sigma_rad = std::numeric_limits<double>::quiet_NaN();
    EXPECT_NE(invalid_argument_of(o).find("bearing_sigma_rad"), std::string::npos);
  }
  {
    FilterOptions o;
    o.new_landmark_probability = 1.0;
    EXPECT_NE(invalid_argument_of(o).find("new_landmark_probability"), std::string::npos);
  }
  {
    FilterOptions o;
    o.gate_probability = 1.0;
    EXPECT_NE(invalid_argument_of(o).find("filter.gate.probability"), std::string::npos);
  }
  {
    FilterOptions o;
    o.resample_neff_fraction = 0.0;
    EXPECT_NE(invalid_argument_of(o).find("filter.resample.neff_fraction"), std::string::npos);
  }
  {
    FilterOptions o;
    o.gate_readmit_after = 0;
    EXPECT_NE(invalid_argument_of(o).find("filter.gate.readmit_after"), std::string::npos);
  }
  {
    FilterOptions o;
    o.delayed_sampling.exit_position_sigma_m = o.delayed_sampling.enter_position_sigma_m * 2.0;
    EXPECT_NE(invalid_argument_of(o).find("delayed_sampling.exit_position_sigma_m"), std::string::npos);
  }
  {
    FilterOptions o;
    o.delayed_sampling.max_landmarks = 0;
    EXPECT_NE(invalid_argument_of(o).find("delayed_sampling.max_landmarks"), std::string::npos);
  }
  {
    FilterOptions o;
    o.anchor_frame.min_landmarks = 1;
    EXPECT_NE(invalid_argument_of(o).find("anchor_frame.min_landmarks"), std::string::npos);
  }
  {
    FilterOptions o;
    o.anchor_frame.min_spread_m = 0.0;
    EXPECT_NE(invalid_argument_of(o).find("anchor_frame.min_spread_m"), std::string::npos);
  }
  // The constructor validates too.
  FilterOptions bad;
  bad.particles = 0;
  EXPECT_THROW(FastSlam2(bad, Pose2::Zero()), std::invalid_argument);
}

// ------------------------------------------------- (d), (e) input robustness

void expect_finite(const PoseEstimate& e) {
  EXPECT_TRUE(e.mean.allFinite()) << e.mean.transpose();
  EXPECT_TRUE(e.cov.allFinite()) << e.cov;
  EXPECT_TRUE(e.best.allFinite());
  EXPECT_TRUE(std::isfinite(e.effective_sample_size));
}

TEST(FastSlam2, InvalidObservationsAreCountedAndIgnored) {
  FilterOptions o;
  o.particles = 50;
  FastSlam2 f(o, Pose2(1.0, 2.0, 0.3));
  f.add_odometry({0.0, 0.0, 0.0});  // standing still: later frames re-observe consistently
  const double nan = std::numeric_limits<double>::quiet_NaN();
  ObservationFrame frame{1.0, {}};
  frame.detections.push_back({1, nan, 0.1});          // NaN range
  frame.detections.push_back({2, -1.0, 0.1});         // negative range
  frame.detections.push_back({3, 2.0, 4.0});          // bearing outside [-pi, pi]
  frame.detections.push_back({4, 2.0, 0.2});          // valid
  f.add_observations(frame);
  EXPECT_EQ(f.counters().observations_invalid, 3u);
  EXPECT_EQ(f.counters().observations_new_landmark, 1u);
  expect_finite(f.pose_estimate());
  const std::vector<LandmarkEstimate> lms = f.landmarks_of_best();
  ASSERT_EQ(lms.size(), 1u);
  EXPECT_EQ(lms[0].id, 4);
  EXPECT_TRUE(lms[0].mean.allFinite());

  // A frame of only invalid detections (incl. infinities and a NaN sigma)
  // changes nothing but the counter.
  const PoseEstimate before = f.pose_estimate();
  ObservationFrame bad{1.0, {}};
  bad.detections.push_back({4, std::numeric_limits<double>::infinity(), 0.0});
  bad.detections.push_back({4, 2.0, nan});
  bad.detections.push_back({4, 2.0, 0.1, nan, 0.0});
  bad.detections.push_back({4, 1000.0, 0.1});  // beyond max_range_m
  f.add_observations(bad);
  EXPECT_EQ(f.counters().observations_invalid, 7u);
  EXPECT_EQ(f.counters().observations_used, 0u);
  expect_same_estimate(f.pose_estimate(), before);
  expect_finite(f.pose_estimate());
  EXPECT_EQ(f.landmarks_of_best()[0].times_observed, 1u);

  // The valid landmark is still usable afterwards.
  f.add_observations({2.0, {{4, 2.0, 0.2}}});
  EXPECT_EQ(f.counters().observations_used, 1u);
  expect_finite(f.pose_estimate());
}

// A sender inventing landmark ids cannot grow the map (and every MapState)
// without bound: ids beyond max_map_landmarks are dropped and counted, the
// landmarks already mapped keep being used.
TEST(FastSlam2, NewLandmarkIdsBeyondTheMapLimitAreDroppedAndCounted) {
  for (const Association association : {Association::kKnownId, Association::kMaximumLikelihood}) {
    FilterOptions o;
    o.particles = 20;
    o.max_map_landmarks = 3;
    o.association = association;
    FastSlam2 f(o, Pose2(0.0, 0.0, 0.0));
    f.add_odometry({0.0, 0.0, 0.0});
    f.add_observations({1.0, {{10, 2.0, -0.5}, {11, 2.0, 0.0}, {12, 2.0, 0.5}}});
    ASSERT_EQ(f.landmarks_of_best().size(), 3u);
    // Three more ids, far from the mapped ones, then the first three again.
    f.add_observations({2.0, {{20, 5.0, -2.0}, {21, 5.0, 2.5}, {22, 6.0, 3.0}}});
    f.add_observations({3.0, {{10, 2.0, -0.5}, {11, 2.0, 0.0}, {12, 2.0, 0.5}}});
    EXPECT_EQ(f.landmarks_of_best().size(), 3u);
    if (association == Association::kKnownId) {
      EXPECT_EQ(f.counters().observations_over_map_limit, 3u);
      EXPECT_EQ(f.counters().observations_used, 3u);
    } else {
      // Any detection may start a landmark: a frame that could pass the limit is dropped whole.
      EXPECT_EQ(f.counters().observations_over_map_limit, 6u);
    }
    expect_finite(f.pose_estimate());
  }
}

// With the ids the camera can give configured (association.landmark_ids), a
// sender inventing ids cannot fill the map: its detections are dropped and
// counted, and a real new landmark is still mapped after 4096 invented ids.
TEST(FastSlam2, IdsOutsideTheConfiguredLandmarkIdsAreDroppedAndCounted) {
  FilterOptions o;
  o.particles = 20;
  o.max_map_landmarks = 8;
  o.landmark_ids = {"1-5", "9"};
  FastSlam2 f(o, Pose2(0.0, 0.0, 0.0));
  f.add_odometry({0.0, 0.0, 0.0});
  f.add_observations({1.0, {{1, 2.0, -0.5}, {5, 2.0, 0.5}}});
  for (int i = 0; i < 4096; i += 4) {
    f.add_observations({1.0 + 1e-4 * (i + 1), {{100 + i, 2.0, 0.0}, {101 + i, 3.0, 0.1}, {6 + i % 3, 2.5, 0.2}, {0, 1.5, 0.3}}});
  }
  f.add_observations({2.0, {{9, 2.0, 0.0}}});
  std::vector<int> ids;
  for (const LandmarkEstimate& l : f.landmarks_of_best()) ids.push_back(l.id);
  EXPECT_EQ(ids, (std::vector<int>{1, 5, 9}));
  EXPECT_EQ(f.counters().observations_unknown_id, 4096u);
  EXPECT_EQ(f.counters().observations_over_map_limit, 0u);
  EXPECT_EQ(parse_landmark_ids({"9", "1-5", "4-7", "8"}), (IdRanges{{1, 9}}));
  EXPECT_TRUE(contains_id(parse_landmark_ids({"1-5", "9"}), 9));
  EXPECT_FALSE(contains_id(parse_landmark_ids({"1-5", "9"}), 6));
  EXPECT_FALSE(contains_id(parse_landmark_ids({"1-5", "9"}), 0));
  for (const std::string bad : {"x", "5-1", "-3", "1-", "2000000", "1.5"}) {
    EXPECT_THROW(parse_landmark_ids({bad}), std::invalid_argument) << bad;
  }
  // Maximum likelihood does not read the ids, nor the list: nothing dropped.
  o.association = Association::kMaximumLikelihood;
  FastSlam2 ml(o, Pose2(0.0, 0.0, 0.0));
  ml.add_odometry({0.0, 0.0, 0.0});
  ml.add_observations({1.0, {{100, 2.0, 0.0}}});
  EXPECT_EQ(ml.counters().observations_unknown_id, 0u);
  EXPECT_EQ(ml.landmarks_of_best().size(), 1u);
}

// Property: whatever arrives (NaN, inf, negative or huge ranges, bearings out
// of range, time going backwards or jumping by days, absurd speeds, bursts of
// one landmark, unknown ids), the estimate and the map stay finite. Random
// sequences from fixed seeds, with delayed sampling off and on.
TEST(FastSlam2, HostileInputSequencesNeverProduceNonFiniteEstimates) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  const std::vector<double> odd = {nan, inf, -inf, -1.0, 0.0, 1e-300, 1e300, -1e300, 7.0, 1e6};
  for (std::uint64_t seed = 1; seed <= 6; ++seed) {
    std::mt19937_64 prng(seed);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    auto pick = [&](double sane) { return u(prng) < 0.3 ? odd[prng() % odd.size()] : sane; };
    FilterOptions o;
    o.particles = 20;
    o.seed = seed;
    o.delayed_sampling.enabled = seed % 2 == 0;
    FastSlam2 f(o, Pose2::Zero());
    double t = 0.0;
    for (int step = 0; step < 1500; ++step) {
      const double r = u(prng);
      t = r < 0.02 ? t - 5.0 : (r < 0.03 ? t + 86400.0 : t + 0.1);
      if (u(prng) < 0.5) {
        f.add_odometry({pick(t), pick(0.2 * u(prng)), pick(u(prng) - 0.5)});
      } else {
        ObservationFrame frame{pick(t), {}};
        const int n = u(prng) < 0.05 ? 40 : static_cast<int>(prng() % 4);
        for (int k = 0; k < n; ++k) {
          RangeBearing z;
          z.landmark_id = u(prng) < 0.1 ? static_cast<int>(prng()) : static_cast<int>(prng() % 6);
          z.range_m = pick(0.3 + 3.0 * u(prng));
          z.bearing_rad = pick(u(prng) - 0.5);
          z.range_sigma_m = u(prng) < 0.2 ? pick(0.05) : 0.0;
          z.bearing_sigma_rad = u(prng) < 0.2 ? pick(0.02) : 0.0;
          frame.detections.push_back(z);
        }
        f.add_observations(frame);
      }
      const PoseEstimate e = f.pose_estimate();
      ASSERT_TRUE(e.mean.allFinite() && e.cov.allFinite()) << "seed " << seed << " step " << step;
      for (const LandmarkEstimate& lm : f.landmarks_of_best()) {
        ASSERT_TRUE(lm.mean.allFinite() && lm.cov.allFinite())
            << "seed " << seed << " step " << step << " landmark " << lm.id;
      }
    }
    EXPECT_GT(f.counters().observations_invalid, 0u);
    EXPECT_GT(f.counters().frames_out_of_order + f.counters().odometry_out_of_order, 0u);
  }
}

TEST(FastSlam2, ObservationAtZeroPredictedRangeKeepsTheEstimateFinite) {
  // Regression: a particle whose pose mean coincides with a mapped landmark has
  // predicted range 0 (0/0 in the Jacobians); that NaN once passed the gate and
  // spread into the pose, the map and the weights. Landmark mapped at (2, 0), the
  // robot drives exactly onto it, then a valid detection of it arrives.
  FilterOptions o;
  o.particles = 10;
  FastSlam2 f(o, Pose2::Zero());
  f.add_odometry({0.0, 0.0, 0.0});
  f.add_observations({0.0, {{1, 2.0, 0.0}}});
  f.add_odometry({0.0, 1.0, 0.0});
  f.add_odometry({2.0, 0.0, 0.0});
  f.add_observations({2.1, {{1, 1.0, 0.0}}});
  expect_finite(f.pose_estimate());
  for (const LandmarkEstimate& lm : f.landmarks_of_best()) {
    EXPECT_TRUE(lm.mean.allFinite());
    EXPECT_TRUE(lm.cov.allFinite());
  }
  for (const Particle& p : f.particles()) EXPECT_FALSE(std::isnan(p.log_weight));
}

// An encoder that stops reporting (unplugged) sends periods without wheel
// data: the motion is unknown, not zero, so the filter keeps driving on the
// control it holds, and stops only control_timeout_s after the last measured one.
TEST(FastSlam2, OdometryWithoutWheelDataKeepsTheHeldControlUntilItsTimeout) {
  FilterOptions o;
  o.particles = 20;
  o.control_timeout_s = 2.0;
  FastSlam2 f(o, Pose2::Zero());
  f.add_odometry({0.0, 0.5, 0.0});
  for (int k = 1; k <= 10; ++k) f.add_odometry({0.1 * k, 0.0, 0.0, false});  // 1 s without data
  EXPECT_EQ(f.counters().odometry_no_data, 10u);
  EXPECT_NEAR(f.pose_estimate().mean.x(), 0.5, 0.05) << "moved on at 0.5 m/s";
  for (int k = 11; k <= 40; ++k) f.add_odometry({0.1 * k, 0.0, 0.0, false});  // the control expires at 2 s
  EXPECT_NEAR(f.pose_estimate().mean.x(), 1.0, 0.05);
  EXPECT_EQ(f.counters().control_timeouts, 1u);
  f.add_odometry({4.1, 0.0, 0.0});  // measured: stopped
  f.add_odometry({5.0, 0.0, 0.0});
  EXPECT_NEAR(f.pose_estimate().mean.x(), 1.0, 0.05);
}

TEST(FastSlam2, OutOfOrderSamplesAreCountedAndAppliedAtFilterTime) {
  FilterOptions o;
  o.particles = 20;
  FastSlam2 f(o, Pose2::Zero());
  f.add_odometry({0.0, 0.5, 0.0});
  f.add_odometry({1.0, 0.5, 0.0});
  EXPECT_EQ(f.counters().odometry_out_of_order, 0u);
  EXPECT_NEAR(f.pose_estimate().mean.x(), 0.5, 0.05);

  f.add_odometry({0.5, 0.0, 0.0});  // older than the filter time
  EXPECT_EQ(f.counters().odometry_out_of_order, 1u);
  EXPECT_EQ(f.counters().odometry_samples, 3u);
  EXPECT_DOUBLE_EQ(f.time_s(), 1.0);  // time does not run backwards
  // Its control (stop) is held from the filter time on: no further motion.
  f.add_odometry({2.0, 0.1, 0.0});
  EXPECT_NEAR(f.pose_estimate().mean.x(), 0.5, 0.05);
  expect_finite(f.pose_estimate());

  // A frame older than the filter time but newer than the last frame is applied
  // at its stamp: the robot was at x = 0.5 then, at 0.6 now.
  f.add_odometry({3.0, 0.0, 0.0});
  f.add_observations({1.5, {{1, 2.0, 0.0}}});
  EXPECT_EQ(f.counters().frames_late, 1u);
  EXPECT_EQ(f.counters().frames_out_of_order, 0u);
  EXPECT_NEAR(f.pose_estimate().mean.x(), 0.6, 0.02);
  ASSERT_EQ(f.landmarks_of_best().size(), 1u);
  EXPECT_NEAR(f.landmarks_of_best()[0].mean.x(), 2.5, 0.02);
  // One older than that frame (which is already applied) goes at the filter time, x = 0.6.
  f.add_observations({1.2, {{2, 2.0, 0.0}}});
  EXPECT_EQ(f.counters().frames_out_of_order, 1u);
  EXPECT_EQ(f.counters().observations_new_landmark, 2u);
  EXPECT_DOUBLE_EQ(f.time_s(), 3.0);
  ASSERT_EQ(f.landmarks_of_best().size(), 2u);
  EXPECT_NEAR(f.landmarks_of_best()[1].mean.x(), 2.6, 0.02);
}

// A camera delivered behind the odometry (its bridge stalled, or its link slower):
// each frame arrives after the odometry of the next 0.45 s. Applied at their
// stamps, the frames give the same result, bit for bit, as input in time order,
// through a blind stretch in delayed sampling too.
TEST(FastSlam2, FramesDeliveredBehindTheOdometryGiveTheSameResultAsInTimeOrder) {
  sim::WorldOptions w;
  sim::WorldRun run = noisy_world(31, 0.1, 0.15, w);
  blind_camera(run, 20.0, 45.0);
  FilterOptions o = options_for_world(w, 50, 7);
  o.delayed_sampling.enabled = true;
  FastSlam2 in_order(o, run.initial_pose);
  feed(in_order, run);
  ASSERT_GT(in_order.counters().delayed_sampling_starts, 0u);

  FastSlam2 delayed(o, run.initial_pose);
  std::size_t k = 0;
  for (const OdometrySample& s : run.odometry) {
    delayed.add_odometry(s);
    while (k < run.frames.size() && run.frames[k].t_s + 0.45 <= s.t_s) delayed.add_observations(run.frames[k++]);
  }
  while (k < run.frames.size()) delayed.add_observations(run.frames[k++]);

  const auto late = std::count_if(run.frames.begin(), run.frames.end(),
                                  [&](const ObservationFrame& f) { return f.t_s < run.odometry.back().t_s; });
  EXPECT_EQ(delayed.counters().frames_late, static_cast<std::uint64_t>(late));
  EXPECT_GT(late, 500);
  EXPECT_EQ(delayed.counters().frames_out_of_order, 0u);
  expect_same_estimate(in_order.pose_estimate(), delayed.pose_estimate());
  expect_same_landmarks(in_order.landmarks_of_best(), delayed.landmarks_of_best());
  EXPECT_EQ(in_order.counters().resamples, delayed.counters().resamples);
  EXPECT_EQ(in_order.counters().delayed_sampling_starts, delayed.counters().delayed_sampling_starts);
}

void expect_same_counters(const FilterCounters& a, const FilterCounters& b) {
  EXPECT_EQ(a.frames, b.frames);
  EXPECT_EQ(a.observations_used, b.observations_used);
  EXPECT_EQ(a.observations_new_landmark, b.observations_new_landmark);
  EXPECT_EQ(a.observations_gated, b.observations_gated);
  EXPECT_EQ(a.observations_invalid, b.observations_invalid);
  EXPECT_EQ(a.resamples, b.resamples);
  EXPECT_EQ(a.delayed_sampling_starts, b.delayed_sampling_starts);
  EXPECT_EQ(a.joint_breakdowns, b.joint_breakdowns);
  EXPECT_EQ(a.joint_iterated_updates, b.joint_iterated_updates);
  EXPECT_EQ(a.joint_heading_splits, b.joint_heading_splits);
}

// Resampled copies of a particle in delayed sampling share one joint state,
// moved and updated once for all of them: the particles, estimates and
// counters are bit-identical to updating every copy on its own, with known ids,
// with the ids withheld and with heading splits (whose random draws end the
// sharing for that frame). A particle copied out of the filter keeps its state.
TEST(FastSlam2, CopiesOfAParticleShareOneJointStateWithTheSameResult) {
  sim::WorldOptions w;
  sim::WorldRun run = noisy_world(41, 0.1, 0.15, w);
  blind_camera(run, 20.0, 50.0);
  run.frames.erase(std::remove_if(run.frames.begin(), run.frames.end(),
                                  [](const ObservationFrame& f) { return f.t_s > 90.0; }),
                   run.frames.end());
  // A start known only roughly in a map of three known poles: the particles
  // begin with different headings, and the poles tell them apart.
  PoseGaussian start;
  start.mean = run.initial_pose;
  start.cov = Eigen::Vector3d(0.2, 0.2, 0.1).asDiagonal();
  std::vector<LandmarkEstimate> prior;
  for (std::size_t i = 0; i < 3; ++i) {
    prior.push_back({run.poles[i].id, Eigen::Vector2d(run.poles[i].x_m, run.poles[i].y_m), Eigen::Matrix2d::Identity() * 1e-4, 5});
  }
  for (int variant = 0; variant < 3; ++variant) {
    SCOPED_TRACE(variant == 0 ? "known ids" : variant == 1 ? "ids withheld" : "heading split");
    FilterOptions o = options_for_world(w, 60, 11);
    o.delayed_sampling.enabled = true;
    // Exit as config/slam_mrclam.yaml does: late, so joint states see resampling.
    o.delayed_sampling.exit_heading_sigma_rad = 0.02;
    o.delayed_sampling.exit_position_sigma_m = 0.06;
    if (variant == 1) o.association = Association::kMaximumLikelihood;
    if (variant == 2) o.delayed_sampling.split_heading = true;
    FastSlam2 shared(o, start);
    o.share_identical_particles = false;
    FastSlam2 alone(o, start);
    shared.set_prior_map(prior);
    alone.set_prior_map(prior);
    std::vector<Particle> copied_out;
    std::vector<JointGaussian> copied_values;
    std::size_t joint_particles = 0, joint_states = 0;  // summed over the frames
    feed(shared, run, [&](std::size_t i) { alone.add_odometry(run.odometry[i]); }, [&]() {
      alone.add_observations(run.frames[static_cast<std::size_t>(shared.counters().frames - 1)]);
      expect_same_estimate(shared.pose_estimate(), alone.pose_estimate());
      std::set<const JointGaussian*> states;
      std::size_t joint = 0;
      for (const Particle& p : shared.particles()) {
        if (!p.joint.active()) continue;
        ++joint;
        states.insert(&*p.joint);
      }
      joint_particles += joint;
      joint_states += states.size();
      if (copied_out.empty() && joint > 0) {
        copied_out = shared.particles();
        for (const Particle& p : copied_out) copied_values.push_back(p.joint.active() ? *p.joint : JointGaussian{});
      }
    });
    const std::vector<Particle>& a = shared.particles();
    const std::vector<Particle>& b = alone.particles();
    ASSERT_EQ(a.size(), b.size());
    for (std::size_t i = 0; i < a.size(); ++i) {
      EXPECT_TRUE(a[i].pose.mean == b[i].pose.mean && a[i].pose.cov == b[i].pose.cov) << "particle " << i;
      EXPECT_EQ(a[i].log_weight, b[i].log_weight) << "particle " << i;
      ASSERT_EQ(a[i].joint.active(), b[i].joint.active()) << "particle " << i;
      if (a[i].joint.active()) {
        EXPECT_TRUE(a[i].joint->cov == b[i].joint->cov) << "particle " << i;
      }
    }
    expect_same_landmarks(shared.landmarks_mixture(), alone.landmarks_mixture());
    expect_same_counters(shared.counters(), alone.counters());
    EXPECT_GT(shared.counters().delayed_sampling_starts, 0u);
    if (variant == 2) {
      EXPECT_GT(shared.counters().joint_heading_splits, 0u);
    }
    // Copies did share: fewer states than particles holding one.
    // (Measured: 7,493 states for 9,237 particles with known ids.)
    EXPECT_GT(joint_particles, 5000u);
    EXPECT_LT(joint_states, joint_particles);
    // The particles copied out were not moved or updated with the filter's.
    ASSERT_FALSE(copied_out.empty());
    for (std::size_t i = 0; i < copied_out.size(); ++i) {
      if (!copied_out[i].joint.active()) continue;
      EXPECT_TRUE(copied_out[i].joint->mean == copied_values[i].mean) << "particle " << i;
      EXPECT_TRUE(copied_out[i].joint->cov == copied_values[i].cov) << "particle " << i;
    }
  }
}

// A joint state that an update would break (a first sighting with sigmas of
// 1 km and 1,000 rad, the most a detection may carry: a landmark variance over (1 km)^2)
// is dropped for that frame: the particle samples its pose, and its map holds
// the state's landmarks as they were before the frame. With copies sharing
// their state and without, the same particles.
TEST(FastSlam2, AJointStateThatBreaksDownLeavesItsLandmarksAsBeforeTheFrame) {
  PoseGaussian start;
  start.mean = Pose2::Zero();
  start.cov = Eigen::Vector3d(0.2, 0.2, 0.04).asDiagonal();
  std::vector<std::vector<Pose2>> after;  // poses only: maps must not outlive their filter's pool
  for (const bool share : {true, false}) {
    FilterOptions o;
    o.particles = 40;
    o.delayed_sampling.enabled = true;
    o.delayed_sampling.exit_heading_sigma_rad = 0.001;  // stays joint
    o.delayed_sampling.exit_position_sigma_m = 0.001;
    o.resample_mode = ResampleMode::kEveryFrame;
    o.share_identical_particles = share;
    FastSlam2 f(o, start);
    f.set_prior_map({{1, Eigen::Vector2d(2.0, 0.0), Eigen::Matrix2d::Identity() * 1e-4, 5}});
    f.add_odometry({0.0, 0.0, 0.0});
    for (int k = 1; k <= 10; ++k) f.add_observations({0.1 * k, {{1, 2.0, 0.0}, {2, 2.0, M_PI / 2}}});
    std::set<const JointGaussian*> states;
    for (const Particle& p : f.particles()) {
      ASSERT_TRUE(p.joint.active());
      states.insert(&*p.joint);
    }
    if (share) {
      EXPECT_LT(states.size(), 40u);  // resampled copies share their state
    }
    const std::vector<LandmarkEstimate> before = f.landmarks_mixture();
    ASSERT_EQ(before.size(), 2u);
    EXPECT_EQ(before[0].times_observed, 15u);  // 5 in the prior map, 10 in the state
    EXPECT_EQ(before[1].times_observed, 10u);
    f.add_observations({1.1, {{3, 3.0, 0.0, 1e3, 1e3}}});
    EXPECT_EQ(f.counters().joint_breakdowns, 40u);
    for (const Particle& p : f.particles()) {
      EXPECT_FALSE(p.joint.active());
      EXPECT_EQ(p.map.size(), 2u);  // landmark 3 not mapped
    }
    expect_same_landmarks(f.landmarks_mixture(), before);
    after.emplace_back();
    for (const Particle& p : f.particles()) after.back().push_back(p.pose.mean);
  }
  EXPECT_TRUE(after[0] == after[1]);
}

// Inside a joint state a landmark's counters live in the state: an outlier
// gated gate_readmit_after times in a row ends the state (plain FastSLAM 2.0
// readmits it next frame), the map then holds the counters, and the
// readmission resets them.
TEST(FastSlam2, AJointStateCountsGatedObservationsAndEndsForReadmission) {
  PoseGaussian start;
  start.mean = Pose2::Zero();
  start.cov = Eigen::Vector3d(0.2, 0.2, 0.04).asDiagonal();
  FilterOptions o;
  o.particles = 20;
  o.gate_enabled = true;
  o.gate_probability = 0.999;
  o.gate_readmit_after = 3;
  o.delayed_sampling.enabled = true;
  o.delayed_sampling.exit_heading_sigma_rad = 1e-6;  // stays joint until the gate ends it
  o.delayed_sampling.exit_position_sigma_m = 1e-6;
  FastSlam2 f(o, start);
  f.set_prior_map({{7, Eigen::Vector2d(2.0, 0.0), Eigen::Matrix2d::Identity() * 1e-4, 4}});
  f.add_odometry({0.0, 0.0, 0.0});
  double t = 0.0;
  for (int i = 0; i < 5; ++i) f.add_observations({t += 0.1, {{7, 2.0, 0.0}}});
  for (const Particle& p : f.particles()) ASSERT_TRUE(p.joint.active());
  EXPECT_EQ(f.landmarks_of_best().at(0).times_observed, 9u);
  for (int i = 1; i <= 2; ++i) {
    f.add_observations({t += 0.1, {{7, 7.0, 0.0}}});
    for (const Particle& p : f.particles()) {
      ASSERT_TRUE(p.joint.active());
      EXPECT_EQ(p.joint->landmarks.at(0).counts.consecutive_rejections, static_cast<std::uint32_t>(i));
      EXPECT_EQ(p.map.find(0)->consecutive_rejections, 0u);  // the map catches up later
    }
  }
  f.add_observations({t += 0.1, {{7, 7.0, 0.0}}});
  EXPECT_EQ(f.counters().observations_gated, 3u);
  for (const Particle& p : f.particles()) {
    ASSERT_FALSE(p.joint.active());
    EXPECT_EQ(p.map.find(0)->consecutive_rejections, 3u);
    EXPECT_EQ(p.map.find(0)->times_observed, 9u);
  }
  const std::uint64_t used = f.counters().observations_used;
  f.add_observations({t += 0.1, {{7, 7.0, 0.0}}});
  EXPECT_EQ(f.counters().observations_used, used + 1);
  EXPECT_EQ(f.landmarks_of_best().at(0).times_observed, 10u);
}

// The odometry steps kept for late frames are bounded: after 65,536 of them
// without a frame they are applied to the particles, and only frames after that
// can still be applied at their stamps.
TEST(FastSlam2, OdometryKeptForLateFramesIsBounded) {
  FilterOptions o;
  o.particles = 10;
  o.motion.v_sigma_m_per_sqrt_s = 1e-4;  // the pose stays known to millimetres over the 700 s
  o.motion.w_sigma_rad_per_sqrt_s = 1e-5;
  FastSlam2 f(o, Pose2::Zero());
  for (int k = 0; k <= 70000; ++k) f.add_odometry({0.01 * k, 0.1, 0.0});
  EXPECT_NEAR(f.pose_estimate().mean.x(), 70.0, 0.5);
  f.add_observations({699.0, {{1, 1.0, 0.0}}});  // after the bound: at its stamp, x = 69.9
  EXPECT_EQ(f.counters().frames_late, 1u);
  ASSERT_EQ(f.landmarks_of_best().size(), 1u);
  EXPECT_NEAR(f.landmarks_of_best()[0].mean.x(), 70.9, 0.05);
  f.add_observations({600.0, {{2, 1.0, 0.0}}});  // before it (and before that frame): at the filter time
  EXPECT_EQ(f.counters().frames_out_of_order, 1u);
  ASSERT_EQ(f.landmarks_of_best().size(), 2u);
  EXPECT_NEAR(f.landmarks_of_best()[1].mean.x(), 71.0, 0.05);
  FastSlam2 g(o, Pose2::Zero());
  for (int k = 0; k <= 70000; ++k) g.add_odometry({0.01 * k, 0.1, 0.0});
  g.add_observations({600.0, {{2, 1.0, 0.0}}});  // older than the bound alone
  EXPECT_EQ(g.counters().frames_out_of_order, 1u);
  EXPECT_EQ(g.counters().frames_late, 0u);
}

TEST(FastSlam2, HeldControlTimesOut) {
  FilterOptions o;
  o.particles = 20;
  o.control_timeout_s = 5.0;
  FastSlam2 f(o, Pose2::Zero());
  f.add_odometry({0.0, 1.0, 0.0});
  f.add_observations({10.0, {}});  // no odometry for 10 s: moves only 5 s
  EXPECT_EQ(f.counters().control_timeouts, 1u);
  EXPECT_NEAR(f.pose_estimate().mean.x(), 5.0, 0.1);
}

// ---------------------------------------------------------------- (f) gating

TEST(FastSlam2, GrossOutlierIsGatedThenReadmitted) {
  // Given a stationary robot that has observed landmark 7 at (2, 0) 20 times,
  FilterOptions o;
  o.particles = 100;
  o.gate_enabled = true;
  o.gate_probability = 0.999;
  o.gate_readmit_after = 3;
  FastSlam2 f(o, Pose2::Zero());
  f.add_odometry({0.0, 0.0, 0.0});
  double t = 0.0;
  for (int i = 0; i < 20; ++i) f.add_observations({t += 0.1, {{7, 2.0, 0.0}}});
  EXPECT_EQ(f.counters().observations_new_landmark, 1u);
  EXPECT_EQ(f.counters().observations_used, 19u);
  EXPECT_EQ(f.counters().observations_gated, 0u);
  const Eigen::Vector2d established = f.landmarks_of_best().at(0).mean;
  EXPECT_NEAR(established.x(), 2.0, 0.05);

  // when it is reported 5 m off, the observation is gated gate_readmit_after times,
  for (int i = 1; i <= 3; ++i) {
    f.add_observations({t += 0.1, {{7, 7.0, 0.0}}});
    EXPECT_EQ(f.counters().observations_gated, static_cast<std::uint64_t>(i));
    EXPECT_EQ(f.counters().observations_used, 19u);
  }
  // leaving the landmark and the pose alone,
  EXPECT_TRUE(f.landmarks_of_best().at(0).mean.isApprox(established, 1e-12));
  EXPECT_LT(f.pose_estimate().mean.norm(), 1e-9);
  // and the next one is readmitted (a drifted particle can recover).
  f.add_observations({t += 0.1, {{7, 7.0, 0.0}}});
  EXPECT_EQ(f.counters().observations_gated, 3u);
  EXPECT_EQ(f.counters().observations_used, 20u);
  expect_finite(f.pose_estimate());
  EXPECT_GT(f.landmarks_of_best().at(0).mean.x(), established.x() + 0.01);
  // The rejection count restarted: the next outlier is gated again.
  f.add_observations({t += 0.1, {{7, 7.0, 0.0}}});
  EXPECT_EQ(f.counters().observations_gated, 4u);
}

TEST(FastSlam2, DisabledGateUsesEveryObservation) {
  FilterOptions o;
  o.particles = 20;
  o.gate_enabled = false;
  FastSlam2 f(o, Pose2::Zero());
  f.add_odometry({0.0, 0.0, 0.0});
  double t = 0.0;
  for (int i = 0; i < 10; ++i) f.add_observations({t += 0.1, {{7, 2.0, 0.0}}});
  f.add_observations({t += 0.1, {{7, 7.0, 0.0}}});
  EXPECT_EQ(f.counters().observations_gated, 0u);
  EXPECT_EQ(f.counters().observations_used, 10u);
}

// ------------------------------------------------------ (g) importance weights

TEST(FastSlam2, WeightsFavourParticlesThatExplainTheObservation) {
  // Landmarks 1 at (2, 0) and 2 at (0, 2) are mapped from the known start pose.
  // After very noisy odometry, frame A sees only a NEW landmark, so every
  // particle samples its pose from the motion model alone (all weights equal).
  // Frame B, at the same time, re-observes landmarks 1 and 2: the particles'
  // poses now have zero covariance and cannot move, so only the importance
  // weights can pull the estimate from the odometry's (0.5, 0, 0) to the truth.
  FilterOptions o;
  o.particles = 2000;
  o.seed = 42;
  o.motion = MotionNoise{0.3, 0.3, 0.0, 0.0};
  o.gate_enabled = false;
  o.resample_mode = ResampleMode::kEffectiveSampleSize;
  o.resample_neff_fraction = 1e-9;  // never resample: look at the raw weights
  const double sr = 0.03, sb = 0.015;
  FastSlam2 f(o, Pose2::Zero());
  f.add_odometry({0.0, 0.0, 0.0});
  f.add_observations({0.0, {{1, 2.0, 0.0, sr, sb}, {2, 2.0, M_PI / 2, sr, sb}}});
  f.add_odometry({0.0, 0.5, 0.0});
  f.add_odometry({1.0, 0.0, 0.0});

  // A pose the motion model can reach (distance 0.6 m, rotation 0.2 rad).
  const Pose2 truth = move(Pose2::Zero(), 0.6, 0.2, 1.0);
  auto observe = [&](int id, const Eigen::Vector2d& lm) {
    const double dx = lm.x() - truth.x(), dy = lm.y() - truth.y();
    return RangeBearing{id, std::hypot(dx, dy), wrap_angle(std::atan2(dy, dx) - truth.z()), sr, sb};
  };
  f.add_observations({1.0, {{3, 1.0, 0.5, sr, sb}}});
  EXPECT_EQ(f.counters().observations_new_landmark, 3u);
  EXPECT_NEAR(f.pose_estimate().effective_sample_size, 2000.0, 1e-6);
  Eigen::Vector2d unweighted = Eigen::Vector2d::Zero();
  for (const Particle& p : f.particles()) unweighted += p.pose.mean.head<2>();
  unweighted /= 2000.0;
  EXPECT_NEAR(unweighted.x(), 0.5, 0.03);  // the motion model's mean

  f.add_observations({1.0, {observe(1, Eigen::Vector2d(2.0, 0.0)), observe(2, Eigen::Vector2d(0.0, 2.0))}});
  EXPECT_EQ(f.counters().observations_used, 2u);
  EXPECT_EQ(f.counters().resamples, 0u);
  const PoseEstimate e = f.pose_estimate();
  EXPECT_LT(e.effective_sample_size, 0.1 * 2000.0);
  const double weighted_error = (e.mean.head<2>() - truth.head<2>()).norm();
  const double unweighted_error = (unweighted - truth.head<2>()).norm();
  EXPECT_GT(unweighted_error, 0.1);
  EXPECT_LT(weighted_error, 0.3 * unweighted_error)
      << "weighted " << weighted_error << " m, unweighted " << unweighted_error << " m";
  EXPECT_LT((e.best.head<2>() - truth.head<2>()).norm(), 0.05);
  EXPECT_NEAR(wrap_angle(e.mean.z() - truth.z()), 0.0, 0.05);
}

TEST(FastSlam2, ResamplingEveryFrameResetsWeights) {
  FilterOptions o;
  o.particles = 200;
  o.motion = MotionNoise{0.3, 0.3, 0.0, 0.0};
  o.resample_mode = ResampleMode::kEveryFrame;
  FastSlam2 f(o, Pose2::Zero());
  f.add_odometry({0.0, 0.0, 0.0});
  f.add_observations({0.0, {{1, 2.0, 0.0}, {2, 2.0, 1.5}}});
  f.add_odometry({0.0, 0.5, 0.1});
  for (int i = 1; i <= 5; ++i) {
    f.add_observations({0.2 * i, {{1, 2.0 - 0.1 * i, 0.0}, {2, 2.0, 1.5}}});
    EXPECT_EQ(f.counters().resamples, static_cast<std::uint64_t>(i + 1));
    for (const Particle& p : f.particles()) EXPECT_EQ(p.log_weight, 0.0);
    EXPECT_NEAR(f.pose_estimate().effective_sample_size, 200.0, 1e-9);
  }
}

// ------------------------------------------------------- observation noise

TEST(FastSlam2, ObservationNoiseFromOptionsOrDetection) {
  // From a known pose, a first sighting straight ahead initialises the landmark
  // with the range variance along x and (r sigma_b)^2 along y.
  FilterOptions o;
  o.particles = 10;
  o.range_sigma_m = 0.05;
  o.range_sigma_per_m = 0.02;
  o.bearing_sigma_rad = 0.01;
  FastSlam2 f(o, Pose2::Zero());
  f.add_odometry({0.0, 0.0, 0.0});
  // Landmark 1 without sigmas: sd = 0.05 + 0.02 * 5 = 0.15; landmark 2 with its own.
  f.add_observations({0.1, {{1, 5.0, 0.0}, {2, 4.0, 0.0, 0.3, 0.02}}});
  const std::vector<LandmarkEstimate> lms = f.landmarks_of_best();
  ASSERT_EQ(lms.size(), 2u);
  EXPECT_EQ(lms[0].id, 1);
  EXPECT_NEAR(lms[0].mean.x(), 5.0, 1e-12);
  EXPECT_NEAR(lms[0].cov(0, 0), 0.15 * 0.15, 1e-12);
  EXPECT_NEAR(lms[0].cov(1, 1), (5.0 * 0.01) * (5.0 * 0.01), 1e-12);
  EXPECT_EQ(lms[1].id, 2);
  EXPECT_NEAR(lms[1].cov(0, 0), 0.3 * 0.3, 1e-12);
  EXPECT_NEAR(lms[1].cov(1, 1), (4.0 * 0.02) * (4.0 * 0.02), 1e-12);
}

// --------------------------------------------------------------- prior map

TEST(FastSlam2, PriorMapIsSharedByAllParticlesAndUsed) {
  FilterOptions o;
  o.particles = 500;
  FastSlam2 f(o, Pose2::Zero());
  std::vector<LandmarkEstimate> prior;
  prior.push_back({11, Eigen::Vector2d(2.0, 0.0), Eigen::Matrix2d::Identity() * 1e-4, 5});
  prior.push_back({12, Eigen::Vector2d(0.0, 3.0), Eigen::Matrix2d::Identity() * 1e-4, 5});
  f.set_prior_map(prior);
  // One tree for all particles: a handful of nodes, not 500 copies.
  EXPECT_LE(f.pool().nodes_live(), 8u);
  expect_same_landmarks(f.landmarks_of_best(), prior);
  f.add_odometry({0.0, 0.0, 0.0});
  f.add_observations({0.1, {{11, 2.0, 0.0}, {12, 3.0, M_PI / 2}}});
  EXPECT_EQ(f.counters().observations_used, 2u);
  EXPECT_EQ(f.counters().observations_new_landmark, 0u);
}

// ------------------------------------------------------ output frame anchoring

// Centroid offset and least-squares rotation from `now` onto `then` (same ids).
struct RigidOffset {
  Eigen::Vector2d translation = Eigen::Vector2d::Zero();
  double rotation = 0.0;
};
RigidOffset rigid_offset(const std::vector<LandmarkEstimate>& now, const std::vector<LandmarkEstimate>& then) {
  std::vector<std::pair<Eigen::Vector2d, Eigen::Vector2d>> pairs;
  for (const LandmarkEstimate& a : now) {
    for (const LandmarkEstimate& b : then) {
      if (a.id == b.id) pairs.push_back({a.mean, b.mean});
    }
  }
  EXPECT_GE(pairs.size(), 2u);
  Eigen::Vector2d ca = Eigen::Vector2d::Zero(), cb = Eigen::Vector2d::Zero();
  for (const auto& [a, b] : pairs) {
    ca += a;
    cb += b;
  }
  ca /= static_cast<double>(pairs.size());
  cb /= static_cast<double>(pairs.size());
  double dot = 0.0, cross = 0.0;
  for (const auto& [a, b] : pairs) {
    dot += (a - ca).dot(b - cb);
    cross += (a - ca).x() * (b - cb).y() - (a - ca).y() * (b - cb).x();
  }
  return {cb - ca, std::atan2(cross, dot)};
}

std::vector<LandmarkEstimate> with_ids(const std::vector<LandmarkEstimate>& all, const std::vector<int>& ids) {
  std::vector<LandmarkEstimate> out;
  for (const LandmarkEstimate& l : all) {
    if (std::find(ids.begin(), ids.end(), l.id) != ids.end()) out.push_back(l);
  }
  return out;
}

TEST(AnchorFrame, OutputStaysOnTheFirstLandmarksWhileTheParticlesMove) {
  sim::WorldOptions w;
  w.duration_s = 60.0;
  const sim::WorldRun run = sim::simulate(w);
  FilterOptions o = options_for_world(w, 100, 5);
  o.anchor_frame.enabled = true;
  FastSlam2 f(o, run.initial_pose);
  std::vector<LandmarkEstimate> anchored;
  double largest_correction = 0.0;
  int checked = 0;
  feed(f, run, {}, [&] {
    if (f.anchor_ids().empty()) {
      // Until anchored the output is the particles' own frame.
      EXPECT_EQ(f.output_rotation_rad(), 0.0);
      EXPECT_TRUE(f.output_translation_m().isZero());
      return;
    }
    const std::vector<LandmarkEstimate> now = with_ids(f.landmarks_mixture(), f.anchor_ids());
    if (anchored.empty()) {
      anchored = now;
      return;
    }
    // In the output the anchors' mean positions keep their anchored centroid
    // and least-squares orientation exactly ...
    const RigidOffset off = rigid_offset(now, anchored);
    EXPECT_LT(off.translation.norm(), 1e-9);
    EXPECT_LT(std::abs(off.rotation), 1e-9);
    ++checked;
    // ... while in the particles' frame they have moved.
    largest_correction = std::max(largest_correction, f.output_translation_m().norm());
  });
  ASSERT_GE(anchored.size(), 2u);
  EXPECT_GT(checked, 100);
  EXPECT_GT(largest_correction, 1e-4);
  // The output pose is the particles' mean moved by the same transform.
  const PoseEstimate e = f.pose_estimate();
  EXPECT_NEAR(e.mean.z(), wrap_angle(e.mean.z()), 1e-12);
  EXPECT_LT(rigid_offset(with_ids(f.landmarks_of_best(), f.anchor_ids()), anchored).translation.norm(), 0.05);
}

TEST(AnchorFrame, WaitsUntilTheLandmarksSpreadEnoughToFixARotation) {
  FilterOptions o;
  o.particles = 50;
  o.anchor_frame.enabled = true;
  o.anchor_frame.min_observations = 5;
  o.anchor_frame.min_spread_m = 0.5;
  FastSlam2 f(o, Pose2::Zero());
  f.add_odometry({0.0, 0.0, 0.0});
  // Two poles 0.2 m apart (spread 0.1 m): seen often, but they fix no rotation.
  double t = 0.1;
  for (int k = 0; k < 10; ++k, t += 0.1) {
    f.add_observations({t, {{1, 2.0, 0.05}, {2, 2.01, -0.05}}});
  }
  EXPECT_TRUE(f.anchor_ids().empty());
  // A third pole 2 m to the side: anchored once it has been seen 5 times.
  for (int k = 0; k < 4; ++k, t += 0.1) f.add_observations({t, {{3, 2.0, M_PI / 2}}});
  EXPECT_TRUE(f.anchor_ids().empty());
  f.add_observations({t, {{3, 2.0, M_PI / 2}}});
  EXPECT_EQ(f.anchor_ids(), (std::vector<int>{1, 2, 3}));
  // A prior map replaces the frame: anchoring starts again.
  f.set_prior_map({{7, Eigen::Vector2d(1.0, 0.0), Eigen::Matrix2d::Identity() * 1e-4, 9}});
  EXPECT_TRUE(f.anchor_ids().empty());
  EXPECT_EQ(f.output_rotation_rad(), 0.0);

  // Without ids a landmark slot is not the same pole in every particle: no anchors.
  o.association = Association::kMaximumLikelihood;
  FastSlam2 g(o, Pose2::Zero());
  g.add_odometry({0.0, 0.0, 0.0});
  for (int k = 0; k < 10; ++k) g.add_observations({0.1 * (k + 1), {{1, 2.0, 0.05}, {3, 2.0, M_PI / 2}}});
  EXPECT_GE(g.landmarks_of_best().size(), 2u);
  EXPECT_TRUE(g.anchor_ids().empty());
}

}  // namespace
}  // namespace pixyslam::slam
