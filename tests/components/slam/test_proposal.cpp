// Tests of the FastSLAM 2.0 pose proposal: fold_into_proposal against the
// closed-form Gaussian product (information form, computed independently),
// sequential folding against the batch solution, the sequential likelihoods
// against the joint density, and a filter-level check that poses are SAMPLED from
// the proposal rather than only reweighted.

#include <cmath>
#include <memory>
#include <random>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Eigenvalues>
#include <Eigen/LU>
#include <gtest/gtest.h>

#include "pixyslam/slam/fastslam2.h"
#include "pixyslam/slam/motion_model.h"
#include "pixyslam/slam/observation_model.h"
#include "pixyslam/slam/slam_options.h"
#include "pixyslam/slam/types.h"

namespace pixyslam::slam {
namespace {

constexpr double kPi = 3.14159265358979323846;

using Mat23 = Eigen::Matrix<double, 2, 3>;

// A random symmetric positive definite n x n matrix, eigenvalues in [lo, hi].
template <int N>
Eigen::Matrix<double, N, N> random_spd(std::mt19937& prng, double lo, double hi) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::uniform_real_distribution<double> ev(lo, hi);
  Eigen::Matrix<double, N, N> a;
  for (int i = 0; i < N * N; ++i) a(i) = u(prng);
  // Orthonormal basis from a QR-free Gram-Schmidt of a random matrix.
  Eigen::Matrix<double, N, N> q;
  for (int j = 0; j < N; ++j) {
    Eigen::Matrix<double, N, 1> v = a.col(j);
    for (int k = 0; k < j; ++k) v -= q.col(k).dot(v) * q.col(k);
    q.col(j) = v.normalized();
  }
  Eigen::Matrix<double, N, 1> d;
  for (int i = 0; i < N; ++i) d(i) = ev(prng);
  return q * d.asDiagonal() * q.transpose();
}

// Closed-form Gaussian product in information form:
//   P = (Sigma^-1 + sum H_k^T Q_k^-1 H_k)^-1,  mu' = mu + P sum H_k^T Q_k^-1 nu_k,
// with every nu_k relative to the prior mean mu.
struct Batch {
  Eigen::Vector3d mean;
  Eigen::Matrix3d cov;
};
Batch information_form(const PoseGaussian& prior, const std::vector<Mat23>& h, const std::vector<Eigen::Matrix2d>& q,
                       const std::vector<Eigen::Vector2d>& nu) {
  Eigen::Matrix3d info = prior.cov.inverse();
  Eigen::Vector3d vec = Eigen::Vector3d::Zero();
  for (std::size_t k = 0; k < h.size(); ++k) {
    const Eigen::Matrix2d q_inv = q[k].inverse();
    info += h[k].transpose() * q_inv * h[k];
    vec += h[k].transpose() * q_inv * nu[k];
  }
  Batch b;
  b.cov = info.inverse();
  b.mean = prior.mean + b.cov * vec;
  return b;
}

void expect_matrix_near(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b, double rel, const char* what) {
  const double scale = b.cwiseAbs().maxCoeff();
  EXPECT_LE((a - b).cwiseAbs().maxCoeff(), rel * scale) << what << "\nactual\n" << a << "\nexpected\n" << b;
}

TEST(Proposal, FoldEqualsClosedFormGaussianProductForSyntheticLinearFits) {
  // The fit is built by hand, so the "measurement model" is exactly linear:
  // z = H x + noise(Q), S = H Sigma H^T + Q.
  std::mt19937 prng(42);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int trial = 0; trial < 200; ++trial) {
    PoseGaussian g;
    g.mean = Pose2(u(prng), u(prng), 0.5 * u(prng));
    g.cov = random_spd<3>(prng, 1e-3, 0.2);
    Mat23 h;
    for (int i = 0; i < 6; ++i) h(i) = u(prng);
    const Eigen::Matrix2d q = random_spd<2>(prng, 1e-3, 0.1);
    ObservationFit fit;
    fit.h_pose = h;
    fit.s = h * g.cov * h.transpose() + q;
    fit.innovation = Eigen::Vector2d(0.2 * u(prng), 0.2 * u(prng));

    const Batch expected = information_form(g, {h}, {q}, {fit.innovation});
    PoseGaussian folded = g;
    fold_into_proposal(folded, fit);
    expect_matrix_near(folded.cov, expected.cov, 1e-9, "posterior covariance");
    EXPECT_NEAR(folded.mean.x(), expected.mean.x(), 1e-9);
    EXPECT_NEAR(folded.mean.y(), expected.mean.y(), 1e-9);
    EXPECT_NEAR(wrap_angle(folded.mean.z() - expected.mean.z()), 0.0, 1e-9);
    // The posterior is symmetric and tighter than the prior.
    EXPECT_LE((folded.cov - folded.cov.transpose()).cwiseAbs().maxCoeff(), 1e-15);
    EXPECT_LT(folded.cov.trace(), g.cov.trace());
  }
}

