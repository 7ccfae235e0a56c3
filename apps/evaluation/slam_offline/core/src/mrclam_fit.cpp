#include "pixyslam/mrclam/mrclam_fit.h"

#include <Eigen/Cholesky>

#include <algorithm>
#include <cmath>
#include <map>
#include <stdexcept>
#include <string>
#include <utility>

namespace pixyslam::mrclam {

namespace {

double wrap(double a) { return std::remainder(a, 2.0 * M_PI); }

double median_of(std::vector<double> v) {
  if (v.empty()) return 0.0;
  const std::size_t mid = v.size() / 2;
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(mid), v.end());
  const double upper = v[mid];
  if (v.size() % 2 == 1) return upper;
  const double lower = *std::max_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(mid));
  return 0.5 * (lower + upper);
}

// 1.4826 MAD about the median (the sd of a normal sample).
double robust_sd(const std::vector<double>& v) {
  const double m = median_of(v);
  std::vector<double> dev(v.size());
  for (std::size_t i = 0; i < v.size(); ++i) dev[i] = std::abs(v[i] - m);
  return 1.4826 * median_of(std::move(dev));
}

double rms(const std::vector<double>& v) {
  if (v.empty()) return 0.0;
  double s = 0.0;
  for (double e : v) s += e * e;
  return std::sqrt(s / static_cast<double>(v.size()));
}

// The ground truth of one robot, cleaned: pieces without gaps over max_gap,
// heading unwrapped, x, y and heading through a running median.
class TruthTrack {
 public:
  struct Pose {
    double x, y, theta;  // theta unwrapped within its piece
  };

  TruthTrack(std::vector<eval::TimedPose> truth, const FitOptions& o) {
    std::stable_sort(truth.begin(), truth.end(), [](const auto& a, const auto& b) { return a.t_s < b.t_s; });
    std::vector<eval::TimedPose> run;
    const auto flush = [&] {
      if (run.size() >= 2) pieces_.push_back(clean(run, o.truth_median_samples));
      run.clear();
    };
    for (const eval::TimedPose& p : truth) {
      if (!std::isfinite(p.t_s) || !std::isfinite(p.x_m) || !std::isfinite(p.y_m) || !std::isfinite(p.theta_rad)) {
        continue;
      }
      if (!run.empty() && p.t_s <= run.back().t_s) continue;  // repeated stamp
      if (!run.empty() && p.t_s - run.back().t_s > o.max_truth_gap_s) flush();
      run.push_back(p);
    }
    flush();
  }

  bool empty() const { return pieces_.empty(); }
  double start() const { return pieces_.front().t.front(); }
  double end() const { return pieces_.back().t.back(); }

  // The pose at t and, when `until` is given, also checks that [t, until] lies
  // in the same piece. Returns the piece index or -1.
  int piece_of(double t, double until) const {
    auto it = std::upper_bound(pieces_.begin(), pieces_.end(), t,
                               [](double time, const Piece& p) { return time < p.t.front(); });
    if (it == pieces_.begin()) return -1;
    --it;
    if (t > it->t.back() || until > it->t.back()) return -1;
    return static_cast<int>(it - pieces_.begin());
  }

  Pose at(int piece, double t) const {
    const Piece& p = pieces_[static_cast<std::size_t>(piece)];
    auto it = std::upper_bound(p.t.begin(), p.t.end(), t);
    std::size_t hi = static_cast<std::size_t>(it - p.t.begin());
    if (hi >= p.t.size()) hi = p.t.size() - 1;
    const std::size_t lo = hi - 1;
    const double dt = p.t[hi] - p.t[lo];
    const double u = dt > 0.0 ? std::clamp((t - p.t[lo]) / dt, 0.0, 1.0) : 0.0;
    return {p.x[lo] + u * (p.x[hi] - p.x[lo]), p.y[lo] + u * (p.y[hi] - p.y[lo]),
            p.th[lo] + u * (p.th[hi] - p.th[lo])};
  }

 private:
  struct Piece {
    std::vector<double> t, x, y, th;
  };

