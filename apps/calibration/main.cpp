// pixyslam_calibrate: camera and odometry calibration from measurements, as
// YAML the bridges read (docs/calibration.md).
//   pixyslam_calibrate camera --samples POLES.csv --config config/pixy_bridge.yaml [--out FILE]
//   pixyslam_calibrate camera --images PHOTOS.csv --config config/pixy_bridge.yaml [--out FILE]
//   pixyslam_calibrate odometry --straight REC=METRES[,REC=METRES...] --turn REC=DEGREES[,...]
//                               --config config/encoder_bridge.yaml [--out FILE]
// POLES.csv: distance_m,height_px[,x_px,bearing_rad] per pole seen at a known
// place. PHOTOS.csv: image,distance_m[,bearing_rad] per photo of a pole at a
// known place (camera backend builds): the colour-code detector measures the
// block, with the config's `camera:` settings or the defaults. REC: the Arduino's serial output captured during one straight run
// (METRES driven, measured) or one turn in place (DEGREES turned, > 0
// counter-clockwise). --out: the config with the fitted keys replaced
// (comments kept), checked by the bridge's own option reader.
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "pixyslam/app/command_line.h"
#include "pixyslam/app/process_main.h"
#include "pixyslam/calibration/calibration.h"
#include "pixyslam/config/yaml_reader.h"
#include "pixyslam/config/yaml_text.h"
#include "pixyslam/encoder/encoder_options.h"
#include "pixyslam/pixy/pixy_options.h"
#ifdef PIXYSLAM_HAS_CAMERA
#include "pixyslam/calibration/pole_images.h"
#include "pixyslam/camera/camera_byte_source.h"
#endif

namespace {

using namespace pixyslam;

constexpr const char* kUsage =
    "usage: pixyslam_calibrate camera (--samples POLES.csv | --images PHOTOS.csv) --config PIXY_BRIDGE.yaml\n"
    "                                 [--out FILE]\n"
    "       pixyslam_calibrate odometry --straight REC=METRES[,...] --turn REC=DEGREES[,...]\n"
    "                                   --config ENCODER_BRIDGE.yaml [--out FILE]\n";

std::string read_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw config::ConfigError(path + ": cannot open");
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

void write_file(const std::string& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary);
  out << text;
  if (!out.flush()) throw std::runtime_error("cannot write '" + path + "'");
}

// "--straight a.txt=1.5,b.txt=2": recordings with their measured truth.
std::vector<calibration::OdometryRun> read_runs(const std::string& flag, const std::string& list, double scale) {
  std::vector<calibration::OdometryRun> runs;
  for (const std::string& item : config::split_comma_list(list)) {
    const std::size_t eq = item.rfind('=');
    std::size_t used = 0;
    double truth = 0.0;
    if (eq != std::string::npos) {
      try {
        truth = std::stod(item.substr(eq + 1), &used);
      } catch (const std::exception&) {
        used = 0;
      }
    }
    if (eq == std::string::npos || eq == 0 || used == 0 || used != item.size() - eq - 1 || !std::isfinite(truth) ||
        truth == 0.0) {
      throw std::invalid_argument("--" + flag + " '" + item + "': want RECORDING=NUMBER (non-zero)");
    }
    const std::string path = item.substr(0, eq);
    runs.push_back({calibration::net_ticks(read_file(path), path), truth * scale, path});
  }
  return runs;
}

// The pole samples of --samples, or measured in the photos of --images.
std::vector<calibration::PoleSample> camera_samples(const app::CommandLine& args, config::YamlReader& root,
                                                    const pixy::PixyOptions& pixy, std::string& source) {
  if (args.has("samples") == args.has("images")) throw std::invalid_argument("give one of --samples and --images");
  if (args.has("samples")) {
    source = args.get("samples");
    return calibration::parse_pole_samples(read_file(source), source);
  }
  source = args.get("images");
#ifdef PIXYSLAM_HAS_CAMERA
  camera::DetectorOptions detector = camera::default_detector_options();
  if (root.has("camera")) {
    config::YamlReader section = root.child("camera");
    detector = camera::read_camera_source_options(section, pixy.camera.image_width_px, pixy.camera.image_height_px)
                   .detector;
  }
  const auto images = calibration::parse_pole_images(read_file(source), source, app::folder_of(source));
  return calibration::pole_samples_from_images(images, detector, pixy.camera, source);
#else
  (void)root;
  (void)pixy;
  throw std::invalid_argument("--images: this pixyslam_calibrate was built without the camera backend");
#endif
}