TEST(Proposal, FoldOfARealObservationFitEqualsClosedForm) {
  // fit_observation linearises the range-bearing model; given that linearisation
  // (H = fit.h_pose, Q = G P G^T + R), the fold must be the exact Gaussian product.
  std::mt19937 prng(42);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int trial = 0; trial < 100; ++trial) {
    PoseGaussian g;
    g.mean = Pose2(u(prng), u(prng), 0.9 * kPi * u(prng));
    g.cov = random_spd<3>(prng, 1e-4, 0.05);
    const double phi = kPi * u(prng);
    const double range = 2.0 + u(prng);
    const Eigen::Vector2d lm = g.mean.head<2>() + range * Eigen::Vector2d(std::cos(phi), std::sin(phi));
    const Eigen::Matrix2d p = random_spd<2>(prng, 1e-4, 0.02);
    Eigen::Matrix2d r;
    r << 0.07 * 0.07, 0.0, 0.0, 0.027 * 0.027;
    const Eigen::Vector2d z = predict_observation(g.mean, lm).z + Eigen::Vector2d(0.1 * u(prng), 0.05 * u(prng));

    const ObservationFit fit = fit_observation(g, lm, p, z, r);
    // Landmark Jacobian written out: G = [dx/r dy/r; -dy/q dx/q].
    const double dx = lm.x() - g.mean.x(), dy = lm.y() - g.mean.y(), q2 = dx * dx + dy * dy, rr = std::sqrt(q2);
    Eigen::Matrix2d gl;
    gl << dx / rr, dy / rr, -dy / q2, dx / q2;
    const Eigen::Matrix2d q = gl * p * gl.transpose() + r;
    expect_matrix_near(fit.s - fit.h_pose * g.cov * fit.h_pose.transpose(), q, 1e-10, "S - H Sigma H^T");

    const Batch expected = information_form(g, {fit.h_pose}, {q}, {fit.innovation});
    PoseGaussian folded = g;
    fold_into_proposal(folded, fit);
    expect_matrix_near(folded.cov, expected.cov, 1e-8, "posterior covariance");
    EXPECT_NEAR(folded.mean.x(), expected.mean.x(), 1e-9);
    EXPECT_NEAR(folded.mean.y(), expected.mean.y(), 1e-9);
    EXPECT_NEAR(wrap_angle(folded.mean.z() - expected.mean.z()), 0.0, 1e-9);
  }
}

