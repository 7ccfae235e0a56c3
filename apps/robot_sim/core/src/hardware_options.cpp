#include "pixyslam/robot_sim/hardware_options.h"

#include <cstdint>
#include <limits>
#include <sstream>
#include <stdexcept>

#include "pixyslam/config/yaml_text.h"

namespace pixyslam::robot_sim {
namespace {

// Ranges shared by validate() and the YAML reader.
constexpr double kMinArduinoHz = 1.0, kMaxArduinoHz = 1000.0;
constexpr double kMinPixyHz = 0.1, kMaxPixyHz = 100.0;
constexpr double kMaxVSigma = 10.0, kMaxWSigma = 10.0;
constexpr double kMinRefHz = 0.1, kMaxRefHz = 1000.0;
constexpr double kMaxRangeSigma = 10.0, kMaxBearingSigma = 1.0;
constexpr double kMinPoleWidth = 0.001, kMaxPoleWidth = 10.0;
constexpr double kMaxMinRange = 100.0;
constexpr double kMinMaxRange = 0.01, kMaxMaxRange = 1000.0;
constexpr std::int64_t kMaxBlockArea = 1000000;
constexpr std::int64_t kMaxAngle = 180;
constexpr double kMinStep = 1e-5, kMaxStep = 0.1;
constexpr std::size_t kMaxVersionChars = 16;

void check_range(const char* name, double v, double lo, double hi) {
  if (!(v >= lo && v <= hi)) {
    std::ostringstream os;
    os << "hardware option " << name << " = " << v << " is out of range [" << lo << ", " << hi << "]";
    throw std::invalid_argument(os.str());
  }
}

// The RST line's version grammar: 1 to 16 of [0-9A-Za-z._-].
bool valid_version(const std::string& v) {
  if (v.empty() || v.size() > kMaxVersionChars) return false;
  for (const char c : v) {
    const bool ok = (c >= '0' && c <= '9') || (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') || c == '.' ||
                    c == '_' || c == '-';
    if (!ok) return false;
  }
  return true;
}

}  // namespace

void validate(const HardwareOptions& o) {
  check_range("arduino_rate_hz", o.arduino_rate_hz, kMinArduinoHz, kMaxArduinoHz);
  if (!valid_version(o.firmware_version)) {
    throw std::invalid_argument("hardware option firmware_version '" + o.firmware_version +
                                "' is not 1 to 16 of [0-9A-Za-z._-]");
  }
  check_range("v_sigma_mps", o.v_sigma_mps, 0.0, kMaxVSigma);
  check_range("w_sigma_radps", o.w_sigma_radps, 0.0, kMaxWSigma);
  check_range("noise_reference_rate_hz", o.noise_reference_rate_hz, kMinRefHz, kMaxRefHz);
  check_range("pixy_rate_hz", o.pixy_rate_hz, kMinPixyHz, kMaxPixyHz);
  check_range("range_sigma_m", o.range_sigma_m, 0.0, kMaxRangeSigma);
  check_range("bearing_sigma_rad", o.bearing_sigma_rad, 0.0, kMaxBearingSigma);
  check_range("pole_width_m", o.pole_width_m, kMinPoleWidth, kMaxPoleWidth);
  check_range("min_range_m", o.min_range_m, 0.0, kMaxMinRange);
  check_range("max_range_m", o.max_range_m, kMinMaxRange, kMaxMaxRange);
  if (!(o.max_range_m > o.min_range_m)) {
    throw std::invalid_argument("hardware option max_range_m must be greater than min_range_m");
  }
  check_range("min_block_area_px", o.min_block_area_px, 0, static_cast<double>(kMaxBlockArea));
  check_range("colour_code_angle_deg", o.colour_code_angle_deg, -kMaxAngle, kMaxAngle);
  check_range("physics_step_s", o.physics_step_s, kMinStep, kMaxStep);
}

HardwareOptions read_hardware_options(config::YamlReader& r) {
  HardwareOptions o;
  o.seed = static_cast<std::uint64_t>(
      r.integer("seed", 0, std::numeric_limits<std::int64_t>::max(), static_cast<std::int64_t>(o.seed)));
  o.arduino_rate_hz = r.number("arduino_rate_hz", kMinArduinoHz, kMaxArduinoHz, o.arduino_rate_hz);
  o.arduino_start_time_us = static_cast<std::uint32_t>(
      r.integer("arduino_start_time_us", 0, std::numeric_limits<std::uint32_t>::max(), o.arduino_start_time_us));
  o.start_ticks = static_cast<std::int32_t>(r.integer("start_ticks", std::numeric_limits<std::int32_t>::min(),
                                                      std::numeric_limits<std::int32_t>::max(), o.start_ticks));
  o.firmware_version = r.text("firmware_version", o.firmware_version);
  if (!valid_version(o.firmware_version)) {
    r.fail("firmware_version", "value '" + o.firmware_version + "' is not 1 to 16 of [0-9A-Za-z._-]");
  }
  o.v_sigma_mps = r.number("v_sigma_mps", 0.0, kMaxVSigma, o.v_sigma_mps);
  o.w_sigma_radps = r.number("w_sigma_radps", 0.0, kMaxWSigma, o.w_sigma_radps);
  o.noise_reference_rate_hz = r.number("noise_reference_rate_hz", kMinRefHz, kMaxRefHz, o.noise_reference_rate_hz);
  o.pixy_rate_hz = r.number("pixy_rate_hz", kMinPixyHz, kMaxPixyHz, o.pixy_rate_hz);
  o.range_sigma_m = r.number("range_sigma_m", 0.0, kMaxRangeSigma, o.range_sigma_m);
  o.bearing_sigma_rad = r.number("bearing_sigma_rad", 0.0, kMaxBearingSigma, o.bearing_sigma_rad);
  o.pole_width_m = r.number("pole_width_m", kMinPoleWidth, kMaxPoleWidth, o.pole_width_m);
  o.min_range_m = r.number("min_range_m", 0.0, kMaxMinRange, o.min_range_m);
  o.max_range_m = r.number("max_range_m", kMinMaxRange, kMaxMaxRange, o.max_range_m);
  if (!(o.max_range_m > o.min_range_m)) r.fail("max_range_m", "must be greater than min_range_m");
  o.min_block_area_px = static_cast<int>(r.integer("min_block_area_px", 0, kMaxBlockArea, o.min_block_area_px));
  o.colour_code_angle_deg =
      static_cast<int>(r.integer("colour_code_angle_deg", -kMaxAngle, kMaxAngle, o.colour_code_angle_deg));
  o.send_empty_frames = r.boolean("send_empty_frames", o.send_empty_frames);
  o.physics_step_s = r.number("physics_step_s", kMinStep, kMaxStep, o.physics_step_s);
  r.finish();
  r.check_mapping([&] { validate(o); });
  return o;
}

std::string to_yaml(const HardwareOptions& o) {
  using config::yaml_number;
  std::ostringstream os;
  os << "hardware:\n"
     << "  seed: " << o.seed << "\n"
     << "  arduino_rate_hz: " << yaml_number(o.arduino_rate_hz) << "\n"
     << "  arduino_start_time_us: " << o.arduino_start_time_us << "\n"
     << "  start_ticks: " << o.start_ticks << "\n"
     << "  firmware_version: \"" << o.firmware_version << "\"\n"
     << "  v_sigma_mps: " << yaml_number(o.v_sigma_mps) << "\n"
     << "  w_sigma_radps: " << yaml_number(o.w_sigma_radps) << "\n"
     << "  noise_reference_rate_hz: " << yaml_number(o.noise_reference_rate_hz) << "\n"
     << "  pixy_rate_hz: " << yaml_number(o.pixy_rate_hz) << "\n"
     << "  range_sigma_m: " << yaml_number(o.range_sigma_m) << "\n"
     << "  bearing_sigma_rad: " << yaml_number(o.bearing_sigma_rad) << "\n"
     << "  pole_width_m: " << yaml_number(o.pole_width_m) << "\n"
     << "  min_range_m: " << yaml_number(o.min_range_m) << "\n"
     << "  max_range_m: " << yaml_number(o.max_range_m) << "\n"
     << "  min_block_area_px: " << o.min_block_area_px << "\n"
     << "  colour_code_angle_deg: " << o.colour_code_angle_deg << "\n"
     << "  send_empty_frames: " << (o.send_empty_frames ? "true" : "false") << "\n"
     << "  physics_step_s: " << yaml_number(o.physics_step_s) << "\n";
  return os.str();
}

}  // namespace pixyslam::robot_sim
