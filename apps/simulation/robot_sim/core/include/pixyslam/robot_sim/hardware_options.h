#pragma once

#include <cstdint>
#include <string>

#include "pixyslam/config/yaml_reader.h"
#include "pixyslam/parameters/parameters.h"

namespace pixyslam::robot_sim {

// How the emulated robot hardware behaves (HardwareEmulator): the Arduino
// encoder sketch, the wheels' odometry noise, the Pixy camera's frame rate,
// noise and limits. SI units as named, pixels as px. A plain value; validate()
// checks it.
//
// Odometry noise. The seed paper gives its odometry error per 10 Hz sample:
// 3 cm/s on v and 2 deg/s (0.0349 rad/s) on w. The emulator puts the noise on
// the wheels, as white noise on the two wheel speeds, sized so that the (v, w)
// the encoder bridge computes over one 1 / noise_reference_rate_hz period has
// exactly those sigmas. With a common mode n_v and a differential mode n_w,
//   left  = v - (b/2) w + n_v - (b/2) n_w,   right = v + (b/2) w + n_v + (b/2) n_w,
// (b = wheel base) the bridge's v = (left + right)/2 and w = (right - left)/b
// carry exactly n_v and n_w. Each wheel's speed noise then has
//   sd = sqrt(v_sigma^2 + (b/2)^2 w_sigma^2)   (30.1 mm/s for b = 0.135 m),
// and the two wheels are correlated,
//   rho = (v_sigma^2 - (b/2)^2 w_sigma^2) / (v_sigma^2 + (b/2)^2 w_sigma^2)   (0.988):
// independent wheels of equal noise could not give both numbers (3 cm/s on v
// would mean 25 deg/s on w). n_v and n_w are drawn once per Arduino interval
// dt_a = 1 / arduino_rate_hz with sd v_sigma * sqrt(arduino_rate_hz / noise_reference_rate_hz)
// (likewise w; 67 mm/s and 4.5 deg/s at 50 Hz): a white-noise density, so the mean over any 0.1 s has the
// paper's sd whatever the Arduino rate. Tick quantisation adds a little
// (about 0.4 deg/s on w at 10 Hz with the shipped wheels).
struct HardwareOptions {
  std::uint64_t seed = 1;  // wheel and camera noise (independent streams)

  // Arduino encoder sketch (docs/arduino_protocol.md). At t = 0 it sends one
  // RST line, then an ENC line every 1 / arduino_rate_hz s, seq from 0, micros()
  // starting at arduino_start_time_us and both counters at start_ticks (both
  // wrap modulo 2^32: an offset near 2^32 us or 2^31 ticks exercises the wraps).
  double arduino_rate_hz = 50.0;
  std::uint32_t arduino_start_time_us = 0;
  std::int32_t start_ticks = 0;
  std::string firmware_version = "sim-1";  // RST line: 1-16 of [0-9A-Za-z._-]

  // Odometry noise (see above): the sd of (v, w) means over 1 / noise_reference_rate_hz.
  double v_sigma_mps = 0.03;
  double w_sigma_radps = 0.0349;
  double noise_reference_rate_hz = 10.0;

  // Pixy camera. The real camera runs at 50 Hz; the seed paper processed 10 Hz.
  double pixy_rate_hz = 10.0;
  double range_sigma_m = 0.07;       // on the true range, before the pixel conversion (paper: 70 mm)
  double bearing_sigma_rad = 0.027;  // on the true bearing (paper: 0.027 rad)
  // The poles are CameraModel::landmark_height_m tall and this wide (the
  // paper's 80 x 40 mm poles: height/width 2.0, the lower aspect bound).
  double pole_width_m = 0.04;
  // The camera sees a pole whose TRUE range lies in [min_range_m, max_range_m].
  double min_range_m = 0.2;
  double max_range_m = 4.0;
  // Blocks with fewer pixels (width * height) are not reported (PixyMon's
  // "min block area" setting).
  int min_block_area_px = 20;
  // The angle word of colour-code blocks: 90 = an upright code whose first tag
  // is at the bottom (the poles stand upright and the camera does not roll).
  int colour_code_angle_deg = 90;
  // A frame with no block: false sends nothing, as the camera firmware does;
  // true sends a lone frame-start sync (encode_frame({})).
  bool send_empty_frames = false;

  // Physics integration step: the true pose and the wheel travel are
  // integrated as exact arcs over steps of at most this length (each split
  // where the path's command switches).
  double physics_step_s = 0.001;
};

// One declaration per key of `hardware:`: range, unit, default, help.
const parameters::Table<HardwareOptions>& hardware_parameters();

// Throws std::invalid_argument naming the first field out of its range.
void validate(const HardwareOptions& options);

// Reads the keys above from a `hardware:` mapping (every key optional, default
// as above) and calls reader.finish(). Throws config::ConfigError naming the
// file and key path for an unknown key, a wrong type or a value out of range.
HardwareOptions read_hardware_options(config::YamlReader& hardware);

// The options as YAML under `hardware:` (for printing the effective configuration).
std::string to_yaml(const HardwareOptions& options);

}  // namespace pixyslam::robot_sim