TEST(Proposal, SequentialFoldsEqualBatchInformationForm) {
  // Two exactly linear observations z_k = H_k x + b_k + noise(Q_k). The second fit
  // is evaluated at the once-updated Gaussian, as the filter does:
  // nu_2' = z_2 - H_2 mu_1 - b_2 and S_2 = H_2 Sigma_1 H_2^T + Q_2.
  std::mt19937 prng(42);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int trial = 0; trial < 100; ++trial) {
    PoseGaussian g;
    g.mean = Pose2(u(prng), u(prng), 0.5 * u(prng));
    g.cov = random_spd<3>(prng, 1e-3, 0.2);
    Mat23 h1, h2;
    for (int i = 0; i < 6; ++i) {
      h1(i) = u(prng);
      h2(i) = u(prng);
    }
    const Eigen::Matrix2d q1 = random_spd<2>(prng, 1e-3, 0.1);
    const Eigen::Matrix2d q2 = random_spd<2>(prng, 1e-3, 0.1);
    // Innovations of both measurements at the prior mean.
    const Eigen::Vector2d nu1(0.2 * u(prng), 0.2 * u(prng));
    const Eigen::Vector2d nu2(0.2 * u(prng), 0.2 * u(prng));

    PoseGaussian seq = g;
    ObservationFit f1;
    f1.h_pose = h1;
    f1.s = h1 * seq.cov * h1.transpose() + q1;
    f1.innovation = nu1;
    fold_into_proposal(seq, f1);
    ObservationFit f2;
    f2.h_pose = h2;
    f2.s = h2 * seq.cov * h2.transpose() + q2;
    f2.innovation = nu2 - h2 * (seq.mean - g.mean);  // linear model re-evaluated at mu_1
    fold_into_proposal(seq, f2);

    const Batch batch = information_form(g, {h1, h2}, {q1, q2}, {nu1, nu2});
    expect_matrix_near(seq.cov, batch.cov, 1e-8, "sequential vs batch covariance");
    EXPECT_NEAR(seq.mean.x(), batch.mean.x(), 1e-9);
    EXPECT_NEAR(seq.mean.y(), batch.mean.y(), 1e-9);
    EXPECT_NEAR(seq.mean.z(), batch.mean.z(), 1e-9);
  }
}

TEST(Proposal, SequentialLikelihoodsEqualTheJointDensity) {
  // Two real range-bearing observations, processed the filter's way: fit 1 at the
  // prior, fold, fit 2 at the folded Gaussian, fold. In the linear case the sum of
  // the two log likelihoods equals log N(nu; 0, H Sigma H^T + blockdiag(Q1, Q2))
  // with the innovations and Jacobians stacked at the prior mean.
  //
  // The range-bearing model is not linear: fit 2 re-linearises at mu_1. The
  // resulting error is of relative order sigma_pose / range, so the landmarks are
  // placed ~1000 m away with a pose standard deviation of ~1 mm (and noises scaled
  // alike) which makes linearisation exact to ~1e-6 relative while keeping the
  // pose uncertainty comparable to the measurement noise, so that the two
  // observations are strongly correlated through the pose (checked below).
  const double range = 1000.0;
  const double sp = 1e-3;            // pose position std [m]
  const double sa = sp / range;      // pose heading std [rad], same scale in bearing
  PoseGaussian g;
  g.mean = Pose2(0.3, -0.2, 0.1);
  g.cov << sp * sp, 0.3 * sp * sp, 0.2 * sp * sa,
           0.3 * sp * sp, 1.5 * sp * sp, -0.1 * sp * sa,
           0.2 * sp * sa, -0.1 * sp * sa, sa * sa;
  const Eigen::Vector2d lm1 = g.mean.head<2>() + range * Eigen::Vector2d(std::cos(0.2), std::sin(0.2));
  const Eigen::Vector2d lm2 = g.mean.head<2>() + 0.8 * range * Eigen::Vector2d(std::cos(1.4), std::sin(1.4));
  Eigen::Matrix2d p1, p2, r;
  p1 << 0.5 * sp * sp, 0.1 * sp * sp, 0.1 * sp * sp, 0.4 * sp * sp;
  p2 << 0.3 * sp * sp, 0.0, 0.0, 0.6 * sp * sp;
  r << 0.8 * sp * sp, 0.0, 0.0, 0.7 * sa * sa;
  const Eigen::Vector2d z1 = predict_observation(g.mean, lm1).z + Eigen::Vector2d(1.3 * sp, -0.9 * sa);
  const Eigen::Vector2d z2 = predict_observation(g.mean, lm2).z + Eigen::Vector2d(-0.7 * sp, 1.6 * sa);

  PoseGaussian seq = g;
  const ObservationFit f1 = fit_observation(seq, lm1, p1, z1, r);
  fold_into_proposal(seq, f1);
  const ObservationFit f2 = fit_observation(seq, lm2, p2, z2, r);
  fold_into_proposal(seq, f2);

  // Joint Gaussian of the stacked innovation at the prior mean.
  const PredictedObservation o1 = predict_observation(g.mean, lm1);
  const PredictedObservation o2 = predict_observation(g.mean, lm2);
  Eigen::Matrix<double, 4, 3> h;
  h << o1.h_pose, o2.h_pose;
  Eigen::Matrix4d c = h * g.cov * h.transpose();
  c.block<2, 2>(0, 0) += o1.h_landmark * p1 * o1.h_landmark.transpose() + r;
  c.block<2, 2>(2, 2) += o2.h_landmark * p2 * o2.h_landmark.transpose() + r;
  Eigen::Vector4d nu;
  nu << innovation(z1, o1.z), innovation(z2, o2.z);
  const double m2 = nu.dot(c.inverse() * nu);
  const double joint = -0.5 * m2 - 2.0 * std::log(2.0 * kPi) - 0.5 * std::log(c.determinant());

  // The Mahalanobis parts are O(1) and compared relatively; the log densities are
  // dominated by -0.5 log det (about +25 here), compared to 1e-6 relative.
  EXPECT_NEAR(f1.mahalanobis2 + f2.mahalanobis2, m2, 1e-6 * m2);
  EXPECT_NEAR(f1.log_likelihood + f2.log_likelihood, joint, 1e-6 * std::abs(joint));

  // The test has teeth: ignoring the pose correlation (fit 2 at the prior
  // Gaussian) differs from the joint density by far more than the tolerance.
  const ObservationFit f2_naive = fit_observation(g, lm2, p2, z2, r);
  EXPECT_GT(std::abs(f1.log_likelihood + f2_naive.log_likelihood - joint), 1e-2);
  EXPECT_GT(std::abs(f1.mahalanobis2 + f2_naive.mahalanobis2 - m2), 1e-3 * m2);

  // And the sequentially folded Gaussian equals the batch product with both.
  const Batch batch = information_form(
      g, {o1.h_pose, o2.h_pose},
      {o1.h_landmark * p1 * o1.h_landmark.transpose() + r, o2.h_landmark * p2 * o2.h_landmark.transpose() + r},
      {innovation(z1, o1.z), innovation(z2, o2.z)});
  expect_matrix_near(seq.cov, batch.cov, 1e-5, "sequential vs batch covariance (real model)");
  EXPECT_NEAR(seq.mean.x(), batch.mean.x(), 1e-5 * sp);
  EXPECT_NEAR(seq.mean.y(), batch.mean.y(), 1e-5 * sp);
  EXPECT_NEAR(seq.mean.z(), batch.mean.z(), 1e-5 * sa);
}

