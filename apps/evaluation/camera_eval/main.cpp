// camera_eval: the OpenCV colour-code detector on the synthetic camera driven
// through the simulated world (config/slam_sim.yaml's world, the bridge's
// colour codes and optics from config/pixy_bridge.yaml). Prints per landmark
// the frames in view (whole, unoccluded, within 2 m) and detected, the range
// error at 1 m, wrong ids and the detection time per frame.
//   camera_eval --config-dir config [--seed S]
#include <cstdio>
#include <string>

#include "pixyslam/camera_eval/camera_eval.h"
#include "pixyslam/app/cli.h"
#include "pixyslam/app/process_main.h"
#include "pixyslam/config/yaml_reader.h"
#include "pixyslam/pixy/pixy_options.h"
#include "pixyslam/slam/slam_options_yaml.h"

int main(int argc, char** argv) {
  using namespace pixyslam;
  std::string dir;
  std::uint64_t seed = 1;
  app::Cli cli{"camera_eval",
               "The colour-code detector on the synthetic camera through the simulated world: per landmark the "
               "frames in view and detected, range error at 1 m, wrong ids, detection time per frame."};
  cli.option("--config-dir", dir, "the config folder (pixy_bridge.yaml, slam_sim.yaml)").required().type("DIR");
  cli.option("--seed", seed, "the synthetic camera's noise seed").seed().type("S");
  if (const auto done = cli.parse(argc, argv)) return *done;
  return app::run_main("camera_eval", [&] {
    config::YamlReader pixy_root = config::YamlReader::from_file(dir + "/pixy_bridge.yaml");
    config::YamlReader pixy_yaml = pixy_root.child("pixy");
    const pixy::PixyOptions pixy = pixy::read_pixy_options(pixy_yaml);
    config::YamlReader sim_root = config::YamlReader::from_file(dir + "/slam_sim.yaml");
    config::YamlReader world_yaml = sim_root.child("world");
    camera_eval::EvalOptions options;
    options.world = sim::read_world_options(world_yaml);
    options.seed = seed;
    config::YamlReader filter_yaml = sim_root.child("filter");
    options.filter = slam::read_filter_options(filter_yaml);
    // Whole-pixel boxes of a camera image: the aspect check forgives one pixel.
    pixy::CameraModel model = pixy.camera;
    model.aspect_tolerance_px = 1;
    const camera_eval::EvalResult r = camera_eval::evaluate(options, pixy.signatures, model);
    std::printf("%-9s %9s %9s %7s\n", "landmark", "in_view", "detected", "rate");
    for (const auto& [id, s] : r.poles) {
      std::printf("%-9d %9d %9d %6.1f%%\n", id, s.in_view, s.detected, s.in_view ? 100.0 * s.detected / s.in_view : 0.0);
    }
    std::printf("frames %d, detection rate %.2f %%, range error at 1 m %.2f %% (%d detections), bearing RMS %.4f rad, "
                "wrong ids %d, detection %.2f ms per frame\n",
                r.frames, 100.0 * r.detection_rate(), 100.0 * r.range_error_1m, r.range_samples_1m, r.bearing_rms_rad,
                r.wrong_ids, r.ms_per_frame);
    std::printf("bridge checks: %llu blocks, %llu detections, unknown signature %llu, bad aspect %llu, outside image "
                "%llu, duplicate %llu\n",
                static_cast<unsigned long long>(r.checks.blocks), static_cast<unsigned long long>(r.checks.detections),
                static_cast<unsigned long long>(r.checks.unknown_signature),
                static_cast<unsigned long long>(r.checks.bad_aspect), static_cast<unsigned long long>(r.checks.outside_image),
                static_cast<unsigned long long>(r.checks.duplicate_landmark));
    std::printf("map through FastSLAM 2.0: %d landmarks, %d with a wrong id or away from their pole, pose ATE %.3f m\n",
                r.map_landmarks, r.map_wrong_ids, r.pose_ate_m);
    return 0;
  });
}
