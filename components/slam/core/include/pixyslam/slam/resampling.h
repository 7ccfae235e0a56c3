#pragma once

#include <cstddef>
#include <random>
#include <vector>

namespace pixyslam::slam {

// Turns log weights into normalised weights (sum 1), subtracting the maximum
// first so that no weight underflows to zero for all particles.
std::vector<double> normalised_weights(const std::vector<double>& log_weights);

// Effective sample size 1 / sum(w_i^2) of normalised weights.
double effective_sample_size(const std::vector<double>& weights);

// Low-variance (systematic) resampling (Thrun et al., Probabilistic Robotics,
// Table 4.4): one uniform draw r in [0, 1/N), then the particles hit by
// r + k/N, k = 0..N-1. Each particle is drawn floor(N w) or ceil(N w) times.
// Returns the indices of the selected particles, in increasing order.
std::vector<std::size_t> systematic_resample(const std::vector<double>& weights, std::mt19937_64& rng);

}  // namespace pixyslam::slam
