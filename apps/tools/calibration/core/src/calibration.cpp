#include "pixyslam/calibration/calibration.h"

#include <cmath>
#include <sstream>
#include <stdexcept>
#include <variant>

#include "pixyslam/config/yaml_reader.h"
#include "pixyslam/parameters/parameters.h"
#include "pixyslam/encoder/arduino_line_parser.h"
#include "pixyslam/encoder/wheel_odometry.h"

namespace pixyslam::calibration {
namespace {

std::string trim(std::string_view s) {
  const std::size_t b = s.find_first_not_of(" \t\r");
  if (b == std::string_view::npos) return "";
  const std::size_t e = s.find_last_not_of(" \t\r");
  return std::string(s.substr(b, e - b + 1));
}

double rms(const std::vector<double>& v) {
  double s = 0.0;
  for (double x : v) s += x * x;
  return v.empty() ? 0.0 : std::sqrt(s / static_cast<double>(v.size()));
}

}  // namespace

CsvTable read_csv(std::string_view text, const std::string& origin) {
  CsvTable table;
  int line_number = 0;
  std::size_t begin = 0;
  while (begin < text.size()) {
    const std::size_t end = std::min(text.find('\n', begin), text.size());
    const std::string line = trim(text.substr(begin, end - begin));
    begin = end + 1;
    ++line_number;
    if (line.empty() || line[0] == '#') continue;
    std::vector<std::string> fields = parameters::split_list(line);
    if (table.header.empty()) {
      table.header = fields;
      table.header_line = line_number;
      continue;
    }
    if (fields.size() != table.header.size()) {
      throw config::ConfigError(origin + ":" + std::to_string(line_number) + ": " +
                                std::to_string(table.header.size()) + " fields expected, got " +
                                std::to_string(fields.size()));
    }
    table.rows.push_back({line_number, std::move(fields)});
  }
  if (table.header.empty()) throw config::ConfigError(origin + ": no header line");
  return table;
}

double csv_number(const CsvTable& table, const CsvRow& row, std::size_t column, const std::string& origin) {
  const std::string& field = row.fields[column];
  std::size_t used = 0;
  double x = 0.0;
  try {
    x = std::stod(field, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used != field.size() || !std::isfinite(x)) {
    throw config::ConfigError(origin + ":" + std::to_string(row.line) + ": " + table.header[column] + " '" + field +
                              "' is not a number");
  }
  return x;
}

void check_pole_sample(const PoleSample& s, const std::string& where) {
  if (s.distance_m <= 0.0 || s.distance_m > 100.0) throw config::ConfigError(where + "distance_m must be in (0, 100]");
  if (s.height_px <= 0.0 || s.height_px > 10000.0) throw config::ConfigError(where + "height_px must be in (0, 10000]");
  if (s.has_bearing && std::abs(s.bearing_rad) >= M_PI / 2) {
    throw config::ConfigError(where + "bearing_rad must be in (-pi/2, pi/2)");
  }
}

std::vector<PoleSample> parse_pole_samples(std::string_view text, const std::string& origin) {
  const CsvTable table = read_csv(text, origin);
  const bool two = table.header == std::vector<std::string>{"distance_m", "height_px"};
  const bool four = table.header == std::vector<std::string>{"distance_m", "height_px", "x_px", "bearing_rad"};
  if (!two && !four) {
    throw config::ConfigError(origin + ":" + std::to_string(table.header_line) +
                              ": the header must be 'distance_m,height_px' or 'distance_m,height_px,x_px,bearing_rad'");
  }
  std::vector<PoleSample> out;
  for (const CsvRow& row : table.rows) {
    PoleSample s;
    s.distance_m = csv_number(table, row, 0, origin);
    s.height_px = csv_number(table, row, 1, origin);
    s.line = row.line;
    if (four) {
      s.has_bearing = true;
      s.x_px = csv_number(table, row, 2, origin);
      s.bearing_rad = csv_number(table, row, 3, origin);
    }
    check_pole_sample(s, origin + ":" + std::to_string(row.line) + ": ");
    out.push_back(s);
  }
  return out;
}

CameraFit fit_camera(const std::vector<PoleSample>& samples, const pixy::CameraModel& camera) {
  if (samples.size() < 2) throw std::invalid_argument("camera calibration needs at least two samples");
  // h_i = K / d_i with K = f h_r I_h / S_h: K = sum(h/d) / sum(1/d^2) minimises the pixel residuals.
  double num = 0.0, den = 0.0;
  for (const PoleSample& s : samples) {
    num += s.height_px / s.distance_m;
    den += 1.0 / (s.distance_m * s.distance_m);
  }
  const double k = num / den;
  CameraFit fit;
  // Eq. 5 (h = block_height_px at 1 m / d) is linear in f: f = K / (its value for f = 1 mm).
  pixy::CameraModel unit_focus = camera;
  unit_focus.focal_length_mm = 1.0;
  fit.focal_length_mm = k / pixy::block_height_px(unit_focus, 1.0);
  pixy::CameraModel fitted = camera;
  fitted.focal_length_mm = fit.focal_length_mm;
  // tan(phi_i) = c u_i, u_i = I_w/2 - x_i, c = S_w / (f I_w): least squares over samples off the axis.
  double su = 0.0, suu = 0.0;
  int off_axis = 0;
  for (const PoleSample& s : samples) {
    if (!s.has_bearing) continue;
    const double u = 0.5 * camera.image_width_px - s.x_px;
    if (std::abs(u) < 0.5) continue;
    su += u * std::tan(s.bearing_rad);
    suu += u * u;
    ++off_axis;
  }
  if (off_axis >= 2) {
    fit.has_sensor_width = true;
    fit.sensor_width_mm = su / suu * fit.focal_length_mm * camera.image_width_px;
    fitted.sensor_width_mm = fit.sensor_width_mm;
  }
  for (const PoleSample& s : samples) {
    fit.height_residual_px.push_back(s.height_px - k / s.distance_m);
    fit.range_error.push_back((pixy::range_m(fitted, s.height_px) - s.distance_m) / s.distance_m);
    fit.bearing_residual_rad.push_back(
        s.has_bearing && fit.has_sensor_width ? pixy::bearing_rad(fitted, s.x_px) - s.bearing_rad : 0.0);
  }
  fit.rms_height_px = rms(fit.height_residual_px);
  fit.rms_range_error = rms(fit.range_error);
  if (fit.has_sensor_width) {
    std::vector<double> used;
    for (std::size_t i = 0; i < samples.size(); ++i) {
      if (samples[i].has_bearing) used.push_back(fit.bearing_residual_rad[i]);
    }
    fit.rms_bearing_rad = rms(used);
  }
  return fit;
}

TickCount net_ticks(std::string_view arduino_bytes, const std::string& origin) {
  encoder::ArduinoLineParser parser;
  bool has_first = false;
  encoder::EncoderSample first, last;
  TickCount count;
  bool reset_after_first = false;
  parser.feed(arduino_bytes.data(), arduino_bytes.size(), [&](const encoder::ArduinoMessage& m) {
    if (std::holds_alternative<encoder::EncoderReset>(m)) {
      if (has_first) reset_after_first = true;
      return;
    }
    const auto& s = std::get<encoder::EncoderSample>(m);
    if (!has_first) {
      first = s;
      has_first = true;
    }
    last = s;
    ++count.samples;
  });
  count.rejected_lines = parser.counters().rejected_lines();
  if (reset_after_first) {
    throw config::ConfigError(origin + ": the Arduino restarted (RST line) during the recording: record it again");
  }
  if (count.samples < 2) {
    throw config::ConfigError(origin + ": " + std::to_string(count.samples) +
                              " encoder sample(s) (ENC lines); a recording needs at least two");
  }
  count.left = encoder::tick_delta(last.left_ticks, first.left_ticks);
  count.right = encoder::tick_delta(last.right_ticks, first.right_ticks);
  return count;
}

OdometryFit fit_odometry(const std::vector<OdometryRun>& straights, const std::vector<OdometryRun>& turns,
                         int ticks_per_revolution, int left_sign, int right_sign) {
  if (straights.empty() || turns.empty()) {
    throw std::invalid_argument("odometry calibration needs at least one straight run and one turn");
  }
  if (ticks_per_revolution <= 0) throw std::invalid_argument("ticks_per_revolution must be > 0");
  auto mean_ticks = [&](const TickCount& t) {
    return 0.5 * (left_sign * static_cast<double>(t.left) + right_sign * static_cast<double>(t.right));
  };
  auto tick_difference = [&](const TickCount& t) {
    return right_sign * static_cast<double>(t.right) - left_sign * static_cast<double>(t.left);
  };
  // distance_j = m a_j (m metres per tick): m = sum(D a) / sum(a^2).
  double sda = 0.0, saa = 0.0;
  for (const OdometryRun& r : straights) {
    const double a = mean_ticks(r.ticks);
    sda += r.truth * a;
    saa += a * a;
  }
  if (saa <= 0.0 || sda <= 0.0) {
    throw std::invalid_argument("the straight runs show no forward wheel motion (check left_sign / right_sign)");
  }
  const double m = sda / saa;
  // angle_j = (m c_j) / b: 1 / b = sum(A m c) / sum((m c)^2).
  double sac = 0.0, scc = 0.0;
  for (const OdometryRun& r : turns) {
    const double c = m * tick_difference(r.ticks);
    sac += r.truth * c;
    scc += c * c;
  }
  if (scc <= 0.0 || sac <= 0.0) {
    throw std::invalid_argument("the turns show no wheel difference in the turning direction (check the signs)");
  }
  OdometryFit fit;
  fit.wheel_radius_m = m * ticks_per_revolution / (2.0 * M_PI);
  fit.wheel_base_m = scc / sac;
  for (const OdometryRun& r : straights) {
    fit.straight_error_m.push_back(m * mean_ticks(r.ticks) - r.truth);
    fit.straight_rotation_rad.push_back(m * tick_difference(r.ticks) / fit.wheel_base_m);
  }
  for (const OdometryRun& r : turns) {
    fit.turn_error_rad.push_back(m * tick_difference(r.ticks) / fit.wheel_base_m - r.truth);
  }
  return fit;
}

std::string replace_yaml_value(const std::string& yaml_text, const std::string& section, const std::string& key,
                               const std::string& value) {
  std::istringstream in(yaml_text);
  std::string out, line;
  bool in_section = false, done = false;
  while (std::getline(in, line)) {
    if (!line.empty() && line[0] != ' ' && line[0] != '#') in_section = line.rfind(section + ":", 0) == 0;
    const std::size_t indent = line.find_first_not_of(' ');
    if (!done && in_section && indent != std::string::npos && indent > 0 &&
        line.compare(indent, key.size() + 1, key + ":") == 0) {
      const std::size_t value_begin = line.find_first_not_of(' ', indent + key.size() + 1);
      const std::size_t comment = value_begin == std::string::npos ? std::string::npos : line.find(" #", value_begin);
      std::string replaced = line.substr(0, indent) + key + ": " + value;
      if (comment != std::string::npos) {
        // The '#' stays in its column when the new value fits.
        const std::size_t hash = comment + 1;
        replaced += std::string(hash > replaced.size() ? hash - replaced.size() : 1, ' ') + line.substr(hash);
      }
      line = replaced;
      done = true;
    }
    out += line + "\n";
  }
  if (!done) throw std::invalid_argument("no line '" + key + ": ...' under '" + section + ":'");
  return out;
}

}  // namespace pixyslam::calibration
