// pixy_bridge: the Pixy's UART block stream (serial) -> one LandmarkObservation
// per camera frame over DDS, until SIGINT/SIGTERM. With a `camera:` section it
// reads a camera, video file or y4m stream instead and detects the colour codes
// itself (a software Pixy, components/pixy_bridge/camera; docs/camera.md).
//   pixy_bridge --config config/pixy_bridge.yaml [--device PATH] [--camera INPUT] [--set KEY=VALUE ...] [--domain N]
//               [--verbose]
// --device overrides node.serial_device (or camera.input), --camera selects the
// camera backend reading INPUT (with the `camera:` settings, or the defaults),
// --set pixy.KEY=V or dds.KEY=V a parameter. --verbose prints the effective
// configuration to stdout; logs go to stderr. Exit status: 0 after a clean stop, 2 for a configuration or
// command-line error, 1 for any other failure.
//
// Built twice: pixy_bridge without OpenCV, and pixy_bridge_camera with the camera
// backend. OpenCV's videoio pulls in some 240 shared libraries (57 MB more
// resident memory, and their loading at every start), which a robot with a Pixy
// does not need: pixy_bridge runs pixy_bridge_camera, from its own folder, in
// its place (same pid and arguments) for --camera, a camera: section, or --help
// (which lists the camera's keys).
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>

#include "pixyslam/app/cli.h"
#include "pixyslam/app/process_main.h"
#include "pixyslam/app/stop_signal.h"
#include "pixyslam/bridge/bridge_options.h"
#include "pixyslam/pixy_node/pixy_node.h"
#ifdef PIXYSLAM_HAS_CAMERA
#include "pixyslam/camera/camera_byte_source.h"
#endif

#ifdef PIXYSLAM_CAMERA_PROGRAM
namespace {

// Replaces this process by the camera program; returns only if that fails
// (with the reason on stderr).
void exec_camera_program(char** argv) {
  std::error_code error;
  const std::filesystem::path self = std::filesystem::read_symlink("/proc/self/exe", error);
  const std::string path = (self.parent_path() / PIXYSLAM_CAMERA_PROGRAM).string();
  ::execv(path.c_str(), argv);
  std::fprintf(stderr, "pixy_bridge: the camera backend is the program %s, which cannot be run: %s\n", path.c_str(),
               std::strerror(errno));
}

bool any_argument(int argc, char** argv, bool (*match)(std::string_view)) {
  for (int i = 1; i < argc; ++i) {
    if (match(argv[i])) return true;
  }
  return false;
}

bool is_help(std::string_view a) { return a == "-h" || a == "--help"; }
bool is_camera(std::string_view a) { return a == "--camera" || a.rfind("--camera=", 0) == 0; }

// A config that cannot be read is reported by the normal reading below.
bool has_camera_section(const std::string& config_path) {
  try {
    return pixyslam::config::YamlReader::from_file(config_path).has("camera");
  } catch (const std::exception&) {
    return false;
  }
}

}  // namespace
#endif

#ifdef PIXYSLAM_HAS_CAMERA
// pixy_bridge_camera, or pixy_bridge when that ran it in its place (same argv).
const char* program_name(const char* argv0) {
  const std::string_view invoked = argv0 == nullptr ? "" : argv0;
  const std::size_t slash = invoked.rfind('/');
  return invoked.substr(slash == std::string_view::npos ? 0 : slash + 1) == "pixy_bridge" ? "pixy_bridge"
                                                                                         : "pixy_bridge_camera";
}
#else
const char* program_name(const char*) { return "pixy_bridge"; }
#endif

