#pragma once

#include <functional>
#include <string>
#include <vector>

#include "pixyslam/bridge/bridge_options.h"
#include "pixyslam/config/yaml_reader.h"
#include "pixyslam/dds/participant.h"
#include "pixyslam/pixy/pixy_options.h"

namespace pixyslam::pixy_node {

// Everything the pixy_bridge process is configured with (config/pixy_bridge.yaml).
struct PixyNodeOptions {
  // `node:` -- the serial link and the process. The link: the Pi's GPIO UART
  // wired to the Pixy's UART, at the Pixy's default rate (PixyMon: Interface >
  // UART baudrate).
  bridge::BridgeProcessOptions process{"/dev/serial0", 19200};
  double camera_latency_s = 0.0;   // subtracted from the host time a frame was read (exposure to UART)
  double frame_timeout_s = 0.01;   // an open frame without new data this long is complete (docs/benchmarks.md)
  pixy::PixyOptions pixy;  // `pixy:` camera model and signature -> landmark map
  dds::DdsOptions dds;     // `dds:`
};

// Reads an optional `camera:` section (the OpenCV camera backend, which this
// library does not depend on), given the options read so far.
using CameraSectionReader = std::function<void(config::YamlReader& camera, const PixyNodeOptions& so_far)>;

// Reads `pixy:` (required), `node:`, `dds:` and `camera:` (optional) from the
// top level of a file and calls root.finish(). `config_dir` resolves a relative
// dds.profiles_file. A `camera:` section without `read_camera` is an error
// (a build without the camera backend). Throws config::ConfigError naming the
// file and key path.
PixyNodeOptions read_pixy_node_options(config::YamlReader& root, const std::string& config_dir,
                                       const CameraSectionReader& read_camera = {});
PixyNodeOptions read_pixy_node_options_file(const std::string& path, const CameraSectionReader& read_camera = {});

// The `node:` keys (serial link, frame timing, reopen_period_s, status_period_s)
// and their rules (a supported baud rate).
const parameters::Table<PixyNodeOptions>& node_parameters();
void validate_node(const PixyNodeOptions& options);

// `--set pixy.KEY=V` and `node.KEY=V` applied and checked, taken out of
// `assignments` (the dds. ones stay for dds::resolve_settings).
void apply_overrides(PixyNodeOptions& options, std::vector<std::string>& assignments);

// Every parameter --set reaches, for --help.
std::string help_text();

// The effective configuration, in the layout read_pixy_node_options() reads.
std::string to_yaml(const PixyNodeOptions& options);

}  // namespace pixyslam::pixy_node
