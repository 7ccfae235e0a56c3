#pragma once

#include <optional>
#include <vector>

#include "pixyslam/offline/offline_run.h"

namespace pixyslam::offline {

// Recovery after a blind stretch (docs/mrclam.md, "Blind stretch and return"):
// a run restarted from the truth is cut into
//   seen    landmarks as recorded;
//   blind   no landmarks; the odometry's turn rate biased by heading_bias_radps
//           (dead reckoning's heading walks off, as a real robot's did by 34 deg
//           in 39 s);
//   far     only landmarks not seen in the first stretch, and only beyond
//           far_min_range_m: mapped in whatever frame the pose drifted into;
//   return  everything again, from the first frame that sees a landmark of the
//           first stretch, scored for after_s seconds.
// A filter that locked in the drifted frame keeps its heading error after the
// return; one that kept the alternatives moves back to the frame of the first
// landmarks.
struct BlindReturnOptions {
  double seen_s = 16.0;
  double blind_s = 40.0;
  double heading_bias_radps = 0.015;
  double far_s = 60.0;
  double far_min_range_m = 2.0;
  double after_s = 60.0;
};
void validate(const BlindReturnOptions& options);

struct BlindReturnCase {
  RunInput input;          // restarted input, modified and cut at return_s + after_s; truth in time order
  double blind_start_s = 0.0;
  double far_start_s = 0.0;
  double return_s = 0.0;   // the first frame that sees a landmark of the first stretch again
  std::vector<int> first_landmarks;  // ids seen in the first stretch
};

// The case from `restarted` (restart_at_truth): times relative to its
// start_time_s. nullopt when no landmark is seen in the first stretch or none of
// them comes back within after_s after the far stretch, or the input ends first.
std::optional<BlindReturnCase> make_blind_return(const RunInput& restarted, const BlindReturnOptions& options);

// The heading error against the truth (interpolated) around the return.
struct ReturnScore {
  double heading_error_at_return_rad = 0.0;  // |error| at the last step before return_s
  double heading_rmse_after_rad = 0.0;       // over [return_s, end]
  double heading_error_end_rad = 0.0;        // mean |error| over the last 10 s
  double ate_after_m = 0.0;                  // position RMSE over [return_s, end]
  std::size_t steps_after = 0;
};
// Throws std::invalid_argument when the trajectory has no step with truth after the return.
ReturnScore score_return(const BlindReturnCase& c, const std::vector<eval::TimedPose>& trajectory);

}  // namespace pixyslam::offline
