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
//   pixyslam_calibrate noise --dataset DIR --robot N --config BASE.yaml --out FILE.yaml [--ground-truth]
//                            [--fit-range-scale] [--keys LIST]
// noise: the odometry noise densities, range and bearing sigmas, range scale,
// the range's cos-bearing exponent and command lag of a robot from the filter's own innovations over a recording
// (repeated filter passes, never the ground truth); BASE with those keys
// replaced. --ground-truth also fits them against the ground truth and prints
// both with their relative difference.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "pixyslam/app/cli.h"
#include "pixyslam/app/process_main.h"
#include "pixyslam/mrclam/mrclam_dataset.h"
#include "pixyslam/offline/offline_run.h"
#include "pixyslam/calibration/calibration.h"
#include "pixyslam/calibration/noise_calibration.h"
#include "pixyslam/config/yaml_reader.h"
#include "pixyslam/config/yaml_text.h"
#include "pixyslam/parameters/parameters.h"
#include "pixyslam/encoder/encoder_options.h"
#include "pixyslam/pixy/pixy_options.h"
#include "pixyslam/slam/slam_options_yaml.h"
#ifdef PIXYSLAM_HAS_CAMERA
#include "pixyslam/calibration/pole_images.h"
#include "pixyslam/camera/camera_byte_source.h"
#endif

namespace {

using namespace pixyslam;

// The flags a command was given, by name without dashes (filled by the
// command line; only given flags are present).
struct Flags {
  std::map<std::string, std::string> values;
  bool has(const std::string& name) const { return values.count(name) != 0; }
  const std::string& get(const std::string& name) const {
    const auto it = values.find(name);
    if (it == values.end()) throw app::UsageError("--" + name + " is required");
    return it->second;
  }
};

// A measurement file (not a config): unreadable exits 1 naming the OS reason.
std::string read_file(const std::string& path) {
  app::check_input_file(path);
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error(path + ": cannot open");
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
  for (const std::string& item : parameters::split_list(list)) {
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
      throw app::UsageError("--" + flag + " '" + item + "': want RECORDING=NUMBER (non-zero)");
    }
    const std::string path = item.substr(0, eq);
    runs.push_back({calibration::net_ticks(read_file(path), path), truth * scale, path});
  }
  return runs;
}

// The pole samples of --samples, or measured in the photos of --images.
std::vector<calibration::PoleSample> camera_samples(const Flags& args, config::YamlReader& root,
                                                    const pixy::PixyOptions& pixy, std::string& source) {
  if (args.has("samples") == args.has("images")) throw app::UsageError("give one of --samples and --images");
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
  const auto images = calibration::parse_pole_images(read_file(source), source, config::folder_of(source));
  return calibration::pole_samples_from_images(images, detector, pixy.camera, source);
#else
  (void)root;
  (void)pixy;
  throw app::UsageError("--images: this pixyslam_calibrate was built without the camera backend");
#endif
}

