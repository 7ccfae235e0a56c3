#include "pixyslam/slam/joint_gaussian.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/LU>

#include "pixyslam/slam/observation_model.h"

namespace pixyslam::slam {
namespace {

constexpr double kMinLandmarkVariance = 1e-10;  // (10 um)^2
// A state variance beyond this ((1 km)^2) means the linearisation broke down.
constexpr double kMaxVariance = 1e6;
// A frame correction beyond this is not folded back into the motion Jacobian.
constexpr double kRelineariseDistance = 0.25;  // m

// Grows the state by one landmark block, zero-filled; returns its index.
int append_block(JointGaussian& g, std::uint32_t slot) {
  const Eigen::Index n = g.mean.size();
  g.mean.conservativeResize(n + 2);
  g.mean.tail<2>().setZero();
  g.cov.grow(2);
  g.landmarks.push_back({});
  g.landmarks.back().slot = slot;
  return g.landmark_count() - 1;
}

}  // namespace

bool JointGaussian::healthy() const {
  // A NaN or infinity in the mean makes its sum non-finite; on the diagonal it
  // fails the range check. Off the diagonal a covariance is bounded by its
  // variances, and an update that makes an entry non-finite makes its row's
  // variance non-finite too.
  if (!std::isfinite(mean.sum())) return false;
  for (Eigen::Index i = 0; i < cov.size(); ++i) {
    const double v = cov.lower(i, i);
    if (!(v >= 0.0 && v <= kMaxVariance)) return false;
  }
  return true;
}

Eigen::Matrix<double, 3, 2> JointGaussian::pose_landmark_cov(int i) const {
  const Eigen::Index j = 3 + 2 * i;
  Eigen::Matrix<double, 3, 2> b;
  for (int c = 0; c < 3; ++c) b.row(c) << cov.lower(j, c), cov.lower(j + 1, c);
  return b;
}

int JointGaussian::find(std::uint32_t slot) const {
  for (std::size_t i = 0; i < landmarks.size(); ++i) {
    if (landmarks[i].slot == slot) return static_cast<int>(i);
  }
  return -1;
}

PoseGaussian JointGaussian::pose() const {
  PoseGaussian p;
  p.mean = mean.head<3>();
  p.cov = pose_cov();
  return p;
}

void JointGaussian::begin(const PoseGaussian& pose) {
  mean = pose.mean;
  cov.assign(pose.cov);
  landmarks.clear();
  frame_pose = pose.mean;
}

void JointGaussian::clear() {
  mean.resize(0);
  cov.clear();
  landmarks.clear();
}

JointGaussian& SharedJointGaussian::begin(const PoseGaussian& pose) {
  state_ = std::make_shared<JointGaussian>();
  state_->begin(pose);
  return *state_;
}

JointGaussian& SharedJointGaussian::own() {
  if (state_.use_count() > 1) state_ = std::make_shared<JointGaussian>(*state_);
  return *state_;
}

void JointGaussian::end_frame() {
  // After a large jump (a loop closure) the motion Jacobian keeps the updated
  // pose: inflating by a metre-sized correction would wreck the covariance.
  const Eigen::Vector2d c = mean.head<2>() - frame_pose.head<2>();
  if (c.norm() > kRelineariseDistance) return;
  // Fc P Fc^T = P + u P_2. + P_.2 u^T + P_22 u u^T with u = (-c_y, c_x, 0, ...):
  // in the lower triangle only columns 0 and 1 change.
  const double u0 = -c.y();
  const double u1 = c.x();
  const double p20 = cov.lower(2, 0), p21 = cov.lower(2, 1), p22 = cov.lower(2, 2);
  cov.lower(0, 0) += 2.0 * u0 * p20 + u0 * u0 * p22;
  cov.lower(1, 0) += u1 * p20 + u0 * p21 + u0 * u1 * p22;
  cov.lower(1, 1) += 2.0 * u1 * p21 + u1 * u1 * p22;
  cov.column(0, 2) += u0 * cov.column(2, 2);
  cov.column(1, 2) += u1 * cov.column(2, 2);
}

void JointGaussian::move_pose(const Eigen::Matrix3d& f, const Eigen::Matrix3d& q) {
  cov.set_diagonal_block<3>(0, f * pose_cov() * f.transpose() + q);
  if (cov.size() == 3) return;
  // The landmarks' rows of the pose columns: P_lx <- P_lx F^T.
  PackedSymmetric::Segment c0 = cov.column(0, 3), c1 = cov.column(1, 3), c2 = cov.column(2, 3);
  for (Eigen::Index r = 0; r < c0.size(); ++r) {
    const Eigen::Vector3d x(c0(r), c1(r), c2(r));
    c0(r) = f.row(0).dot(x);
    c1(r) = f.row(1).dot(x);
    c2(r) = f.row(2).dot(x);
  }
}

void JointGaussian::propagate(double v_mps, double w_radps, double dt_s, const MotionNoise& noise) {
  if (dt_s <= 0.0) return;
  const MotionStep step = motion_step(mean.head<3>(), v_mps, w_radps, dt_s, noise);
  move_pose(step.f, step.q);
  mean.head<3>() = step.mean;
}

void JointGaussian::apply_motion(const ComposedMotion& motion) {
  if (motion.empty()) return;
  const double c = std::cos(mean(2));
  const double s = std::sin(mean(2));
  move_pose(motion.jacobian(c, s), motion.noise(c, s));
  mean.head<3>() = motion.moved_mean(mean.head<3>(), c, s);
}

int JointGaussian::add_known(std::uint32_t slot, const Eigen::Vector2d& landmark_mean,
                             const Eigen::Matrix2d& landmark_cov, LandmarkCounts landmark_counts) {
  const int i = append_block(*this, slot);
  mean.tail<2>() = landmark_mean;
  cov.set_diagonal_block<2>(3 + 2 * i, landmark_cov);
  landmarks.back().first = landmark_mean;
  landmarks.back().counts = landmark_counts;
  return i;
}

int JointGaussian::add_new(std::uint32_t slot, const Eigen::Vector2d& z, const Eigen::Matrix2d& r) {
  const double heading = frame_pose(2) + z.y();
  const double c = std::cos(heading);
  const double s = std::sin(heading);
  Eigen::Matrix<double, 2, 3> gx;
  gx << 1.0, 0.0, -z.x() * s,
        0.0, 1.0, z.x() * c;
  Eigen::Matrix2d gz;
  gz << c, -z.x() * s,
        s, z.x() * c;
  const Eigen::Vector2d landmark(frame_pose(0) + z.x() * c, frame_pose(1) + z.x() * s);
  // Gx P_x., 2 x n, before the state grows.
  const Eigen::Index n = mean.size();
  const Eigen::Matrix3d pxx = pose_cov();
  Eigen::Matrix<double, 2, Eigen::Dynamic> cross(2, n);
  cross.leftCols<3>() = gx * pxx;
  for (Eigen::Index k = 3; k < n; ++k) {
    cross.col(k) = gx * Eigen::Vector3d(cov.lower(k, 0), cov.lower(k, 1), cov.lower(k, 2));
  }
  const int i = append_block(*this, slot);
  mean.tail<2>() = landmark;
  landmarks.back().first = landmark;
  landmarks.back().relative = true;
  for (Eigen::Index k = 0; k < n; ++k) {
    cov.lower(n, k) = cross(0, k);
    cov.lower(n + 1, k) = cross(1, k);
  }
  cov.set_diagonal_block<2>(n, gx * pxx * gx.transpose() + gz * r * gz.transpose());
  return i;
}

JointFit fit_observation(const JointGaussian& g, int index, const Eigen::Vector2d& z, const Eigen::Matrix2d& r) {
  const Eigen::Index j = 3 + 2 * index;
  const PredictedObservation p =
      predict_observation(g.frame_pose, g.landmarks[static_cast<std::size_t>(index)].first);
  JointFit fit;
  fit.index = index;
  fit.innovation = innovation(z, predict_observation(g.mean.head<3>(), g.mean.segment<2>(j)).z);
  fit.h_pose = p.h_pose;
  fit.h_landmark = p.h_landmark;
  const Eigen::Matrix<double, 2, 3> pose_rows_x = p.h_pose * g.pose_cov();
  const Eigen::Matrix2d cross = p.h_pose * g.pose_landmark_cov(index) * p.h_landmark.transpose();
  fit.s = pose_rows_x * p.h_pose.transpose() + cross + cross.transpose() +
          p.h_landmark * g.landmark_cov(index) * p.h_landmark.transpose() + r;
  fit.mahalanobis2 = fit.innovation.dot(fit.s.inverse() * fit.innovation);
  fit.log_likelihood = -0.5 * fit.mahalanobis2 - std::log(2.0 * M_PI) - 0.5 * std::log(fit.s.determinant());
  return fit;
}

JointFit fit_observation_iterated(const JointGaussian& g, int index, const Eigen::Vector2d& z,
                                  const Eigen::Matrix2d& r, int max_iterations) {
  const Eigen::Index j = 3 + 2 * index;
  // The pose and landmark blocks are all the iteration needs: x = (pose, landmark).
  using Vector5d = Eigen::Matrix<double, 5, 1>;
  using Matrix5d = Eigen::Matrix<double, 5, 5>;
  Vector5d x0;
  x0 << g.mean.head<3>(), g.mean.segment<2>(j);
  Matrix5d p;
  p.topLeftCorner<3, 3>() = g.pose_cov();
  p.topRightCorner<3, 2>() = g.pose_landmark_cov(index);
  p.bottomLeftCorner<2, 3>() = g.pose_landmark_cov(index).transpose();
  p.bottomRightCorner<2, 2>() = g.landmark_cov(index);
  JointFit fit;
  fit.index = index;
  Vector5d x = x0;
  for (int k = 0; k < std::max(1, max_iterations); ++k) {
    const PredictedObservation pred = predict_observation(x.head<3>(), x.tail<2>());
    Eigen::Matrix<double, 2, 5> h;
    h << pred.h_pose, pred.h_landmark;
    Vector5d dx = x0 - x;
    dx(2) = wrap_angle(dx(2));
    fit.h_pose = pred.h_pose;
    fit.h_landmark = pred.h_landmark;
    fit.innovation = innovation(z, pred.z) - h * dx;
    fit.s = h * p * h.transpose() + r;
    Vector5d next = x0 + p * h.transpose() * fit.s.ldlt().solve(fit.innovation);
    next(2) = wrap_angle(next(2));
    Vector5d change = next - x;
    change(2) = wrap_angle(change(2));
    x = next;
    if (!x.allFinite()) break;
    if (change.cwiseAbs().maxCoeff() < 1e-9) break;
  }
  fit.mahalanobis2 = fit.innovation.dot(fit.s.inverse() * fit.innovation);
  fit.log_likelihood = -0.5 * fit.mahalanobis2 - std::log(2.0 * M_PI) - 0.5 * std::log(fit.s.determinant());
  return fit;
}

bool apply_observation(JointGaussian& g, const JointFit& fit) {
  const Eigen::Index j = 3 + 2 * fit.index;
  PackedSymmetric& p = g.cov;
  const Eigen::Index n = p.size();
  // Scratch without an allocation per update: P H^T, K, A and K nu.
  thread_local std::vector<double> scratch;
  scratch.resize(static_cast<std::size_t>(7 * n));
  using Columns2 = Eigen::Map<Eigen::Matrix<double, Eigen::Dynamic, 2>>;
  Columns2 pht(scratch.data(), n, 2);
  Columns2 k(scratch.data() + 2 * n, n, 2);
  Columns2 a(scratch.data() + 4 * n, n, 2);
  Eigen::Map<Eigen::VectorXd> step(scratch.data() + 6 * n, n);
  // P H^T touches only the pose and landmark columns of P, read from the lower
  // triangle: the pose columns below the pose block, the landmark's rows left
  // of its block (in columns the update writes anyway) and its columns below.
  const Eigen::Matrix<double, 3, 2> hp = fit.h_pose.transpose();
  const Eigen::Matrix2d hl = fit.h_landmark.transpose();
  pht.topRows<3>().noalias() = g.pose_cov() * hp;
  for (int q = 0; q < 2; ++q) {
    pht.col(q).tail(n - 3) = p.column(0, 3) * hp(0, q) + p.column(1, 3) * hp(1, q) + p.column(2, 3) * hp(2, q);
  }
  for (Eigen::Index r = 0; r < j; ++r) pht.row(r) += Eigen::RowVector2d(p.lower(j, r), p.lower(j + 1, r)) * hl;
  pht.middleRows<2>(j).noalias() += g.landmark_cov(fit.index) * hl;
  if (j + 2 < n) {
    for (int q = 0; q < 2; ++q) {
      pht.col(q).tail(n - j - 2) += p.column(j, j + 2) * hl(0, q) + p.column(j + 1, j + 2) * hl(1, q);
    }
  }
  const Eigen::Matrix2d s_inverse = fit.s.inverse();
  k.noalias() = pht * s_inverse;
  step.noalias() = k * fit.innovation;
  // K S K^T = (P H^T) S^-1 (P H^T)^T = A A^T with A = P H^T L, S^-1 = L L^T,
  // subtracted column by column from the lower triangle.
  const Eigen::LLT<Eigen::Matrix2d> llt(s_inverse);
  if (llt.info() != Eigen::Success) return false;
  a.noalias() = pht * llt.matrixL().toDenseMatrix();
  // Checked before anything changes (O(n)): the state after the update must be
  // healthy() (finite, variances in [0, kMaxVariance]).
  if (!std::isfinite(step.sum()) || !std::isfinite(a.sum())) return false;
  for (Eigen::Index r = 0; r < n; ++r) {
    const double v = p.lower(r, r) - (a(r, 0) * a(r, 0) + a(r, 1) * a(r, 1));
    if (!(v >= 0.0 && v <= kMaxVariance)) return false;
  }
  g.mean += step;
  g.mean(2) = wrap_angle(g.mean(2));
  for (Eigen::Index c = 0; c < n; ++c) {
    p.column(c, c) -= a.col(0).tail(n - c) * a(c, 0) + a.col(1).tail(n - c) * a(c, 1);
  }
  return true;
}

namespace {

Eigen::Matrix2d rotation(double theta) {
  const double c = std::cos(theta);
  const double s = std::sin(theta);
  Eigen::Matrix2d r;
  r << c, -s, s, c;
  return r;
}

// d rotation(theta) / d theta.
Eigen::Matrix2d rotation_derivative(double theta) {
  const double c = std::cos(theta);
  const double s = std::sin(theta);
  Eigen::Matrix2d r;
  r << -s, -c, c, -s;
  return r;
}

}  // namespace

namespace {

// The relative landmarks in robot-centred coordinates, m_R = R(theta)^T (m - p),
// and the Jacobian of that change of coordinates at the state's mean.
void to_robocentric(const JointGaussian& g, Eigen::VectorXd& mean, Eigen::MatrixXd& cov) {
  const Eigen::Index n = g.mean.size();
  const Eigen::Vector3d pose = g.mean.head<3>();
  const Eigen::Matrix2d rt = rotation(pose(2)).transpose();
  const Eigen::Matrix2d drt = rotation_derivative(pose(2)).transpose();
  Eigen::MatrixXd j = Eigen::MatrixXd::Identity(n, n);
  mean = g.mean;
  for (int i = 0; i < g.landmark_count(); ++i) {
    if (!g.landmarks[static_cast<std::size_t>(i)].relative) continue;
    const Eigen::Index b = 3 + 2 * i;
    const Eigen::Vector2d d = g.mean.segment<2>(b) - pose.head<2>();
    mean.segment<2>(b) = rt * d;
    j.block<2, 2>(b, 0) = -rt;
    j.block<2, 1>(b, 2) = drt * d;
    j.block<2, 2>(b, b) = rt;
  }
  cov = j * g.cov.full() * j.transpose();
}

// Back to world coordinates, m = p + R(theta) m_R, into `out` (a copy of the
// state the coordinates came from). The linearisation points (first estimates of
// the relative landmarks, frame pose) move by the same rigid motion as the pose.
void from_robocentric(const JointGaussian& from, const Eigen::VectorXd& mean, const Eigen::MatrixXd& cov,
                      JointGaussian& out) {
  const Eigen::Index n = mean.size();
  const Eigen::Vector3d before = from.mean.head<3>();
  const Eigen::Vector3d after = mean.head<3>();
  const Eigen::Matrix2d r = rotation(after(2));
  const Eigen::Matrix2d dr = rotation_derivative(after(2));
  Eigen::MatrixXd j = Eigen::MatrixXd::Identity(n, n);
  out.mean = mean;
  for (int i = 0; i < from.landmark_count(); ++i) {
    if (!from.landmarks[static_cast<std::size_t>(i)].relative) continue;
    const Eigen::Index b = 3 + 2 * i;
    const Eigen::Vector2d m_r = mean.segment<2>(b);
    out.mean.segment<2>(b) = after.head<2>() + r * m_r;
    j.block<2, 2>(b, 0) = Eigen::Matrix2d::Identity();
    j.block<2, 1>(b, 2) = dr * m_r;
    j.block<2, 2>(b, b) = r;
  }
  out.cov.assign(j * cov * j.transpose());
  const Eigen::Matrix2d turn = r * rotation(before(2)).transpose();
  const auto move = [&](const Eigen::Vector2d& q) -> Eigen::Vector2d {
    return after.head<2>() + turn * (q - before.head<2>());
  };
  for (int i = 0; i < from.landmark_count(); ++i) {
    const auto k = static_cast<std::size_t>(i);
    if (from.landmarks[k].relative) out.landmarks[k].first = move(from.landmarks[k].first);
  }
  out.frame_pose.head<2>() = move(from.frame_pose.head<2>());
  out.frame_pose(2) = wrap_angle(from.frame_pose(2) + wrap_angle(after(2) - before(2)));
}

}  // namespace

std::vector<HeadingComponent> split_heading(const JointGaussian& g, double spacing_rad) {
  std::vector<HeadingComponent> out;
  const double variance = g.heading_variance();
  const double component_variance = 0.25 * spacing_rad * spacing_rad;
  if (!(spacing_rad > 0.0) || !(variance > component_variance)) return out;
  Eigen::VectorXd y;
  Eigen::MatrixXd p;
  to_robocentric(g, y, p);
  // Regression of the state on the heading; the heading's own coordinate is 1.
  const Eigen::VectorXd b = p.col(2) / p(2, 2);
  const double spread = variance - component_variance;  // of the component means
  const Eigen::MatrixXd cov = p - spread * b * b.transpose();
  const int half = static_cast<int>(std::ceil(3.0 * std::sqrt(spread) / spacing_rad));
  double total = 0.0;
  for (int k = -half; k <= half; ++k) {
    const double delta = k * spacing_rad;
    HeadingComponent c;
    c.weight = std::exp(-0.5 * delta * delta / spread);
    Eigen::VectorXd mean = y + delta * b;
    mean(2) = wrap_angle(mean(2));
    c.state = g;
    from_robocentric(g, mean, cov, c.state);
    if (!c.state.healthy()) continue;
    total += c.weight;
    out.push_back(std::move(c));
  }
  for (HeadingComponent& c : out) c.weight /= total;
  return out;
}

std::vector<ConditionedLandmark> condition_on_pose(const JointGaussian& g, const Pose2& pose) {
  // A tiny ridge keeps Pxx invertible when a direction has no uncertainty yet.
  const Eigen::Matrix3d pxx = g.pose_cov() + 1e-12 * Eigen::Matrix3d::Identity();
  const Eigen::LDLT<Eigen::Matrix3d> ldlt(pxx);
  Eigen::Vector3d dx = pose - g.mean.head<3>();
  dx(2) = wrap_angle(dx(2));
  std::vector<ConditionedLandmark> out;
  out.reserve(g.landmarks.size());
  for (int i = 0; i < g.landmark_count(); ++i) {
    const Eigen::Index j = 3 + 2 * i;
    const Eigen::Matrix<double, 3, 2> pxi = g.pose_landmark_cov(i);
    const Eigen::Matrix<double, 2, 3> a = ldlt.solve(pxi).transpose();  // P_ix Pxx^-1
    ConditionedLandmark c;
    c.slot = g.landmarks[static_cast<std::size_t>(i)].slot;
    c.counts = g.landmarks[static_cast<std::size_t>(i)].counts;
    c.mean = g.mean.segment<2>(j) + a * dx;
    c.cov = g.landmark_cov(i) - a * pxi;
    c.cov = 0.5 * (c.cov + c.cov.transpose()).eval();
    // Rounding can leave a nearly singular block indefinite: floor its eigenvalues.
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eig(c.cov);
    if (eig.eigenvalues().minCoeff() < kMinLandmarkVariance) {
      const Eigen::Vector2d floored = eig.eigenvalues().cwiseMax(kMinLandmarkVariance);
      c.cov = eig.eigenvectors() * floored.asDiagonal() * eig.eigenvectors().transpose();
    }
    out.push_back(c);
  }
  return out;
}

}  // namespace pixyslam::slam