  static Piece clean(const std::vector<eval::TimedPose>& run, int median_samples) {
    const std::size_t n = run.size();
    const std::size_t half = median_samples > 1 ? static_cast<std::size_t>(median_samples / 2) : 0;
    Piece p;
    p.t.resize(n);
    p.x.resize(n);
    p.y.resize(n);
    p.th.resize(n);
    std::vector<double> wx, wy, wth;
    double reference = run.front().theta_rad;
    for (std::size_t i = 0; i < n; ++i) {
      // Symmetric window, shrunk at the ends of the piece.
      const std::size_t h = std::min({half, i, n - 1 - i});
      wx.clear();
      wy.clear();
      wth.clear();
      for (std::size_t j = i - h; j <= i + h; ++j) {
        wx.push_back(run[j].x_m);
        wy.push_back(run[j].y_m);
        // Unwrapped against the previous cleaned heading: a glitch becomes a
        // value within pi of it that the median drops, not a 2 pi slip.
        wth.push_back(reference + wrap(run[j].theta_rad - reference));
      }
      p.t[i] = run[i].t_s;
      p.x[i] = median_of(wx);
      p.y[i] = median_of(wy);
      p.th[i] = median_of(wth);
      reference = p.th[i];
    }
    return p;
  }

  std::vector<Piece> pieces_;
};

// Commanded velocities held from their stamp to the next one, at most
// timeout (then zero).
class Commands {
 public:
  Commands(const std::vector<OdometryRow>& rows, double timeout_s) : timeout_(timeout_s) {
    std::vector<OdometryRow> sorted = rows;
    std::stable_sort(sorted.begin(), sorted.end(), [](const auto& a, const auto& b) { return a.t_s < b.t_s; });
    for (const OdometryRow& r : sorted) {
      if (!std::isfinite(r.t_s) || !std::isfinite(r.v_mps) || !std::isfinite(r.w_radps)) continue;
      if (!t_.empty() && r.t_s == t_.back()) {  // the later row of a repeated stamp wins
        v_.back() = r.v_mps;
        w_.back() = r.w_radps;
        continue;
      }
      t_.push_back(r.t_s);
      v_.push_back(r.v_mps);
      w_.push_back(r.w_radps);
    }
  }

  bool empty() const { return t_.empty(); }
  double first() const { return t_.front(); }
  double last() const { return t_.back(); }

  // Index of the command in force at s (the last stamp at or before s), or -1.
  long index_at(double s) const {
    return static_cast<long>(std::upper_bound(t_.begin(), t_.end(), s) - t_.begin()) - 1;
  }
  double w_at(long i, double s) const {
    if (i < 0) return 0.0;
    const std::size_t k = static_cast<std::size_t>(i);
    return s - t_[k] > timeout_ ? 0.0 : w_[k];
  }

  // Integrals of v and v |w| over [a, b] (a at or after the first command).
  void integrate(double a, double b, double& int_v, double& int_vw) const {
    int_v = int_vw = 0.0;
    long i = index_at(a);
    for (; i >= 0 && static_cast<std::size_t>(i) < t_.size(); ++i) {
      const std::size_t k = static_cast<std::size_t>(i);
      if (t_[k] >= b) break;
      const double next = k + 1 < t_.size() ? t_[k + 1] : b;
      const double held_until = std::min(next, t_[k] + timeout_);
      const double lo = std::max(a, t_[k]), hi = std::min(b, held_until);
      if (hi > lo) {
        int_v += v_[k] * (hi - lo);
        int_vw += v_[k] * std::abs(w_[k]) * (hi - lo);
      }
    }
  }

 private:
  double timeout_;
  std::vector<double> t_, v_, w_;
};

void check_robots(const std::vector<const RobotData*>& robots) {
  if (robots.empty()) throw std::invalid_argument("mrclam fit: no robots");
  for (const RobotData* r : robots) {
    if (r == nullptr) throw std::invalid_argument("mrclam fit: null robot");
    if (r->groundtruth.size() < 2) {
      throw std::invalid_argument("mrclam fit: robot " + std::to_string(r->robot) + " has no ground truth");
    }
  }
}

