#pragma once

#include <string>

#include "pixyslam/config/yaml_reader.h"
#include "pixyslam/parameters/parameters.h"

namespace pixyslam::encoder {

// Options of the encoder bridge: the wheel geometry that turns ticks into
// metres, and the odometry output rate (the serial link is the process's,
// `node.serial_device` and `node.baud`: encoder_node_options.h). SI units
// as named. A sign of +1 means the wheel's counter increases when the wheel
// rolls forward, -1 that it decreases (mirror-mounted motors). A plain value;
// validate() checks it.
struct EncoderOptions {
  double wheel_radius_m = 0.0325;
  int ticks_per_revolution = 1320;   // counter steps per wheel turn (4 per quadrature cycle)
  double wheel_base_m = 0.135;       // distance between the wheels' contact points
  int left_sign = 1;
  int right_sign = 1;
  double publish_rate_hz = 10.0;     // (v, w) outputs per second (seed paper: 10)
  double max_wheel_speed_mps = 1.5;  // faster wheel travel between two samples is rejected
  double max_sample_gap_s = 0.5;     // longer Arduino intervals give no velocity
};

// One declaration per field: key, range, unit, help.
const parameters::Table<EncoderOptions>& encoder_parameters();

// Throws std::invalid_argument naming the first field out of its range.
void validate(const EncoderOptions& options);

// Reads the options from the keys of `reader` (the component's mapping, e.g.
// `encoder_bridge` of config/encoder_bridge.yaml) and calls reader.finish().
// publish_rate_hz, max_wheel_speed_mps and max_sample_gap_s may be left out (defaults above); the wheel geometry
// (wheel_radius_m, ticks_per_revolution, wheel_base_m, left_sign, right_sign)
// is required. Throws config::ConfigError naming the file and the key path.
EncoderOptions read_encoder_options(config::YamlReader& reader);

// Reads the `encoder_bridge` mapping of a file. The process's `node` and `dds`
// mappings may be there too (not read here: the encoder node reads the whole
// file); any other top-level key is an error.
EncoderOptions read_encoder_options_file(const std::string& path);

// The options as YAML text in the layout read_encoder_options() expects, under
// `encoder_bridge:` (for printing the effective configuration at start-up).
std::string to_yaml(const EncoderOptions& options);

}  // namespace pixyslam::encoder
