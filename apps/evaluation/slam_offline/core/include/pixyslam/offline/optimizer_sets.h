#pragma once

#include <stdexcept>
#include <string>
#include <vector>

#include "pixyslam/slam/slam_options.h"
#ifdef PIXYSLAM_HAVE_MAP_OPTIMIZER
#include "pixyslam/offline/optimised_run.h"
#endif

namespace pixyslam::offline {

// The optimizer. section of --set (slam_offline, mrclam_eval): it needs
// --optimise, and in a build with the map optimiser every KEY=V is checked now,
// not after the filter ran. Throws std::invalid_argument naming the first bad one.
inline void check_optimizer_sets(const slam::FilterOptions& options, const std::vector<std::string>& sets,
                                 bool optimise) {
  if (!sets.empty() && !optimise) throw std::invalid_argument(sets.front() + ": optimizer. needs --optimise");
#ifdef PIXYSLAM_HAVE_MAP_OPTIMIZER
  map_optimizer::SolveScheduleOptions schedule;
  optimizer_options(options, sets, schedule);
#else
  (void)options;
#endif
}

}  // namespace pixyslam::offline
