#include "pixyslam/fleet_map/map_fusion.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <set>
#include <stdexcept>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <Eigen/LU>

namespace pixyslam::fleet_map {

const char* to_string(FrameVerdict verdict) {
  switch (verdict) {
    case FrameVerdict::kAgrees: return "agrees";
    case FrameVerdict::kDisagrees: return "disagrees";
    case FrameVerdict::kUnchecked: return "unchecked";
  }
  return "?";
}

namespace {

// The regularised incomplete beta function I_x(a, b), by its continued
// fraction (modified Lentz), on the side where it converges fast.
double incomplete_beta(double x, double a, double b) {
  if (x <= 0.0) return 0.0;
  if (x >= 1.0) return 1.0;
  if (x > (a + 1.0) / (a + b + 2.0)) return 1.0 - incomplete_beta(1.0 - x, b, a);
  const double log_front = std::lgamma(a + b) - std::lgamma(a) - std::lgamma(b) + a * std::log(x) + b * std::log1p(-x);
  constexpr double kTiny = 1e-300;
  double c = 1.0, d = 1.0 - (a + b) * x / (a + 1.0);
  if (std::abs(d) < kTiny) d = kTiny;
  d = 1.0 / d;
  double f = d;
  for (int m = 1; m <= 500; ++m) {
    for (int step = 0; step < 2; ++step) {
      const double numerator = step == 0 ? m * (b - m) * x / ((a + 2 * m - 1) * (a + 2 * m))
                                         : -(a + m) * (a + b + m) * x / ((a + 2 * m) * (a + 2 * m + 1));
      d = 1.0 + numerator * d;
      if (std::abs(d) < kTiny) d = kTiny;
      c = 1.0 + numerator / c;
      if (std::abs(c) < kTiny) c = kTiny;
      d = 1.0 / d;
      f *= c * d;
      if (step == 1 && std::abs(c * d - 1.0) < 1e-14) return std::exp(log_front) * f / a;
    }
  }
  return std::exp(log_front) * f / a;
}

double f_cdf(double f, int d1, int d2) {
  return incomplete_beta(d1 * f / (d1 * f + d2), 0.5 * d1, 0.5 * d2);
}

}  // namespace

double f_quantile(double probability, int d1, int d2) {
  if (!(probability > 0.0 && probability < 1.0) || d1 < 1 || d2 < 1) {
    throw std::invalid_argument("f_quantile: probability must be in (0, 1) and the degrees of freedom >= 1");
  }
  double lo = 0.0, hi = 1.0;
  while (f_cdf(hi, d1, d2) < probability && hi < 1e12) hi *= 2.0;
  for (int i = 0; i < 200 && hi - lo > 1e-12 * hi; ++i) {
    const double mid = 0.5 * (lo + hi);
    (f_cdf(mid, d1, d2) < probability ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

namespace {

// Positions and variances no estimator of a real map makes: within 1000 km of
// the origin, standard deviations from 1 um to 1 km. Anything beyond (a hostile
// or broken sender) would swamp the fusion: 1e200 m with a tiny covariance
// makes every fused landmark NaN, and the maps are kept while the robot is.
constexpr double kMaxCoordinate = 1e6;       // m
constexpr double kMinVariance = 1e-12;       // m^2
constexpr double kMaxVariance = 1e6;         // m^2

bool usable(const LandmarkEstimate& l) {
  if (!l.mean.allFinite() || !l.cov.allFinite()) return false;
  if (l.mean.cwiseAbs().maxCoeff() > kMaxCoordinate) return false;
  if (std::abs(l.cov(0, 1) - l.cov(1, 0)) > 1e-9 * (std::abs(l.cov(0, 0)) + std::abs(l.cov(1, 1)))) return false;
  const Eigen::Vector2d variances = Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d>(l.cov).eigenvalues();
  return variances.minCoeff() >= kMinVariance && variances.maxCoeff() <= kMaxVariance;
}

// Information-form sums of one landmark.
struct Information {
  Eigen::Matrix2d matrix = Eigen::Matrix2d::Zero();
  Eigen::Vector2d vector = Eigen::Vector2d::Zero();
  std::size_t robots = 0;
  void add(const LandmarkEstimate& l) {
    const Eigen::Matrix2d inverse = l.cov.inverse();
    matrix += inverse;
    vector += inverse * l.mean;
    ++robots;
  }
  LandmarkEstimate estimate(int id) const {
    LandmarkEstimate e;
    e.id = id;
    e.cov = matrix.inverse();
    e.mean = e.cov * vector;
    return e;
  }
};

// The usable landmarks of each map, by id.
using Clean = std::vector<std::map<int, LandmarkEstimate>>;

std::map<int, Information> fuse(const Clean& maps, const std::vector<bool>& use) {
  std::map<int, Information> out;
  for (std::size_t r = 0; r < maps.size(); ++r) {
    if (!use[r]) continue;
    for (const auto& [id, l] : maps[r]) out[id].add(l);
  }
  return out;
}

// The landmarks `mine` shares with `fleet`: (mine, fleet's estimate) by id.
using Pairs = std::vector<std::pair<LandmarkEstimate, LandmarkEstimate>>;
Pairs shared_with(const std::map<int, LandmarkEstimate>& mine, const std::map<int, Information>& fleet) {
  Pairs shared;
  for (const auto& [id, l] : mine) {
    const auto it = fleet.find(id);
    if (it != fleet.end()) shared.emplace_back(l, it->second.estimate(id));
  }
  return shared;
}

// A pair's weight: 1 / trace of the summed covariance.
double weight(const LandmarkEstimate& a, const LandmarkEstimate& b) { return 1.0 / (a.cov + b.cov).trace(); }

// The weighted least-squares rigid fit of the first of each pair onto the
// second, about `centre`: the weighted centroids (relative to centre) and the
// rotation between them (0 with fewer than two pairs).
struct RigidFit {
  double w_sum = 0.0;
  Eigen::Vector2d a_bar = Eigen::Vector2d::Zero(), b_bar = Eigen::Vector2d::Zero();
  double angle = 0.0;
};

RigidFit fit_rigid(const Pairs& shared, const Eigen::Vector2d& centre) {
  RigidFit f;
  for (const auto& [a, b] : shared) {
    const double w = weight(a, b);
    f.w_sum += w;
    f.a_bar += w * (a.mean - centre);
    f.b_bar += w * (b.mean - centre);
  }
  f.a_bar /= f.w_sum;
  f.b_bar /= f.w_sum;
  double dot = 0.0, cross = 0.0;
  for (const auto& [a, b] : shared) {
    const double w = weight(a, b);
    const Eigen::Vector2d p = a.mean - centre - f.a_bar, q = b.mean - centre - f.b_bar;
    dot += w * p.dot(q);
    cross += w * (p.x() * q.y() - p.y() * q.x());
  }
  f.angle = shared.size() >= 2 ? std::atan2(cross, dot) : 0.0;
  return f;
}

FrameCheck check(const std::string& robot_id, const std::map<int, LandmarkEstimate>& mine,
                 const std::map<int, Information>& others, const FusionOptions& options) {
  FrameCheck c;
  c.robot_id = robot_id;
  c.landmarks = mine.size();
  const Pairs shared = shared_with(mine, others);
  c.common = shared.size();
  if (c.common == 0) return c;
  const RigidFit fit = fit_rigid(shared, Eigen::Vector2d::Zero());
  c.offset_m = (fit.b_bar - fit.a_bar).norm();
  c.rotation_rad = fit.angle;
  // Weighted residual sums without the motion (rss0) and after the rigid fit (rss1).
  const Eigen::Rotation2Dd rotation(c.rotation_rad);
  const Eigen::Vector2d shift = fit.b_bar - rotation * fit.a_bar;
  double rss0 = 0.0, rss1 = 0.0;
  for (const auto& [a, b] : shared) {
    const double w = weight(a, b);
    rss0 += w * (b.mean - a.mean).squaredNorm();
    rss1 += w * (b.mean - (rotation * a.mean + shift)).squaredNorm();
  }
  c.residual_m = std::sqrt(rss1 / fit.w_sum);
  const int n = static_cast<int>(c.common);
  if (n < std::max(3, options.min_common_landmarks)) return c;
  c.f_statistic = rss1 > 0.0 ? ((rss0 - rss1) / 3.0) / (rss1 / (2 * n - 3)) : (rss0 > 0.0 ? 1e300 : 0.0);
  c.threshold = f_quantile(options.agreement_probability, 3, 2 * n - 3);
  c.verdict = c.f_statistic <= c.threshold ? FrameVerdict::kAgrees : FrameVerdict::kDisagrees;
  return c;
}

// A rigid motion about the point `centre`: p -> R(angle) (p - centre) + centre + shift.
struct Motion {
  double angle = 0.0;
  Eigen::Vector2d shift = Eigen::Vector2d::Zero();
};

// The weighted least-squares motion about `centre` that puts `mine` on `fleet`'s
// shared landmarks; false with fewer than `min_common` shared.
bool fit_motion(const std::map<int, LandmarkEstimate>& mine, const std::map<int, Information>& fleet,
                const Eigen::Vector2d& centre, int min_common, Motion& motion) {
  const Pairs shared = shared_with(mine, fleet);
  if (shared.size() < static_cast<std::size_t>(min_common)) return false;
  const RigidFit fit = fit_rigid(shared, centre);
  motion.angle = fit.angle;
  motion.shift = fit.b_bar - Eigen::Rotation2Dd(motion.angle) * fit.a_bar;
  return true;
}

std::map<int, LandmarkEstimate> moved(const std::map<int, LandmarkEstimate>& landmarks, const Motion& m,
                                      const Eigen::Vector2d& centre) {
  const Eigen::Matrix2d r = Eigen::Rotation2Dd(m.angle).toRotationMatrix();
  std::map<int, LandmarkEstimate> out;
  for (auto [id, l] : landmarks) {
    l.mean = r * (l.mean - centre) + centre + m.shift;
    l.cov = r * l.cov * r.transpose();
    out[id] = l;
  }
  return out;
}

// kAlign: fuse, fit every robot's motion onto the fusion, hold the motions'
// mean at zero, move the maps, until the motions settle.
Clean align(const Clean& maps, const FusionOptions& options, std::vector<FrameCheck>& checks) {
  const std::vector<bool> all(maps.size(), true);
  Eigen::Vector2d centre = Eigen::Vector2d::Zero();
  {
    const std::map<int, Information> first = fuse(maps, all);
    for (const auto& [id, information] : first) centre += information.estimate(id).mean;
    if (!first.empty()) centre /= static_cast<double>(first.size());
  }
  std::vector<Motion> motions(maps.size());
  Clean current = maps;
  for (int iteration = 0; iteration < 50; ++iteration) {
    const std::map<int, Information> fleet = fuse(current, all);
    std::vector<bool> fitted(maps.size(), false);
    std::vector<Motion> next(maps.size());
    Motion mean;
    int count = 0;
    for (std::size_t r = 0; r < maps.size(); ++r) {
      fitted[r] = fit_motion(maps[r], fleet, centre, options.min_common_landmarks, next[r]);
      if (!fitted[r]) continue;
      mean.angle += next[r].angle;
      mean.shift += next[r].shift;
      ++count;
    }
    if (count == 0) break;
    double change = 0.0;
    for (std::size_t r = 0; r < maps.size(); ++r) {
      if (!fitted[r]) continue;
      next[r].angle -= mean.angle / count;
      next[r].shift -= mean.shift / count;
      change = std::max({change, std::abs(next[r].angle - motions[r].angle), (next[r].shift - motions[r].shift).norm()});
      motions[r] = next[r];
      current[r] = moved(maps[r], motions[r], centre);
    }
    if (change < 1e-9) break;
  }
  for (std::size_t r = 0; r < maps.size(); ++r) {
    checks[r].moved_rotation_rad = motions[r].angle;
    checks[r].moved_shift_m = motions[r].shift.norm();
  }
  return current;
}

}  // namespace

FleetMap fuse_maps(const std::vector<RobotMap>& maps, const FusionOptions& options) {
  if (options.min_common_landmarks < 3) throw std::invalid_argument("min_common_landmarks must be >= 3");
  if (!(options.agreement_probability > 0.0 && options.agreement_probability < 1.0)) {
    throw std::invalid_argument("agreement_probability must be in (0, 1)");
  }
  std::set<std::string> ids;
  Clean clean(maps.size());
  for (std::size_t r = 0; r < maps.size(); ++r) {
    if (!ids.insert(maps[r].robot_id).second) {
      throw std::invalid_argument("robot '" + maps[r].robot_id + "' given twice");
    }
    for (const LandmarkEstimate& l : maps[r].landmarks) {
      if (usable(l)) clean[r][l.id] = l;
    }
  }
  FleetMap out;
  out.robots.resize(maps.size());
  std::vector<bool> use(maps.size(), true);
  const bool set_aside = options.disagreement == FusionOptions::Disagreement::kSetAside;
  for (;;) {
    // Leave one out: each robot still in against the fusion of the others still in.
    std::size_t worst = maps.size();
    double worst_ratio = 0.0;
    for (std::size_t r = 0; r < maps.size(); ++r) {
      if (!use[r]) continue;
      std::vector<bool> others = use;
      others[r] = false;
      out.robots[r] = check(maps[r].robot_id, clean[r], fuse(clean, others), options);
      const FrameCheck& c = out.robots[r];
      if (c.verdict != FrameVerdict::kDisagrees) continue;
      const double ratio = c.f_statistic / c.threshold;
      const bool worse = worst == maps.size() || ratio > worst_ratio * (1.0 + 1e-9) ||
                         (ratio >= worst_ratio * (1.0 - 1e-9) && c.landmarks < out.robots[worst].landmarks);
      if (worse) {
        worst = r;
        worst_ratio = ratio;
      }
    }
    if (!set_aside || worst == maps.size()) break;
    use[worst] = false;  // its check stays as it was: disagrees
    out.robots[worst].fused = false;
  }
  const Clean fused = set_aside ? clean : align(clean, options, out.robots);
  for (const auto& [id, information] : fuse(fused, use)) {
    const LandmarkEstimate e = information.estimate(id);
    out.landmarks.push_back({id, e.mean, e.cov, information.robots});
  }
  return out;
}

}  // namespace pixyslam::fleet_map