int calibrate_camera(const Flags& args) {
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

int odometry(const Flags& args) {
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

// Rounded to 4 significant digits for the config file.
std::string rounded(double value) {
  if (value == 0.0 || !std::isfinite(value)) return config::yaml_number(value);
  const double digits = std::pow(10.0, 3 - std::floor(std::log10(std::abs(value))));
  return config::yaml_number(std::round(value * digits) / digits);
}

void print_parameters(const char* title, const calibration::NoiseParameters& p) {
  std::printf("%s: v_sigma %.5f m/sqrt(s), w_sigma %.5f rad/sqrt(s), range_sigma %.4f m, bearing_sigma %.4f rad, "
              "range_scale %.4f, range_cos_bearing_exponent %.3f, odometry_delay %.3f s, error_correlation %.2f s\n",
              title, p.v_sigma_m_per_sqrt_s, p.w_sigma_rad_per_sqrt_s, p.range_sigma_m, p.bearing_sigma_rad,
              p.range_scale, p.range_cos_bearing_exponent, p.odometry_delay_s, p.error_correlation_s);
}

int noise(const Flags& args, int robot, bool with_ground_truth, bool fit_range_scale) {
  const std::string config_path = args.get("config");
  // --keys: which of the values to write (default all but the range scale,
  // which --fit-range-scale adds). The error correlation is fitted, and used by
  // the calibration's own filter passes, only when it is written.
  std::set<std::string> keys{"v_sigma",        "w_sigma",        "range_sigma",      "bearing_sigma",
                             "range_exponent", "odometry_delay", "error_correlation"};
  if (fit_range_scale) keys.insert("range_scale");
  if (args.has("keys")) {
    keys.clear();
    for (const std::string& key : parameters::split_list(args.get("keys"))) {
      if (key != "v_sigma" && key != "w_sigma" && key != "range_sigma" && key != "bearing_sigma" &&
          key != "range_scale" && key != "range_exponent" && key != "odometry_delay" && key != "error_correlation") {
        throw app::UsageError("--keys: unknown value '" + key +
                                    "' (v_sigma, w_sigma, range_sigma, bearing_sigma, range_scale, range_exponent, "
                                    "odometry_delay, error_correlation)");
      }
      keys.insert(key);
    }
  }
  const std::string base_text = config::read_config_text(config_path);
  config::YamlReader root = config::YamlReader::from_string(base_text, config_path);
  config::YamlReader filter_yaml = root.child("filter");
  const slam::FilterOptions base = slam::read_filter_options(filter_yaml);
  offline::MrclamSensorModel model = offline::read_mrclam_sensor_model(root);
  calibration::NoiseParameters start;
  start.v_sigma_m_per_sqrt_s = base.motion.v_sigma_m_per_sqrt_s;
  start.w_sigma_rad_per_sqrt_s = base.motion.w_sigma_rad_per_sqrt_s;
  start.range_sigma_m = base.range_sigma_m;
  start.bearing_sigma_rad = base.bearing_sigma_rad;
  start.range_scale = model.range_scale;
  start.range_cos_bearing_exponent = model.range_cos_bearing_exponent;
  start.odometry_delay_s = model.odometry_delay_s;
  start.error_correlation_s = base.error_correlation_s;
  // The calibration applies its own range model and delay to the raw input.
  model.range_scale = 1.0;
  model.range_cos_bearing_exponent = 0.0;
  model.odometry_delay_s = 0.0;

  const mrclam::RobotData data = mrclam::load_robot(args.get("dataset"), robot);
  mrclam::RobotData blind_data = data;
  blind_data.groundtruth.clear();  // a new robot has none: start at the origin
  blind_data.landmarks.clear();
  const offline::RunInput blind = offline::mrclam_input(blind_data, model);
  std::printf("robot %d: %zu odometry samples, %zu frames; %d particles\n", data.robot, blind.odometry.size(),
              blind.frames.size(), base.particles);
  print_parameters("start", start);
  int pass = 0;
  calibration::NoiseCalibrationOptions noise_options;
  // Blind, the range scale comes from landmark pairs against the odometry; the
  // MRCLAM robots' odometry (commanded speeds, slower while turning) makes it
  // wrong there (docs/calibration.md): only on request.
  noise_options.fit_range_scale = fit_range_scale;
  noise_options.fit_error_correlation = keys.count("error_correlation") > 0;
  const calibration::NoiseCalibration result = calibration::calibrate_noise(
      blind, base, start, noise_options, [&](const calibration::NoiseIteration& it) {
        char title[192];
        std::snprintf(title, sizeof title,
                      "pass %d (%zu innovations, %zu outliers, mean NIS %.2f, log-lik %.3f; %zu pairs: sigmas %.4f m, %.4f rad)",
                      ++pass, it.statistics.innovations, it.statistics.outliers, it.statistics.mean_nis,
                      it.statistics.mean_log_likelihood, it.statistics.correlation_pairs,
                      it.statistics.pair_range_sigma_m, it.statistics.pair_bearing_sigma_rad);
        print_parameters(title, it.parameters);
      });
  const calibration::NoiseParameters& p = result.parameters;
  char title[128];
  std::snprintf(title, sizeof title, "calibrated (mean of passes %zu-%zu, pass %zu of %zu the most likely; %s)",
                std::min<std::size_t>(3, result.best_iteration + 1), result.best_iteration + 1,
                result.best_iteration + 1, result.iterations.size(), result.converged ? "settled" : "not settled");
  print_parameters(title, p);
  if (!result.iterations.empty()) {
    std::printf("mean range innovation %.4f m (a range bias; not written)\n",
                result.iterations.back().statistics.range_bias_m);
  }

  if (with_ground_truth) {
    const offline::RunInput with_truth = offline::mrclam_input(data, model);
    calibration::NoiseCalibrationOptions truth_options;
    truth_options.fit_error_correlation = noise_options.fit_error_correlation;
    const calibration::NoiseCalibration fit = calibration::calibrate_noise_with_truth(with_truth, start, truth_options);
    print_parameters("fit with ground truth", fit.parameters);
    const calibration::NoiseParameters& g = fit.parameters;
    const auto row = [](const char* name, double blind_value, double truth_value) {
      std::printf("  %-24s %10.5f %10.5f %+8.1f %%\n", name, blind_value, truth_value,
                  truth_value != 0.0 ? 100.0 * (blind_value - truth_value) / std::abs(truth_value) : 0.0);
    };
    std::printf("  %-24s %10s %10s %9s\n", "value", "blind", "truth", "relative");
    row("v_sigma_m_per_sqrt_s", p.v_sigma_m_per_sqrt_s, g.v_sigma_m_per_sqrt_s);
    row("w_sigma_rad_per_sqrt_s", p.w_sigma_rad_per_sqrt_s, g.w_sigma_rad_per_sqrt_s);
    row("range_sigma_m", p.range_sigma_m, g.range_sigma_m);
    row("bearing_sigma_rad", p.bearing_sigma_rad, g.bearing_sigma_rad);
    row("range_scale", p.range_scale, g.range_scale);
    row("range_cos_bearing_exponent", p.range_cos_bearing_exponent, g.range_cos_bearing_exponent);
    row("odometry_delay_s", p.odometry_delay_s, g.odometry_delay_s);
    row("error_correlation_s", p.error_correlation_s, g.error_correlation_s);
  }

  std::string out = base_text;
  const auto replace = [&](const char* key, const char* section, const char* yaml_key, const std::string& value) {
    if (!keys.count(key)) return;
    try {
      out = calibration::replace_yaml_value(out, section, yaml_key, value);
    } catch (const std::invalid_argument&) {
      if (args.has("keys")) throw;  // asked for by name: the base must have the line
      // Written by default: older bases lack the line.
      std::printf("note: %s has no '%s:' line under %s:, so %s %s is not written\n", config_path.c_str(), yaml_key,
                  section, yaml_key, value.c_str());
    }
  };
  replace("v_sigma", "filter", "v_sigma_m_per_sqrt_s", rounded(p.v_sigma_m_per_sqrt_s));
  replace("w_sigma", "filter", "w_sigma_rad_per_sqrt_s", rounded(p.w_sigma_rad_per_sqrt_s));
  replace("range_sigma", "filter", "range_sigma_m", rounded(p.range_sigma_m));
  replace("bearing_sigma", "filter", "bearing_sigma_rad", rounded(p.bearing_sigma_rad));
  replace("range_scale", "mrclam", "range_scale", rounded(p.range_scale));
  replace("range_exponent", "mrclam", "range_cos_bearing_exponent",
          config::yaml_number(std::round(p.range_cos_bearing_exponent * 1000.0) / 1000.0));
  replace("odometry_delay", "mrclam", "odometry_delay_s",
          config::yaml_number(std::round(p.odometry_delay_s * 1000.0) / 1000.0));
  replace("error_correlation", "filter", "error_correlation_s",
          config::yaml_number(std::round(p.error_correlation_s * 100.0) / 100.0));
  // Read back with the programs' own readers before writing.
  config::YamlReader check = config::YamlReader::from_string(out, args.get("out"));
  config::YamlReader check_filter = check.child("filter");
  slam::read_filter_options(check_filter);
  offline::read_mrclam_sensor_model(check);
  write_file(args.get("out"), out);
  std::printf("wrote %s\n", args.get("out").c_str());
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  app::Cli cli{"pixyslam_calibrate",
               "Camera, odometry and noise calibration from measurements, written as the YAML the bridges and the "
               "filter read (docs/calibration.md)."};
  Flags flags;
  // --NAME VALUE into flags.values["NAME"] when given.
  const auto value = [&](app::Cli& command, const std::string& name, const std::string& help, const char* type) {
    return &command
                .option_call(
                    "--" + name, [&flags, name](const std::string& v) { flags.values[name] = v; }, help)
                .type(type);
  };
  app::Cli& camera = cli.subcommand("camera", "the focal length from poles seen at known places");
  value(camera, "samples", "distance_m,height_px[,x_px,bearing_rad] per pole seen at a known place", "POLES.csv");
  value(camera, "images", "image,distance_m[,bearing_rad] per photo of a pole (camera backend builds)", "PHOTOS.csv");
  value(camera, "config", "the pixy bridge's YAML", "PIXY_BRIDGE.yaml")->required();
  value(camera, "out", "write the config with the fitted keys replaced (comments kept)", "FILE");

  app::Cli& odometry_command = cli.subcommand("odometry", "wheel radius and base from straight runs and turns");
  value(odometry_command, "straight", "REC=METRES,...: Arduino captures of straight runs and the distance driven",
        "LIST")
      ->required();
  value(odometry_command, "turn", "REC=DEGREES,...: captures of turns in place (> 0 counter-clockwise)", "LIST")
      ->required();
  value(odometry_command, "config", "the encoder bridge's YAML", "ENCODER_BRIDGE.yaml")->required();
  value(odometry_command, "out", "write the config with the fitted keys replaced (comments kept)", "FILE");

  bool with_ground_truth = false, fit_range_scale = false;
  int robot = 0;
  app::Cli& noise_command = cli.subcommand(
      "noise",
      "odometry noise densities, range and bearing sigmas, the range's cos-bearing exponent and command lag from "
      "the filter's own innovations (never the ground truth); the errors' correlation time from pairs of sightings");
  // --mrclam: the old name of --dataset, still accepted.
  noise_command
      .option_call(
          "--dataset,--mrclam", [&flags](const std::string& v) { flags.values["dataset"] = v; },
          "the MRCLAM data set folder of the recording (--mrclam: its old name, deprecated)")
      .type("DIR")
      .required();
  noise_command.option("--robot", robot, "the robot, 1-5").required().range(mrclam::kFirstRobot, mrclam::kLastRobot).type("N");
  value(noise_command, "config", "the base YAML (filter: and mrclam:)", "BASE.yaml")->required();
  value(noise_command, "out", "write BASE with the calibrated keys replaced", "FILE.yaml")->required();
  value(noise_command, "keys",
        "write only these of v_sigma, w_sigma, range_sigma, bearing_sigma, range_scale, range_exponent, "
        "odometry_delay, error_correlation",
        "LIST");
  noise_command.flag("--ground-truth", with_ground_truth,
                     "also fit against the ground truth and print both with their relative difference");
  noise_command.flag("--fit-range-scale", fit_range_scale, "also fit (and write) the range scale");
  if (const auto done = cli.parse(argc, argv)) return *done;
  return app::run_main("pixyslam_calibrate", [&] {
    // A folder that is not there fails now, not after a calibration of minutes.
    if (flags.has("out")) {
      const std::string folder = config::folder_of(flags.get("out"));
      if (!std::filesystem::is_directory(folder)) {
        throw app::UsageError("--out " + flags.get("out") + ": no folder '" + folder + "' to write it in");
      }
    }
    if (camera.chosen()) return calibrate_camera(flags);
    if (odometry_command.chosen()) return odometry(flags);
    return noise(flags, robot, with_ground_truth, fit_range_scale);
  });
}
