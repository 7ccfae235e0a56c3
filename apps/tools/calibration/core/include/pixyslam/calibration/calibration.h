#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "pixyslam/pixy/pixy_geometry.h"

namespace pixyslam::calibration {

// ---- Camera: Eq. 5 and 6 of the seed paper fitted to poles at known places.

// A pole seen at a known distance: its block height (and, optionally, its
// column x_px at a known bearing, > 0 left of the optical axis).
struct PoleSample {
  double distance_m = 0.0;
  double height_px = 0.0;
  bool has_bearing = false;
  double x_px = 0.0;
  double bearing_rad = 0.0;
  int line = 0;  // in the CSV it came from
};

// A CSV file: a header line, then rows with as many comma-separated fields;
// '#' comments and blank lines skipped. config::ConfigError naming
// `origin`:line for a row of the wrong width, or a file without a header.
struct CsvRow {
  int line = 0;
  std::vector<std::string> fields;
};
struct CsvTable {
  int header_line = 0;
  std::vector<std::string> header;
  std::vector<CsvRow> rows;
};
CsvTable read_csv(std::string_view text, const std::string& origin);
// Field `column` of `row` as a finite number, else config::ConfigError naming
// origin:line, the column's name and the text.
double csv_number(const CsvTable& table, const CsvRow& row, std::size_t column, const std::string& origin);
// Throws config::ConfigError (prefixed by `where`) for a distance outside (0, 100] m,
// a height outside (0, 10000] px or a bearing outside (-pi/2, pi/2).
void check_pole_sample(const PoleSample& sample, const std::string& where);

// CSV with the header distance_m,height_px[,x_px,bearing_rad].
std::vector<PoleSample> parse_pole_samples(std::string_view text, const std::string& origin);

struct CameraFit {
  double focal_length_mm = 0.0;   // from the heights: h = f h_r I_h / (S_h r), least squares in pixels
  bool has_sensor_width = false;
  double sensor_width_mm = 0.0;   // from the columns: tan(phi) = (I_w/2 - x) S_w / (f I_w)
  std::vector<double> height_residual_px;  // measured - fitted, per sample
  std::vector<double> range_error;         // (Eq. 5 range with the fit - distance) / distance
  std::vector<double> bearing_residual_rad;  // per sample with a bearing (else 0)
  double rms_height_px = 0.0;
  double rms_range_error = 0.0;
  double rms_bearing_rad = 0.0;
};

// Fits f (and S_w when at least two samples have a bearing off the axis), the
// rest of `camera` (S_h, I_h, I_w, h_r) as given. std::invalid_argument with
// fewer than two usable samples.
CameraFit fit_camera(const std::vector<PoleSample>& samples, const pixy::CameraModel& camera);

// ---- Odometry: wheel radius from straight runs, wheel base from turns.

// The net tick counts of one recording of the Arduino's serial output (its
// lines as captured, e.g. `cat /dev/ttyACM0 > run.txt`): last ENC sample minus
// first, wrap-aware. config::ConfigError naming `origin` when it holds fewer
// than two samples or an RST line between them (the counters restarted).
struct TickCount {
  std::int64_t left = 0;
  std::int64_t right = 0;
  std::size_t samples = 0;
  std::size_t rejected_lines = 0;
};
TickCount net_ticks(std::string_view arduino_bytes, const std::string& origin);

struct OdometryRun {
  TickCount ticks;
  double truth = 0.0;  // straight: distance driven (m, > 0 forward); turn: angle turned (rad, > 0 CCW)
  std::string name;
};

struct OdometryFit {
  double wheel_radius_m = 0.0;  // distance = (2 pi r / N) (sL dL + sR dR) / 2, least squares over straights
  double wheel_base_m = 0.0;    // angle = (2 pi r / N) (sR dR - sL dL) / b, least squares over turns
  std::vector<double> straight_error_m;       // fitted distance - truth, per straight run
  std::vector<double> straight_rotation_rad;  // rotation the fit sees in each straight run (should be ~0)
  std::vector<double> turn_error_rad;         // fitted angle - truth, per turn
};

// std::invalid_argument without a straight run and a turn, or when the runs
// give no usable motion (no ticks, a turn whose wheels moved the same way).
OdometryFit fit_odometry(const std::vector<OdometryRun>& straights, const std::vector<OdometryRun>& turns,
                         int ticks_per_revolution, int left_sign, int right_sign);

// ---- Output.

// `yaml_text` with the value of the one line "  key: value  # comment" (any
// indent; the first such line under `section:`) replaced by `value`, comment
// kept. std::invalid_argument naming the key when there is no such line.
std::string replace_yaml_value(const std::string& yaml_text, const std::string& section, const std::string& key,
                               const std::string& value);

}  // namespace pixyslam::calibration