Eigen::VectorXd solve_weighted(const Eigen::MatrixXd& X, const Eigen::VectorXd& y, const Eigen::VectorXd& w) {
  const Eigen::MatrixXd A = X.transpose() * w.asDiagonal() * X;
  const Eigen::VectorXd b = X.transpose() * w.cwiseProduct(y);
  const Eigen::LDLT<Eigen::MatrixXd> ldlt(A);
  // (LDLT::rcond() misses an exactly zero pivot: the pivots themselves are checked.)
  const Eigen::VectorXd pivots = ldlt.vectorD();
  if (ldlt.info() != Eigen::Success || !(pivots.minCoeff() > 1e-12 * pivots.cwiseAbs().maxCoeff())) {
    throw std::invalid_argument("robust_linear_fit: singular normal equations");
  }
  return ldlt.solve(b);
}

// 1.4826 times the median absolute residual.
double residual_scale(const Eigen::VectorXd& r) {
  std::vector<double> a(static_cast<std::size_t>(r.size()));
  for (Eigen::Index i = 0; i < r.size(); ++i) a[static_cast<std::size_t>(i)] = std::abs(r[i]);
  return 1.4826 * median_of(std::move(a));
}

}  // namespace

RobustLinearFit robust_linear_fit(const Eigen::MatrixXd& X, const Eigen::VectorXd& y, double huber_k,
                                  double trim_sigmas) {
  const Eigen::Index n = X.rows(), p = X.cols();
  if (y.size() != n || p == 0) throw std::invalid_argument("robust_linear_fit: X and y sizes disagree");
  if (n < 2 * p) throw std::invalid_argument("robust_linear_fit: too few samples");
  if (!X.allFinite() || !y.allFinite()) throw std::invalid_argument("robust_linear_fit: non-finite input");
  RobustLinearFit fit;
  fit.samples = static_cast<std::size_t>(n);
  Eigen::VectorXd w = Eigen::VectorXd::Ones(n);
  Eigen::VectorXd beta = solve_weighted(X, y, w);
  // Huber M-estimate by IRLS, the scale from the MAD at each step.
  for (int it = 0; it < 200; ++it) {
    const Eigen::VectorXd r = y - X * beta;
    const double sigma = residual_scale(r);
    if (!(sigma > 0.0)) break;  // half the samples fit exactly
    const double c = huber_k * sigma;
    for (Eigen::Index i = 0; i < n; ++i) w[i] = std::abs(r[i]) <= c ? 1.0 : c / std::abs(r[i]);
    const Eigen::VectorXd next = solve_weighted(X, y, w);
    const double change = (next - beta).norm();
    beta = next;
    if (change <= 1e-12 * (1.0 + beta.norm())) break;
  }
  // Trimmed least squares: drop beyond trim_sigmas sigma, refit, until stable.
  std::vector<bool> inlier(static_cast<std::size_t>(n), true), previous;
  for (int it = 0; it < 50; ++it) {
    const Eigen::VectorXd r = y - X * beta;
    const double sigma = residual_scale(r);
    for (Eigen::Index i = 0; i < n; ++i) {
      inlier[static_cast<std::size_t>(i)] = !(sigma > 0.0) || std::abs(r[i]) <= trim_sigmas * sigma;
    }
    if (inlier == previous) break;
    previous = inlier;
    for (Eigen::Index i = 0; i < n; ++i) w[i] = inlier[static_cast<std::size_t>(i)] ? 1.0 : 0.0;
    if (w.sum() < static_cast<double>(2 * p)) break;
    beta = solve_weighted(X, y, w);
  }
  fit.coef = beta;
  fit.sigma = residual_scale(y - X * beta);
  fit.inliers = static_cast<std::size_t>(std::count(inlier.begin(), inlier.end(), true));
  return fit;
}

