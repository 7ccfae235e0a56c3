#include "pixyslam/encoder/encoder_options.h"

#include <array>
#include <sstream>
#include <stdexcept>

#include "pixyslam/config/yaml_text.h"

namespace pixyslam::encoder {
namespace {

constexpr std::array<long, 30> kStandardBauds = {
    50,     75,     110,    134,     150,     200,     300,     600,     1200,    1800,
    2400,   4800,   9600,   19200,   38400,   57600,   115200,  230400,  460800,  500000,
    576000, 921600, 1000000, 1152000, 1500000, 2000000, 2500000, 3000000, 3500000, 4000000};

// Ranges shared by validate() and the YAML reader.
constexpr double kMinRadiusM = 0.001, kMaxRadiusM = 1.0;
constexpr long kMinTicks = 1, kMaxTicks = 10000000;
constexpr double kMinBaseM = 0.01, kMaxBaseM = 5.0;
constexpr double kMinRateHz = 0.1, kMaxRateHz = 100.0;
constexpr double kMinSpeedMps = 0.01, kMaxSpeedMps = 20.0;
constexpr double kMinGapS = 0.001, kMaxGapS = 60.0;

void check_range(const char* name, double v, double lo, double hi) {
  if (!(v >= lo && v <= hi)) {
    std::ostringstream os;
    os << name << " = " << v << " is out of range [" << lo << ", " << hi << "]";
    throw std::invalid_argument(os.str());
  }
}

std::string baud_list() {
  std::string s;
  for (const long b : kStandardBauds) s += (s.empty() ? "" : ", ") + std::to_string(b);
  return s;
}

int read_sign(config::YamlReader& r, const std::string& key) {
  const auto v = r.integer(key, -1, 1);
  if (v == 0) r.fail(key, "value 0 is not a sign (expected 1 or -1)");
  return static_cast<int>(v);
}

}  // namespace

bool is_standard_baud(long baud) {
  for (const long b : kStandardBauds) {
    if (b == baud) return true;
  }
  return false;
}

void validate(const EncoderOptions& o) {
  if (o.serial_device.empty() || o.serial_device.front() != '/') {
    throw std::invalid_argument("serial_device '" + o.serial_device + "' is not an absolute path");
  }
  if (!is_standard_baud(o.baud)) {
    throw std::invalid_argument("baud " + std::to_string(o.baud) + " is not a standard rate");
  }
  check_range("wheel_radius_m", o.wheel_radius_m, kMinRadiusM, kMaxRadiusM);
  check_range("ticks_per_revolution", o.ticks_per_revolution, kMinTicks, kMaxTicks);
  check_range("wheel_base_m", o.wheel_base_m, kMinBaseM, kMaxBaseM);
  if (o.left_sign != 1 && o.left_sign != -1) throw std::invalid_argument("left_sign must be 1 or -1");
  if (o.right_sign != 1 && o.right_sign != -1) throw std::invalid_argument("right_sign must be 1 or -1");
  check_range("publish_rate_hz", o.publish_rate_hz, kMinRateHz, kMaxRateHz);
  check_range("max_wheel_speed_mps", o.max_wheel_speed_mps, kMinSpeedMps, kMaxSpeedMps);
  check_range("max_sample_gap_s", o.max_sample_gap_s, kMinGapS, kMaxGapS);
}

EncoderOptions read_encoder_options(config::YamlReader& r) {
  EncoderOptions o;
  o.serial_device = r.text("serial_device", o.serial_device);
  if (o.serial_device.empty() || o.serial_device.front() != '/') {
    r.fail("serial_device", "value '" + o.serial_device + "' is not an absolute path (e.g. /dev/ttyACM0)");
  }
  o.baud = static_cast<int>(r.integer("baud", 1, 4000000, o.baud));
  if (!is_standard_baud(o.baud)) {
    r.fail("baud", "value " + std::to_string(o.baud) + " is not a standard serial rate (" + baud_list() + ")");
  }
  o.wheel_radius_m = r.number("wheel_radius_m", kMinRadiusM, kMaxRadiusM);
  o.ticks_per_revolution = static_cast<int>(r.integer("ticks_per_revolution", kMinTicks, kMaxTicks));
  o.wheel_base_m = r.number("wheel_base_m", kMinBaseM, kMaxBaseM);
  o.left_sign = read_sign(r, "left_sign");
  o.right_sign = read_sign(r, "right_sign");
  o.publish_rate_hz = r.number("publish_rate_hz", kMinRateHz, kMaxRateHz, o.publish_rate_hz);
  o.max_wheel_speed_mps = r.number("max_wheel_speed_mps", kMinSpeedMps, kMaxSpeedMps, o.max_wheel_speed_mps);
  o.max_sample_gap_s = r.number("max_sample_gap_s", kMinGapS, kMaxGapS, o.max_sample_gap_s);
  r.finish();
  r.check_mapping([&] { validate(o); });
  return o;
}

EncoderOptions read_encoder_options_file(const std::string& path) {
  config::YamlReader root = config::YamlReader::from_file(path);
  config::YamlReader bridge = root.child("encoder_bridge");
  EncoderOptions o = read_encoder_options(bridge);
  // The process's own mappings, read by the encoder node (encoder_node_options.h).
  for (const char* process_key : {"node", "dds"}) {
    if (root.has(process_key)) root.child(process_key);
  }
  root.finish();
  return o;
}

std::string to_yaml(const EncoderOptions& o) {
  using config::yaml_number;
  std::ostringstream os;
  os << "encoder_bridge:\n"
     << "  serial_device: " << config::yaml_quoted(o.serial_device) << "\n"
     << "  baud: " << o.baud << "\n"
     << "  wheel_radius_m: " << yaml_number(o.wheel_radius_m) << "\n"
     << "  ticks_per_revolution: " << o.ticks_per_revolution << "\n"
     << "  wheel_base_m: " << yaml_number(o.wheel_base_m) << "\n"
     << "  left_sign: " << o.left_sign << "\n"
     << "  right_sign: " << o.right_sign << "\n"
     << "  publish_rate_hz: " << yaml_number(o.publish_rate_hz) << "\n"
     << "  max_wheel_speed_mps: " << yaml_number(o.max_wheel_speed_mps) << "\n"
     << "  max_sample_gap_s: " << yaml_number(o.max_sample_gap_s) << "\n";
  return os.str();
}

}  // namespace pixyslam::encoder
