#pragma once

#include <string>
#include <vector>

#include "pixyslam/offline/offline_run.h"
#include "pixyslam/map_optimizer/map_optimizer.h"

namespace pixyslam::offline {

struct OptimisedRun {
  // Same layout as the filter's: a pose at every filter step (its keyframe in
  // the solution moved by the odometry since), covariances NaN (not computed),
  // the filter's dead reckoning, the optimised landmarks with their marginal
  // covariances; wall and CPU time of building and solving.
  RunResult result;
  map_optimizer::SolveSummary solve;            // the final whole-problem solve
  std::vector<map_optimizer::SolveSummary> window_solves, whole_solves;  // on the way (the schedule)
  map_optimizer::OptimizerCounters counters;
  map_optimizer::SolveScheduleOptions schedule;  // the one it ran (after optimizer_sets)
  bool landmark_covariances = false;
};

// The map optimiser over a whole run after the filter (slam_offline --optimise,
// mrclam_eval --optimise): the same input in the filter's order, keyframes
// started from the filter's poses at the camera frames and landmarks from its
// map, one solve of the whole problem at the end (and on the way as `schedule`
// says; the live process's schedule for bench_map_optimizer). The optimiser's
// own keys keep their defaults but for `optimizer_sets` ("KEY=V", the
// optimizer. section of --set: the optimiser's and the schedule's keys, as the
// map_optimizer process takes them; std::invalid_argument naming a bad one).
OptimisedRun optimise_run(const slam::FilterOptions& options, const RunInput& input, const RunResult& filter,
                          const map_optimizer::SolveScheduleOptions& schedule =
                              map_optimizer::SolveScheduleOptions::at_end_only(),
                          const std::vector<std::string>& optimizer_sets = {});

// The optimiser's options for a run with these filter options, and `schedule`,
// after --set optimizer.KEY=V.
map_optimizer::MapOptimizerOptions optimizer_options(const slam::FilterOptions& options,
                                                     const std::vector<std::string>& optimizer_sets,
                                                     map_optimizer::SolveScheduleOptions& schedule);

}  // namespace pixyslam::offline