int main(int argc, char** argv) {
  using namespace pixyslam;
  app::StopSignal::install();  // first: every thread inherits the blocked signals
  const char* const name = program_name(argv[0]);
#ifdef PIXYSLAM_CAMERA_PROGRAM
  const bool help = any_argument(argc, argv, is_help);
  if (help || any_argument(argc, argv, is_camera)) {
    exec_camera_program(argv);
    if (!help) return 2;  // --help goes on without it (and without the camera's keys)
  }
#endif
  bridge::BridgeCommandLine args;
  std::string camera_input;
  app::Cli cli{name, "The Pixy's UART block stream (or a camera) -> one LandmarkObservation per frame over DDS, until "
               "SIGINT/SIGTERM."};
  bridge::add_bridge_flags(cli, args, "config/pixy_bridge.yaml: node:, pixy:, camera: (optional), dds:",
                           "pixy.frame_rate_hz=30");
  cli.option("--camera", camera_input, "read this camera, video file or y4m stream instead of the Pixy")
      .type("INPUT");
#ifdef PIXYSLAM_HAS_CAMERA
  cli.footer(pixy_node::help_text() + "the camera backend (camera:; --camera or a camera: section):\n" +
             parameters::help_text(camera::camera_source_parameters(), "camera"));
#else
  cli.footer(pixy_node::help_text());
#endif
  if (const auto done = cli.parse(argc, argv)) return *done;
#ifdef PIXYSLAM_CAMERA_PROGRAM
  if (has_camera_section(args.config)) {
    exec_camera_program(argv);
    return 2;
  }
#endif

  pixy_node::PixyNodeOptions options;
  pixy_node::CameraSectionReader read_camera;
#ifdef PIXYSLAM_HAS_CAMERA
  std::optional<camera::CameraSourceOptions> camera_options;
  read_camera = [&](config::YamlReader& section, const pixy_node::PixyNodeOptions& so_far) {
    camera_options = camera::read_camera_source_options(section, so_far.pixy.camera.image_width_px,
                                                        so_far.pixy.camera.image_height_px);
  };
#endif
  const std::optional<int> bad = app::configure(name, [&] {
    options = pixy_node::read_pixy_node_options_file(args.config, read_camera);
    pixy_node::apply_overrides(options, args.overrides);
#ifdef PIXYSLAM_HAS_CAMERA
    if (!camera_input.empty() && !camera_options) {
      camera_options = camera::CameraSourceOptions{};
      camera_options->image_width_px = options.pixy.camera.image_width_px;
      camera_options->image_height_px = options.pixy.camera.image_height_px;
    }
    if (camera_options) {
      for (const std::string& a : parameters::take_section(args.overrides, "camera")) {
        parameters::apply_override(*camera_options, camera::camera_source_parameters(), "camera", a);
      }
      if (!camera_input.empty()) camera_options->input = camera_input;  // the flag after --set
      camera::validate(*camera_options);
      bridge::apply_command_line(args, camera_options->input, options.dds);
      return;
    }
#else
    if (!camera_input.empty()) {
      throw std::invalid_argument("--camera: this pixy_bridge was built without the camera backend");
    }
#endif
    if (!parameters::take_section(args.overrides, "camera").empty()) {
      throw std::invalid_argument("--set camera.KEY=V needs the camera backend: --camera INPUT or a camera: section");
    }
    bridge::apply_command_line(args, options.process.serial_device, options.dds);
  });
  if (bad) return *bad;
  std::string effective = pixy_node::to_yaml(options);
#ifdef PIXYSLAM_HAS_CAMERA
  if (camera_options) effective += camera::to_yaml(*camera_options);
#endif
  if (args.verbose) app::print_effective_configuration(name, effective);

  return app::run_main(name, [&] {
    std::unique_ptr<bridge::ByteSource> source;
#ifdef PIXYSLAM_HAS_CAMERA
    if (camera_options) source = std::make_unique<camera::CameraByteSource>(*camera_options, bridge::stderr_log(name));
#endif
    if (!source) source = std::make_unique<bridge::SerialByteSource>(options.process.serial_device, options.process.baud);
    pixy_node::PixyNode node(options, std::move(source), bridge::stderr_log(name));
    node.start();
    while (!app::StopSignal::wait_for(std::chrono::milliseconds(200))) {
    }
    node.stop();
    std::fprintf(stderr, "%s: stopped (signal %d)\n", name, app::StopSignal::signal_number());
    return 0;
  });
}