RangeFit fit_range(const std::vector<const RobotData*>& robots, const FitOptions& o) {
  check_robots(robots);
  struct Sample {
    double r, b, r_true, b_true;
  };
  std::vector<Sample> samples;
  for (const RobotData* data : robots) {
    const TruthTrack track(data->groundtruth, o);
    if (track.empty()) continue;
    std::map<int, std::pair<double, double>> landmarks;
    for (const eval::LandmarkPoint& l : data->landmarks) landmarks[l.id] = {l.x_m, l.y_m};
    for (const MeasurementFrame& f : data->frames) {
      const int piece = track.piece_of(f.t_s, f.t_s);
      if (piece < 0) continue;
      const TruthTrack::Pose g = track.at(piece, f.t_s);
      for (const Detection& d : f.detections) {
        if (d.subject >= 1 && d.subject <= 5) continue;  // another robot
        const auto lm = landmarks.find(d.subject);
        if (lm == landmarks.end()) continue;
        const double dx = lm->second.first - g.x, dy = lm->second.second - g.y;
        const double r_true = std::hypot(dx, dy);
        if (!(r_true >= o.min_true_range_m) || !(d.range_m > 0.0) || !std::isfinite(d.bearing_rad)) continue;
        if (!(std::cos(d.bearing_rad) >= o.min_cos_bearing)) continue;
        samples.push_back({d.range_m, d.bearing_rad, r_true, wrap(std::atan2(dy, dx) - g.theta)});
      }
    }
  }
  Eigen::MatrixXd X(static_cast<Eigen::Index>(samples.size()), 2);
  Eigen::VectorXd y(static_cast<Eigen::Index>(samples.size()));
  for (std::size_t i = 0; i < samples.size(); ++i) {
    const auto k = static_cast<Eigen::Index>(i);
    X(k, 0) = 1.0;
    X(k, 1) = std::log(std::cos(samples[i].b));
    y[k] = std::log(samples[i].r / samples[i].r_true);
  }
  const RobustLinearFit f = robust_linear_fit(X, y);
  RangeFit out;
  out.range_scale = std::exp(f.coef[0]);
  out.cos_bearing_exponent = f.coef[1];
  out.samples = f.samples;
  out.inliers = f.inliers;
  out.log_sigma = f.sigma;
  std::vector<double> after, before, bearing;
  for (const Sample& s : samples) {
    after.push_back(s.r / (out.range_scale * std::pow(std::cos(s.b), out.cos_bearing_exponent)) - s.r_true);
    before.push_back(s.r - s.r_true);
    bearing.push_back(wrap(s.b - s.b_true));
  }
  out.range_sigma_m = robust_sd(after);
  out.range_rms_m = rms(after);
  out.range_sigma_before_m = robust_sd(before);
  out.range_rms_before_m = rms(before);
  out.bearing_sigma_rad = robust_sd(bearing);
  out.bearing_rms_rad = rms(bearing);
  out.bearing_median_rad = median_of(bearing);
  return out;
}

DelayFit fit_delay(const std::vector<const RobotData*>& robots, const FitOptions& o) {
  check_robots(robots);
  if (!(o.delay_step_s > 0.0) || !(o.delay_max_s >= o.delay_min_s)) {
    throw std::invalid_argument("fit_delay: bad lag grid");
  }
  const auto lags = static_cast<std::size_t>(std::floor((o.delay_max_s - o.delay_min_s) / o.delay_step_s + 1e-9)) + 1;
  // Truth yaw rates beyond this are motion-capture errors (the robots turn at
  // most ~1 rad/s); such times are left out at every lag.
  constexpr double kMaxYawRate = 3.0;
  struct Sums {
    double n = 0, x = 0, y = 0, xx = 0, yy = 0, xy = 0;
  };
  std::vector<Sums> sums(lags);
  const double h = 0.5 * o.yaw_rate_window_s;
  for (const RobotData* data : robots) {
    const TruthTrack track(data->groundtruth, o);
    const Commands commands(data->odometry, o.control_timeout_s);
    if (track.empty() || commands.empty()) continue;
    // Grid times with a truth yaw rate and a command at every lag.
    std::vector<double> times, rates;
    const double t0 = std::max(track.start(), commands.first() + o.delay_max_s) + h;
    for (long j = 0;; ++j) {
      const double t = t0 + static_cast<double>(j) * o.delay_step_s;
      if (t + h > track.end()) break;
      const int piece = track.piece_of(t - h, t + h);
      if (piece < 0) continue;
      const double rate = (track.at(piece, t + h).theta - track.at(piece, t - h).theta) / (2.0 * h);
      if (std::abs(rate) > kMaxYawRate) continue;
      times.push_back(t);
      rates.push_back(rate);
    }
    for (std::size_t k = 0; k < lags; ++k) {
      const double d = o.delay_min_s + static_cast<double>(k) * o.delay_step_s;
      Sums& s = sums[k];
      for (std::size_t j = 0; j < times.size(); ++j) {
        const double at = times[j] - d;
        const double x = commands.w_at(commands.index_at(at), at), y = rates[j];
        s.n += 1;
        s.x += x;
        s.y += y;
        s.xx += x * x;
        s.yy += y * y;
        s.xy += x * y;
      }
    }
  }
  DelayFit out;
  out.samples = static_cast<std::size_t>(sums[0].n);
  if (out.samples < 10) throw std::invalid_argument("fit_delay: too few samples with truth and commands");
  for (std::size_t k = 0; k < lags; ++k) {
    const Sums& s = sums[k];
    const double cov = s.xy - s.x * s.y / s.n;
    const double vx = s.xx - s.x * s.x / s.n, vy = s.yy - s.y * s.y / s.n;
    const double c = vx > 0.0 && vy > 0.0 ? cov / std::sqrt(vx * vy) : 0.0;
    out.lags_s.push_back(o.delay_min_s + static_cast<double>(k) * o.delay_step_s);
    out.correlations.push_back(c);
  }
  const std::size_t best = static_cast<std::size_t>(
      std::max_element(out.correlations.begin(), out.correlations.end()) - out.correlations.begin());
  out.delay_s = out.lags_s[best];
  out.correlation = out.correlations[best];
  out.correlation_at_zero = out.correlations.front();
  return out;
}

