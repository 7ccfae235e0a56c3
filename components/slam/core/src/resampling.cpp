#include "pixyslam/slam/resampling.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace pixyslam::slam {

std::vector<double> normalised_weights(const std::vector<double>& log_weights) {
  if (log_weights.empty()) return {};
  const double max_log = *std::max_element(log_weights.begin(), log_weights.end());
  std::vector<double> w(log_weights.size());
  double sum = 0.0;
  for (std::size_t i = 0; i < w.size(); ++i) {
    w[i] = std::exp(log_weights[i] - max_log);
    sum += w[i];
  }
  for (double& x : w) x /= sum;
  return w;
}

double effective_sample_size(const std::vector<double>& weights) {
  double sum_sq = 0.0;
  for (double w : weights) sum_sq += w * w;
  return sum_sq > 0.0 ? 1.0 / sum_sq : 0.0;
}

std::vector<std::size_t> systematic_resample(const std::vector<double>& weights, std::mt19937_64& rng) {
  const std::size_t n = weights.size();
  if (n == 0) throw std::invalid_argument("systematic_resample: no weights");
  std::vector<std::size_t> picks(n);
  const double step = 1.0 / static_cast<double>(n);
  const double r = std::uniform_real_distribution<double>(0.0, step)(rng);
  double cumulative = weights[0];
  std::size_t i = 0;
  for (std::size_t k = 0; k < n; ++k) {
    const double u = r + static_cast<double>(k) * step;
    while (u > cumulative && i + 1 < n) cumulative += weights[++i];
    picks[k] = i;
  }
  return picks;
}

}  // namespace pixyslam::slam