int calibrate_camera(const app::CommandLine& args) {
  const std::string config_path = args.get("config");
  const std::string config_text = config::read_config_text(config_path);  // regular file, size-capped
  config::YamlReader root = config::YamlReader::from_string(config_text, config_path);
  config::YamlReader pixy_yaml = root.child("pixy");
  const pixy::PixyOptions pixy = pixy::read_pixy_options(pixy_yaml);
  std::string samples_path;
  const std::vector<calibration::PoleSample> samples = camera_samples(args, root, pixy, samples_path);
  const calibration::CameraFit fit = calibration::fit_camera(samples, pixy.camera);
  std::printf("camera calibration: %zu poles from %s (pole height %.3f m, S_h %.3f mm, I_h %d px)\n",
              samples.size(), samples_path.c_str(), pixy.camera.landmark_height_m, pixy.camera.sensor_height_mm,
              pixy.camera.image_height_px);
  std::printf("  %-6s %10s %10s %12s %12s %14s\n", "line", "distance_m", "height_px", "residual_px", "range_error",
              "bearing_res_rad");
  for (std::size_t i = 0; i < samples.size(); ++i) {
    std::printf("  %-6d %10.3f %10.1f %12.2f %11.2f%% %14.4f\n", samples[i].line, samples[i].distance_m,
                samples[i].height_px, fit.height_residual_px[i], 100.0 * fit.range_error[i],
                fit.bearing_residual_rad[i]);
  }
  std::printf("  focal_length_mm %.4f (was %.4f); RMS %.2f px, range RMS %.2f %%\n", fit.focal_length_mm,
              pixy.camera.focal_length_mm, fit.rms_height_px, 100.0 * fit.rms_range_error);
  std::string out = calibration::replace_yaml_value(config_text, "pixy", "focal_length_mm",
                                                    config::yaml_number(std::round(fit.focal_length_mm * 1e4) / 1e4));
  if (fit.has_sensor_width) {
    std::printf("  sensor_width_mm %.4f (was %.4f); bearing RMS %.4f rad\n", fit.sensor_width_mm,
                pixy.camera.sensor_width_mm, fit.rms_bearing_rad);
    out = calibration::replace_yaml_value(out, "pixy", "sensor_width_mm",
                                          config::yaml_number(std::round(fit.sensor_width_mm * 1e4) / 1e4));
  } else {
    std::printf("  sensor_width_mm not fitted: fewer than two samples with x_px,bearing_rad off the axis\n");
  }
  if (args.has("out")) {
    write_file(args.get("out"), out);
    config::YamlReader check_root = config::YamlReader::from_string(out, args.get("out"));
    config::YamlReader check = check_root.child("pixy");
    pixy::read_pixy_options(check);
    std::printf("wrote %s\n", args.get("out").c_str());
  }
  return 0;
}

int odometry(const app::CommandLine& args) {
  const std::string config_path = args.get("config");
  const encoder::EncoderOptions options = encoder::read_encoder_options_file(config_path);
  const auto straights = read_runs("straight", args.get("straight"), 1.0);
  const auto turns = read_runs("turn", args.get("turn"), M_PI / 180.0);
  const calibration::OdometryFit fit = calibration::fit_odometry(straights, turns, options.ticks_per_revolution,
                                                                 options.left_sign, options.right_sign);
  std::printf("odometry calibration: %zu straight run(s), %zu turn(s), %d ticks per revolution\n", straights.size(),
              turns.size(), options.ticks_per_revolution);
  for (std::size_t i = 0; i < straights.size(); ++i) {
    const auto& r = straights[i];
    std::printf("  straight %-24s %8.3f m: ticks L %lld R %lld (%zu samples, %zu lines rejected); fit error "
                "%+.4f m, rotation seen %+.2f deg\n",
                r.name.c_str(), r.truth, static_cast<long long>(r.ticks.left), static_cast<long long>(r.ticks.right),
                r.ticks.samples, r.ticks.rejected_lines, fit.straight_error_m[i],
                fit.straight_rotation_rad[i] * 180.0 / M_PI);
  }
  for (std::size_t i = 0; i < turns.size(); ++i) {
    const auto& r = turns[i];
    std::printf("  turn     %-24s %8.1f deg: ticks L %lld R %lld (%zu samples, %zu lines rejected); fit error "
                "%+.2f deg\n",
                r.name.c_str(), r.truth * 180.0 / M_PI, static_cast<long long>(r.ticks.left),
                static_cast<long long>(r.ticks.right), r.ticks.samples, r.ticks.rejected_lines,
                fit.turn_error_rad[i] * 180.0 / M_PI);
  }
  std::printf("  wheel_radius_m %.5f (was %.5f), wheel_base_m %.4f (was %.4f)\n", fit.wheel_radius_m,
              options.wheel_radius_m, fit.wheel_base_m, options.wheel_base_m);
  if (args.has("out")) {
    std::string out =
        calibration::replace_yaml_value(config::read_config_text(config_path), "encoder_bridge", "wheel_radius_m",
                                        config::yaml_number(std::round(fit.wheel_radius_m * 1e6) / 1e6));
    out = calibration::replace_yaml_value(out, "encoder_bridge", "wheel_base_m",
                                          config::yaml_number(std::round(fit.wheel_base_m * 1e5) / 1e5));
    write_file(args.get("out"), out);
    encoder::read_encoder_options_file(args.get("out"));
    std::printf("wrote %s\n", args.get("out").c_str());
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  const std::vector<std::string> all(argv + 1, argv + argc);
  if (const auto status = app::usage_exit(all, kUsage)) return *status;
  const std::string command = all[0];
  if (command != "camera" && command != "odometry") {
    std::fprintf(stderr, "pixyslam_calibrate: unknown command '%s'\n%s", command.c_str(), kUsage);
    return 2;
  }
  return app::run_main("pixyslam_calibrate", [&] {
    const app::CommandLine args(argc - 1, argv + 1, command == "camera" ? std::set<std::string>{"samples", "images", "config", "out"}
                                                                        : std::set<std::string>{"straight", "turn", "config", "out"});
    return command == "camera" ? calibrate_camera(args) : odometry(args);
  });
}
