#include "pixyslam/robot_sim/hardware_options.h"

#include <cstdint>
#include <limits>
#include <sstream>
#include <stdexcept>

#include "pixyslam/config/parameters_yaml.h"

namespace pixyslam::robot_sim {
namespace {

constexpr std::size_t kMaxVersionChars = 16;

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

const parameters::Table<HardwareOptions>& hardware_parameters() {
  using O = HardwareOptions;
  namespace P = parameters;
  static const P::Table<O> table = {
      P::integer<O, std::uint64_t>("seed", 0, P::kMaxSeed, "", "wheel and camera noise",
                                   [](O& o) -> std::uint64_t& { return o.seed; }),
      P::real<O>("arduino_rate_hz", 1.0, 1000.0, "Hz", "encoder lines per second",
                 [](O& o) -> double& { return o.arduino_rate_hz; }),
      P::integer<O, std::uint32_t>("arduino_start_time_us", 0, std::numeric_limits<std::uint32_t>::max(), "us",
                                   "the Arduino's micros() at power-on",
                                   [](O& o) -> std::uint32_t& { return o.arduino_start_time_us; }),
      P::integer<O, std::int32_t>("start_ticks", std::numeric_limits<std::int32_t>::min(),
                                  std::numeric_limits<std::int32_t>::max(), "", "the counters at power-on",
                                  [](O& o) -> std::int32_t& { return o.start_ticks; }),
      P::text<O>("firmware_version", "the RST line's version", [](O& o) -> std::string& { return o.firmware_version; },
                 [](const std::string& v) {
                   if (!valid_version(v)) throw std::invalid_argument("not 1 to 16 of [0-9A-Za-z._-]");
                 }),
      P::real<O>("v_sigma_mps", 0.0, 10.0, "m/s", "wheel speed noise at the reference rate",
                 [](O& o) -> double& { return o.v_sigma_mps; }),
      P::real<O>("w_sigma_radps", 0.0, 10.0, "rad/s", "turn rate noise at the reference rate",
                 [](O& o) -> double& { return o.w_sigma_radps; }),
      P::real<O>("noise_reference_rate_hz", 0.1, 1000.0, "Hz", "the rate the two sigmas above are given at",
                 [](O& o) -> double& { return o.noise_reference_rate_hz; }),
      P::real<O>("pixy_rate_hz", 0.1, 100.0, "Hz", "camera frames per second",
                 [](O& o) -> double& { return o.pixy_rate_hz; }),
      P::real<O>("range_sigma_m", 0.0, 10.0, "m", "range noise on the true range",
                 [](O& o) -> double& { return o.range_sigma_m; }),
      P::real<O>("bearing_sigma_rad", 0.0, 1.0, "rad", "bearing noise on the true bearing",
                 [](O& o) -> double& { return o.bearing_sigma_rad; }),
      P::real<O>("pole_width_m", 0.001, 10.0, "m", "the poles' width", [](O& o) -> double& { return o.pole_width_m; }),
      P::real<O>("min_range_m", 0.0, 100.0, "m", "poles nearer than this are not seen",
                 [](O& o) -> double& { return o.min_range_m; }),
      P::real<O>("max_range_m", 0.01, 1000.0, "m", "poles farther than this are not seen (> min_range_m)",
                 [](O& o) -> double& { return o.max_range_m; }),
      P::integer<O, int>("min_block_area_px", 0, 1000000, "px", "smaller blocks are not reported",
                         [](O& o) -> int& { return o.min_block_area_px; }),
      P::integer<O, int>("colour_code_angle_deg", -180, 180, "deg", "the colour code block's angle",
                         [](O& o) -> int& { return o.colour_code_angle_deg; }),
      P::boolean<O>("send_empty_frames", "frames without blocks too", [](O& o) -> bool& { return o.send_empty_frames; }),
      P::real<O>("physics_step_s", 1e-5, 0.1, "s", "the simulation's time step",
                 [](O& o) -> double& { return o.physics_step_s; }),
  };
  return table;
}

void validate(const HardwareOptions& o) {
  parameters::check_ranges(o, hardware_parameters(), "hardware");
  if (!(o.max_range_m > o.min_range_m)) {
    throw parameters::RuleError("hardware", "max_range_m",
                                "value " + parameters::number_text(o.max_range_m) + " must be greater than min_range_m (" +
                                    parameters::number_text(o.min_range_m) + ")");
  }
}

HardwareOptions read_hardware_options(config::YamlReader& r) {
  HardwareOptions o;
  config::read_parameters(r, hardware_parameters(), o);
  r.finish();
  config::check_rules(r, [&] { validate(o); });
  return o;
}

std::string to_yaml(const HardwareOptions& o) { return parameters::to_yaml(o, hardware_parameters(), "hardware"); }

}  // namespace pixyslam::robot_sim
