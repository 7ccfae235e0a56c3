#pragma once

#include "offline_run.h"
#include "pixyslam/map_optimizer/map_optimizer.h"

namespace pixyslam::offline {

// The live process's solves as the data come (map_optimizer): the newest
// window_keyframes every window_period_s of data, the whole problem every
// whole_period_s; 0 turns either off. The whole problem is solved at the end
// in any case.
struct OptimiseSchedule {
  double window_period_s = 0.0;
  std::size_t window_keyframes = 100;
  double whole_period_s = 0.0;
};

struct OptimisedRun {
  // Same layout as the filter's: a pose at every filter step (its keyframe in
  // the solution moved by the odometry since), covariances NaN (not computed),
  // the filter's dead reckoning, the optimised landmarks with their marginal
  // covariances; wall and CPU time of building and solving.
  RunResult result;
  map_optimizer::SolveSummary solve;            // the final whole-problem solve
  std::vector<map_optimizer::SolveSummary> window_solves, whole_solves;  // on the way (OptimiseSchedule)
  map_optimizer::OptimizerCounters counters;
  bool landmark_covariances = false;
};

// The map optimiser over a whole run after the filter (slam_offline --optimise,
// mrclam_eval --optimise): the same input in the filter's order, keyframes
// started from the filter's poses at the camera frames and landmarks from its
// map, one solve of the whole problem at the end (and on the way as `schedule` says).
OptimisedRun optimise_run(const slam::FilterOptions& options, const RunInput& input, const RunResult& filter,
                          const OptimiseSchedule& schedule = {});

}  // namespace pixyslam::offline
