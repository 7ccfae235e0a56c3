#include "pixyslam/slam_node/map_state_conversions.h"

#include <algorithm>
#include <cmath>

namespace pixyslam::slam_node {

namespace {

double to_seconds(std::uint64_t stamp_ns, std::uint64_t epoch_ns) {
  // Signed: a sample older than the epoch gives a negative time.
  return static_cast<double>(static_cast<std::int64_t>(stamp_ns - epoch_ns)) * 1e-9;
}

}  // namespace

msg::Pose2D to_pose_msg(const slam::Pose2& p) {
  msg::Pose2D out;
  out.x_m(p.x());
  out.y_m(p.y());
  out.theta_rad(p.z());
  return out;
}

std::uint64_t to_stamp_ns(double t_s, std::uint64_t epoch_ns) {
  return epoch_ns + static_cast<std::uint64_t>(static_cast<std::int64_t>(std::llround(t_s * 1e9)));
}

slam::OdometryInput to_odometry_input(const msg::Odometry& m, std::uint64_t epoch_ns) {
  slam::OdometryInput in;
  in.sample.t_s = to_seconds(m.header().stamp_ns(), epoch_ns);
  in.sample.v_mps = m.v_mps();
  in.sample.w_radps = m.w_radps();
  in.sample.measured = m.encoder_samples() > 0;
  in.period_s = m.period_s();
  in.seq = m.header().seq();
  return in;
}

slam::ObservationInput to_observation_input(const msg::LandmarkObservation& m,
                                            std::uint64_t epoch_ns, bool use_detection_sigmas) {
  slam::ObservationInput in;
  in.frame.t_s = to_seconds(m.header().stamp_ns(), epoch_ns);
  in.seq = m.header().seq();
  in.frame.detections.reserve(m.detections().size());
  for (const msg::LandmarkDetection& d : m.detections()) {
    slam::RangeBearing rb;
    rb.landmark_id = d.landmark_id();
    rb.range_m = d.range_m();
    rb.bearing_rad = d.bearing_rad();
    if (use_detection_sigmas) {
      rb.range_sigma_m = d.range_sigma_m();
      rb.bearing_sigma_rad = d.bearing_sigma_rad();
    }
    in.frame.detections.push_back(rb);
  }
  return in;
}

void fill_map_state(const slam::FastSlam2& filter, const StepInfo& info, int max_particle_poses,
                    bool mixture_landmarks, msg::MapState& out) {
  const slam::PoseEstimate estimate = filter.pose_estimate();
  out.header().stamp_ns(to_stamp_ns(estimate.t_s, info.epoch_ns));
  out.header().frame_id("map");
  out.mean_pose(to_pose_msg(estimate.mean));
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) out.pose_covariance()[static_cast<std::size_t>(3 * r + c)] = estimate.cov(r, c);
  }
  out.best_pose(to_pose_msg(estimate.best));
  out.effective_sample_size(estimate.effective_sample_size);
  out.particle_count(static_cast<std::uint32_t>(estimate.particles));

  const std::size_t count = filter.particle_count();
  out.particle_poses().clear();
  const std::size_t wanted = std::min<std::size_t>(count, static_cast<std::size_t>(std::max(0, max_particle_poses)));
  for (std::size_t k = 0; k < wanted; ++k) {
    out.particle_poses().push_back(to_pose_msg(filter.to_output(filter.particle_pose(k * count / wanted))));
  }

  out.landmarks().clear();
  const std::vector<slam::LandmarkEstimate> landmarks =
      mixture_landmarks ? filter.landmarks_mixture() : filter.landmarks_of_best();
  for (const slam::LandmarkEstimate& l : landmarks) {
    msg::LandmarkEstimate e;
    e.landmark_id(l.id);
    e.x_m(l.mean.x());
    e.y_m(l.mean.y());
    e.cov_xx_m2(l.cov(0, 0));
    e.cov_xy_m2(l.cov(0, 1));
    e.cov_yy_m2(l.cov(1, 1));
    e.times_observed(l.times_observed);
    out.landmarks().push_back(e);
  }

  const slam::FilterCounters& c = filter.counters();
  out.update_time_s(info.update_time_s);
  out.odometry_sequence(info.odometry_seq);
  out.observation_sequence(info.observation_seq);
  out.observations_used(c.observations_used);
  out.observations_gated(c.observations_gated);
  out.observations_new_landmark(c.observations_new_landmark);
  out.samples_late(info.samples_late);
}

}  // namespace pixyslam::slam_node