TEST(Proposal, FoldHandlesRankDeficientMotionCovariance) {
  // Straight motion from a known pose leaves Sigma rank-deficient (no lateral
  // noise); the covariance-form fold must still give a finite PSD result.
  PoseGaussian g;
  g.mean = Pose2(0.0, 0.0, 0.0);
  propagate(g, 0.5, 0.0, 1.0, MotionNoise{0.1, 0.0, 0.0, 0.0});
  ASSERT_NEAR(g.cov.determinant(), 0.0, 1e-20);
  Eigen::Matrix2d r;
  r << 0.0049, 0.0, 0.0, 0.0007;
  const ObservationFit fit =
      fit_observation(g, Eigen::Vector2d(2.0, 1.0), Eigen::Matrix2d::Identity() * 1e-4, Eigen::Vector2d(1.8, 0.45), r);
  fold_into_proposal(g, fit);
  EXPECT_TRUE(g.mean.allFinite());
  EXPECT_TRUE(g.cov.allFinite());
  EXPECT_GE(Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(g.cov).eigenvalues().minCoeff(), -1e-15);
  EXPECT_LT(g.cov(0, 0), 0.01);  // the x variance (0.01 before) shrank
}

// Unweighted sample mean and covariance of the particles' poses.
void particle_spread(FastSlam2& f, Eigen::Vector3d& mean, Eigen::Matrix3d& cov) {
  mean.setZero();
  for (const Particle& p : f.particles()) mean += p.pose.mean;
  mean /= static_cast<double>(f.particles().size());
  cov.setZero();
  for (const Particle& p : f.particles()) {
    Eigen::Vector3d d = p.pose.mean - mean;
    d.z() = wrap_angle(d.z());
    cov += d * d.transpose();
  }
  cov /= static_cast<double>(f.particles().size() - 1);
}