SpeedFit fit_speed(const std::vector<const RobotData*>& robots, double delay_s, const FitOptions& o) {
  check_robots(robots);
  if (!(o.speed_window_s > 0.0) || !(o.speed_stride_s > 0.0)) throw std::invalid_argument("fit_speed: bad window");
  const double h = 0.5 * o.speed_window_s;
  const int steps = std::max(1, static_cast<int>(std::lround(o.speed_window_s / 0.01)));
  std::vector<double> col_v, col_vw, target;
  for (const RobotData* data : robots) {
    const TruthTrack track(data->groundtruth, o);
    const Commands commands(data->odometry, o.control_timeout_s);
    if (track.empty() || commands.empty()) continue;
    const double c0 = std::max(track.start(), commands.first() + delay_s) + h;
    for (long j = 0;; ++j) {
      const double c = c0 + static_cast<double>(j) * o.speed_stride_s;
      if (c + h > track.end()) break;
      const int piece = track.piece_of(c - h, c + h);
      if (piece < 0) continue;
      double int_v = 0.0, int_vw = 0.0;
      commands.integrate(c - h - delay_s, c + h - delay_s, int_v, int_vw);
      const double mean_v = int_v / o.speed_window_s, mean_vw = int_vw / o.speed_window_s;
      if (!(std::abs(mean_v) > o.min_speed_mps)) continue;
      // Forward distance: each increment projected on the heading at its middle.
      double forward = 0.0;
      TruthTrack::Pose prev = track.at(piece, c - h);
      for (int m = 1; m <= steps; ++m) {
        const double s = m == steps ? c + h : c - h + o.speed_window_s * m / steps;
        const TruthTrack::Pose next = track.at(piece, s);
        const double mid = 0.5 * (prev.theta + next.theta);
        forward += (next.x - prev.x) * std::cos(mid) + (next.y - prev.y) * std::sin(mid);
        prev = next;
      }
      col_v.push_back(mean_v);
      col_vw.push_back(mean_vw);
      target.push_back(forward / o.speed_window_s);
    }
  }
  const auto n = static_cast<Eigen::Index>(target.size());
  Eigen::MatrixXd X(n, 2);
  Eigen::VectorXd y(n);
  for (Eigen::Index i = 0; i < n; ++i) {
    X(i, 0) = col_v[static_cast<std::size_t>(i)];
    X(i, 1) = -col_vw[static_cast<std::size_t>(i)];
    y[i] = target[static_cast<std::size_t>(i)];
  }
  const RobustLinearFit f = robust_linear_fit(X, y);
  SpeedFit out;
  out.speed_scale = f.coef[0];
  out.speed_loss_per_radps = f.coef[1];
  out.samples = f.samples;
  out.inliers = f.inliers;
  out.sigma_mps = f.sigma;
  return out;
}

CorrectionFit fit_corrections(const std::vector<const RobotData*>& robots, const FitOptions& options) {
  CorrectionFit fit;
  fit.range = fit_range(robots, options);
  fit.delay = fit_delay(robots, options);
  fit.speed = fit_speed(robots, fit.delay.delay_s, options);
  return fit;
}

}  // namespace pixyslam::mrclam
