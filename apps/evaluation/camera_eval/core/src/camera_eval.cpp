#include "pixyslam/camera_eval/camera_eval.h"

#include <chrono>
#include <cmath>

#include "pixyslam/offline/offline_run.h"

namespace pixyslam::camera_eval {

double EvalResult::detection_rate() const {
  long in_view = 0, detected = 0;
  for (const auto& [id, s] : poles) {
    in_view += s.in_view;
    detected += s.detected;
  }
  return in_view > 0 ? static_cast<double>(detected) / static_cast<double>(in_view) : 0.0;
}

EvalResult evaluate(const EvalOptions& options, const pixy::SignatureMap& signatures, const pixy::CameraModel& model) {
  std::vector<sim::SyntheticPole> poles;
  for (const sim::Pole& p : sim::place_poles(options.world)) {
    const auto sig = [&]() -> std::optional<std::uint16_t> {
      for (const auto& [s, id] : signatures.entries()) {
        if (id == p.id) return s;
      }
      return std::nullopt;
    }();
    if (!sig || *sig < 8 || *sig >= 64) continue;  // two-tag codes only
    poles.push_back({p.id, p.x_m, p.y_m, *sig / 8, *sig % 8});
  }
  const sim::WorldRun run = sim::simulate(options.world);
  sim::SyntheticCameraOptions camera_options = options.camera;
  camera_options.camera = model;
  std::mt19937_64 rng(options.seed);
  EvalResult r;
  double bearing_sq = 0.0, range_error_sum = 0.0;
  int bearing_n = 0;
  double detect_s = 0.0;
  const double frame_dt = 1.0 / options.world.camera_rate_hz;
  double next = 0.0;
  offline::RunInput input;
  input.initial_pose = run.initial_pose;
  input.odometry = run.odometry;
  input.truth = run.truth;
  for (const eval::TimedPose& truth : run.truth) {
    if (truth.t_s + 1e-9 < next) continue;
    next += frame_dt;
    ++r.frames;
    std::vector<sim::RenderedPole> drawn;
    const cv::Mat image = sim::render_camera_image(slam::Pose2(truth.x_m, truth.y_m, truth.theta_rad), poles,
                                                      camera_options, options.detector, rng, &drawn);
    const auto begin = std::chrono::steady_clock::now();
    const std::vector<pixy::PixyBlock> blocks = camera::detect_colour_codes(image, options.detector);
    detect_s += std::chrono::duration<double>(std::chrono::steady_clock::now() - begin).count();
    std::map<int, const sim::RenderedPole*> truth_of;
    for (const sim::RenderedPole& d : drawn) truth_of[d.id] = &d;
    std::map<int, bool> seen;
    slam::ObservationFrame frame{truth.t_s, {}};
    // The bridge's own checks (signature known, inside the image, aspect ratio, duplicates), Eq. 5 and 6.
    pixy::PixyFrame pixy_frame;
    pixy_frame.blocks = blocks;
    for (const pixy::Detection& d : pixy::to_detections(pixy_frame, signatures, model, r.checks)) {
      frame.detections.push_back({d.landmark_id, d.range_m, d.bearing_rad, d.range_sigma_m, d.bearing_sigma_rad});
      const auto t = truth_of.find(d.landmark_id);
      if (t == truth_of.end() || std::abs(d.bearing_rad - t->second->bearing_rad) > 0.1) {
        ++r.wrong_ids;
        continue;
      }
      seen[d.landmark_id] = true;
      bearing_sq += (d.bearing_rad - t->second->bearing_rad) * (d.bearing_rad - t->second->bearing_rad);
      ++bearing_n;
      if (std::abs(t->second->range_m - 1.0) <= 0.1) {
        range_error_sum += std::abs(d.range_m - t->second->range_m) / t->second->range_m;
        ++r.range_samples_1m;
      }
    }
    if (!frame.detections.empty()) input.frames.push_back(frame);
    for (const sim::RenderedPole& d : drawn) {
      if (!d.in_image || d.occluded || d.range_m > options.max_range_m) continue;
      PoleStats& s = r.poles[d.id];
      ++s.in_view;
      if (seen.count(d.id)) ++s.detected;
    }
  }
  r.range_error_1m = r.range_samples_1m > 0 ? range_error_sum / r.range_samples_1m : 0.0;
  r.bearing_rms_rad = bearing_n > 0 ? std::sqrt(bearing_sq / bearing_n) : 0.0;
  r.ms_per_frame = r.frames > 0 ? detect_s / r.frames * 1e3 : 0.0;
  const offline::RunResult slam = offline::run_filter(options.filter, input);
  r.pose_ate_m = eval::compare_trajectory(slam.trajectory, run.truth).ate_rmse_m;
  for (const eval::LandmarkRow& l : slam.landmarks) {
    ++r.map_landmarks;
    bool near_its_pole = false;
    for (const sim::SyntheticPole& p : poles) {
      if (p.id == l.id && std::hypot(p.x_m - l.x_m, p.y_m - l.y_m) <= 0.5) near_its_pole = true;
    }
    if (!near_its_pole) ++r.map_wrong_ids;
  }
  return r;
}

}  // namespace pixyslam::camera_eval