TEST(Proposal, FilterSamplesPosesFromTheProposal) {
  // Given a filter at a known pose that maps landmark 1 at (2, 0), then drives
  // with very noisy odometry (nominally to x = 0.5) and sees landmark 1 at range
  // 1.3 (i.e. the robot really is at x = 0.7):
  FilterOptions o;
  o.particles = 2000;
  o.seed = 42;
  o.motion = MotionNoise{0.3, 0.3, 0.0, 0.0};
  o.gate_enabled = false;
  // Never resample: resampling would concentrate particles even with a
  // motion-only proposal and hide whether the poses were sampled from the proposal.
  o.resample_mode = ResampleMode::kEffectiveSampleSize;
  o.resample_neff_fraction = 1e-9;
  const double sr = 0.01, sb = 0.005;

  auto run = [&](int landmark_seen_at_end) {
    auto f = std::make_unique<FastSlam2>(o, Pose2(0.0, 0.0, 0.0));
    f->add_odometry({0.0, 0.0, 0.0});
    f->add_observations({0.0, {{1, 2.0, 0.0, sr, sb}}});
    f->add_odometry({0.0, 0.5, 0.0});
    f->add_odometry({1.0, 0.0, 0.0});
    f->add_observations({1.0, {{landmark_seen_at_end, 1.3, 0.0, sr, sb}}});
    return f;
  };

  // Reference: the same motion, but the final frame sees a NEW landmark, so the
  // pose is sampled from the motion model alone.
  const auto motion_only = run(2);
  Eigen::Vector3d m0;
  Eigen::Matrix3d c0;
  particle_spread(*motion_only, m0, c0);
  PoseGaussian predicted;
  propagate(predicted, 0.5, 0.0, 1.0, o.motion);
  EXPECT_NEAR(c0(0, 0), predicted.cov(0, 0), 0.1 * predicted.cov(0, 0));  // 0.09
  EXPECT_NEAR(c0(2, 2), predicted.cov(2, 2), 0.1 * predicted.cov(2, 2));  // 0.09
  EXPECT_NEAR(m0.x(), 0.5, 0.03);

  // When the final frame re-observes landmark 1,
  const auto with_proposal = run(1);
  EXPECT_EQ(with_proposal->counters().observations_used, 1u);
  EXPECT_EQ(with_proposal->counters().resamples, 0u);
  Eigen::Vector3d m1;
  Eigen::Matrix3d c1;
  particle_spread(*with_proposal, m1, c1);
  // then the particles' own poses (unweighted) are concentrated along the range
  // direction: the x spread is ~1e-4 (landmark + range noise), not 0.09,
  EXPECT_LT(c1(0, 0), 0.01 * c0(0, 0)) << "x variance with proposal " << c1(0, 0) << " motion-only " << c0(0, 0);
  // and their mean moved from the odometry's 0.5 to the observed 0.7,
  EXPECT_NEAR(m1.x(), 0.7, 0.02);
  // while all particles had the same proposal, so their weights stay equal
  // (the concentration comes from sampling, not from reweighting).
  EXPECT_NEAR(with_proposal->pose_estimate().effective_sample_size, 2000.0, 1e-6);
  // The bearing (y/r - theta, r = 1.3) is constrained too: bearing spread shrinks.
  std::vector<double> bearing;
  double bm = 0.0;
  for (const Particle& p : with_proposal->particles()) {
    const double b = std::atan2(-p.pose.mean.y(), 2.0 - p.pose.mean.x()) - p.pose.mean.z();
    bearing.push_back(b);
    bm += b;
  }
  bm /= static_cast<double>(bearing.size());
  double bv = 0.0;
  for (double b : bearing) bv += (b - bm) * (b - bm);
  bv /= static_cast<double>(bearing.size() - 1);
  EXPECT_LT(bv, 0.01 * c0(2, 2));
}

}  // namespace
}  // namespace pixyslam::slam
