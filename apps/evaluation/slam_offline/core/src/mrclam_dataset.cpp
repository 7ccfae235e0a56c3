#include "pixyslam/mrclam/mrclam_dataset.h"

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <set>
#include <stdexcept>
#include <string_view>
#include <system_error>

namespace pixyslam::mrclam {
namespace {

namespace fs = std::filesystem;

constexpr const char* kBarcodeFile = "Barcodes.dat";
constexpr const char* kLandmarkFile = "Landmark_Groundtruth.dat";
constexpr const char* kLandmarkFixedFile = "Landmark_Groundtruth_fixed_11_17.dat";

// Type of one column: real number or integer (subject and barcode numbers).
enum class Col { Real, Int };

bool is_space(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f'; }

std::string_view trim(std::string_view s) {
  std::size_t b = 0;
  while (b < s.size() && is_space(s[b])) ++b;
  std::size_t e = s.size();
  while (e > b && is_space(s[e - 1])) --e;
  return s.substr(b, e - b);
}

[[noreturn]] void fail_line(const std::string& path, std::size_t line_no, const std::string& what,
                            std::string_view line) {
  constexpr std::size_t kMaxShown = 200;
  std::string shown(trim(line).substr(0, kMaxShown));
  throw std::runtime_error("mrclam: " + path + ":" + std::to_string(line_no) + ": " + what + " in line '" + shown +
                           "'");
}

std::string read_whole_file(const std::string& path) {
  std::error_code ec;
  if (!fs::is_regular_file(path, ec)) throw std::runtime_error("mrclam: required file not found: " + path);
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error("mrclam: cannot open file: " + path);
  std::string content((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (in.bad()) throw std::runtime_error("mrclam: read error in file: " + path);
  return content;
}

// Parses every data line of `path` (skipping blank lines and '#' comments) as
// exactly N whitespace-separated numbers of the given column types and calls
// on_row(values, line_no); integers are passed as exactly representable doubles.
template <std::size_t N, class OnRow>
void read_table(const std::string& path, const std::array<Col, N>& cols, OnRow&& on_row) {
  const std::string content = read_whole_file(path);
  std::array<double, N> values{};
  std::array<std::string_view, N> tokens{};
  std::size_t line_no = 0;
  std::size_t pos = 0;
  while (pos < content.size()) {
    std::size_t eol = content.find('\n', pos);
    if (eol == std::string::npos) eol = content.size();
    const std::string_view line(content.data() + pos, eol - pos);
    pos = eol + 1;
    ++line_no;

    const std::string_view body = trim(line);
    if (body.empty() || body.front() == '#') continue;

    std::size_t n_tokens = 0;
    std::size_t i = 0;
    while (i < body.size()) {
      while (i < body.size() && is_space(body[i])) ++i;
      if (i == body.size()) break;
      const std::size_t start = i;
      while (i < body.size() && !is_space(body[i])) ++i;
      if (n_tokens < N) tokens[n_tokens] = body.substr(start, i - start);
      ++n_tokens;
    }
    if (n_tokens != N) {
      fail_line(path, line_no, "expected " + std::to_string(N) + " columns, found " + std::to_string(n_tokens),
                line);
    }

    for (std::size_t c = 0; c < N; ++c) {
      const std::string_view tok = tokens[c];
      const char* first = tok.data();
      const char* last = tok.data() + tok.size();
      if (first != last && *first == '+') ++first;  // from_chars rejects a leading '+'
      std::from_chars_result r{};
      if (cols[c] == Col::Int) {
        int v = 0;
        r = std::from_chars(first, last, v);
        values[c] = static_cast<double>(v);
      } else {
        r = std::from_chars(first, last, values[c]);
      }
      if (first == last || r.ec != std::errc() || r.ptr != last) {
        fail_line(path, line_no,
                  "column " + std::to_string(c + 1) + " is not " + (cols[c] == Col::Int ? "an integer" : "a number") +
                      ": '" + std::string(tok) + "'",
                  line);
      }
      if (!std::isfinite(values[c])) {
        fail_line(path, line_no, "column " + std::to_string(c + 1) + " is not finite: '" + std::string(tok) + "'",
                  line);
      }
    }
    on_row(values, line_no);
  }
}

template <class Row>
void sort_by_time(std::vector<Row>& rows) {
  const auto earlier = [](const Row& a, const Row& b) { return a.t_s < b.t_s; };
  if (!std::is_sorted(rows.begin(), rows.end(), earlier)) std::stable_sort(rows.begin(), rows.end(), earlier);
}

}  // namespace

RobotData load_robot(const std::string& dataset_dir, int robot) {
  if (robot < kFirstRobot || robot > kLastRobot) {
    throw std::runtime_error("mrclam: robot number must be in 1..5, got " + std::to_string(robot));
  }
  std::error_code ec;
  if (!fs::is_directory(dataset_dir, ec)) {
    throw std::runtime_error("mrclam: data set folder not found: " + dataset_dir);
  }
  const fs::path dir(dataset_dir);
  const std::string prefix = "Robot" + std::to_string(robot) + "_";
  const auto file = [&](const std::string& name) { return (dir / name).string(); };

  RobotData data;
  data.robot = robot;

  // Barcode -> subject.
  std::map<int, int> subject_of_barcode;
  const std::string barcode_path = file(kBarcodeFile);
  read_table<2>(barcode_path, {Col::Int, Col::Int}, [&](const std::array<double, 2>& v, std::size_t line_no) {
    const int subject = static_cast<int>(v[0]);
    const int barcode = static_cast<int>(v[1]);
    if (subject < 1) {
      throw std::runtime_error("mrclam: " + barcode_path + ":" + std::to_string(line_no) +
                               ": subject number must be >= 1, got " + std::to_string(subject));
    }
    const auto [it, inserted] = subject_of_barcode.emplace(barcode, subject);
    if (!inserted && it->second != subject) {
      throw std::runtime_error("mrclam: " + barcode_path + ":" + std::to_string(line_no) + ": barcode " +
                               std::to_string(barcode) + " maps to subject " + std::to_string(subject) +
                               " but earlier to subject " + std::to_string(it->second));
    }
  });

  // Landmark ground truth, preferring the corrected file; optional (a robot of
  // one's own may have no surveyed landmarks).
  std::set<int> landmark_ids;
  if (fs::exists(dir / kLandmarkFixedFile, ec)) {
    data.landmark_file = kLandmarkFixedFile;
  } else if (fs::exists(dir / kLandmarkFile, ec)) {
    data.landmark_file = kLandmarkFile;
  }
  if (!data.landmark_file.empty()) {
    const std::string landmark_path = file(data.landmark_file);
    read_table<5>(landmark_path, {Col::Int, Col::Real, Col::Real, Col::Real, Col::Real},
                  [&](const std::array<double, 5>& v, std::size_t line_no) {
                    const int subject = static_cast<int>(v[0]);
                    if (!landmark_ids.insert(subject).second) {
                      throw std::runtime_error("mrclam: " + landmark_path + ":" + std::to_string(line_no) +
                                               ": landmark " + std::to_string(subject) + " listed twice");
                    }
                    data.landmarks.push_back(eval::LandmarkPoint{subject, v[1], v[2]});
                  });
  }

  // Odometry.
  read_table<3>(file(prefix + "Odometry.dat"), {Col::Real, Col::Real, Col::Real},
                [&](const std::array<double, 3>& v, std::size_t) {
                  data.odometry.push_back(OdometryRow{v[0], v[1], v[2]});
                });
  sort_by_time(data.odometry);

  // Measurements: map barcodes, drop robots and spurious barcodes, group by time.
  struct RawMeasurement {
    double t_s;
    int barcode;
    double range_m;
    double bearing_rad;
  };
  std::vector<RawMeasurement> raw;
  read_table<4>(file(prefix + "Measurement.dat"), {Col::Real, Col::Int, Col::Real, Col::Real},
                [&](const std::array<double, 4>& v, std::size_t) {
                  raw.push_back(RawMeasurement{v[0], static_cast<int>(v[1]), v[2], v[3]});
                });
  sort_by_time(raw);
  data.counts.measurement_rows = raw.size();
  for (const RawMeasurement& m : raw) {
    const auto it = subject_of_barcode.find(m.barcode);
    if (it == subject_of_barcode.end()) {
      ++data.counts.unknown_barcode_rows;
      continue;
    }
    const int subject = it->second;
    // Subjects 1-5 are the robots, unless the landmark file lists one (a data
    // set converted from another robot may number its landmarks from 1).
    if (subject >= kFirstRobot && subject <= kLastRobot && landmark_ids.count(subject) == 0) {
      ++data.counts.robot_rows;
      if (data.robot_sightings.empty() || data.robot_sightings.back().t_s != m.t_s) {
        data.robot_sightings.push_back(MeasurementFrame{m.t_s, {}});
      }
      data.robot_sightings.back().detections.push_back(Detection{subject, m.range_m, m.bearing_rad});
      continue;
    }
    ++data.counts.landmark_rows;
    if (data.frames.empty() || data.frames.back().t_s != m.t_s) data.frames.push_back(MeasurementFrame{m.t_s, {}});
    data.frames.back().detections.push_back(Detection{subject, m.range_m, m.bearing_rad});
  }

  // Ground truth of this robot, optional.
  const fs::path groundtruth = dir / (prefix + "Groundtruth.dat");
  if (fs::exists(groundtruth, ec)) {
    read_table<4>(groundtruth.string(), {Col::Real, Col::Real, Col::Real, Col::Real},
                  [&](const std::array<double, 4>& v, std::size_t) {
                    data.groundtruth.push_back(eval::TimedPose{v[0], v[1], v[2], v[3]});
                  });
    sort_by_time(data.groundtruth);
  }
  return data;
}

namespace {

// Opens `path` for writing, calls write(stream), and checks that it all reached the file.
template <class Write>
void write_file(const fs::path& path, Write&& write) {
  std::ofstream out(path);
  if (!out) throw std::runtime_error("mrclam: cannot write " + path.string());
  out.precision(17);
  write(out);
  out.close();
  if (!out) throw std::runtime_error("mrclam: write failed: " + path.string());
}

}  // namespace

void write_robot(const std::string& dataset_dir, const RobotData& data) {
  if (data.robot < kFirstRobot || data.robot > kLastRobot) {
    throw std::runtime_error("mrclam: robot number must be in 1..5, got " + std::to_string(data.robot));
  }
  std::set<int> subjects;
  for (const eval::LandmarkPoint& l : data.landmarks) {
    if (l.id <= kLastRobot || !subjects.insert(l.id).second) {
      throw std::runtime_error("mrclam: landmark subject " + std::to_string(l.id) +
                               (l.id <= kLastRobot ? " is a robot's number (1..5)" : " given twice"));
    }
  }
  for (const MeasurementFrame& f : data.frames) {
    for (const Detection& d : f.detections) {
      if (d.subject <= kLastRobot) {
        throw std::runtime_error("mrclam: detection of subject " + std::to_string(d.subject) +
                                 " at t = " + std::to_string(f.t_s) + " s: landmark subjects are above 5");
      }
      subjects.insert(d.subject);
    }
  }
  const fs::path dir(dataset_dir);
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec) throw std::runtime_error("mrclam: cannot create " + dataset_dir + ": " + ec.message());
  const std::string prefix = "Robot" + std::to_string(data.robot) + "_";
  write_file(dir / kBarcodeFile, [&](std::ostream& out) {
    out << "# Subject #\tBarcode #\n";
    for (int r = kFirstRobot; r <= kLastRobot; ++r) out << r << '\t' << r << '\n';
    for (int s : subjects) out << s << '\t' << s << '\n';
  });
  write_file(dir / kLandmarkFile, [&](std::ostream& out) {
    out << "# Subject #\tx [m]\ty [m]\tx std-dev [m]\ty std-dev [m]\n";
    for (const eval::LandmarkPoint& l : data.landmarks) out << l.id << '\t' << l.x_m << '\t' << l.y_m << "\t0\t0\n";
  });
  write_file(dir / (prefix + "Odometry.dat"), [&](std::ostream& out) {
    out << "# Time [s]\tv [m/s]\tw [rad/s]\n";
    for (const OdometryRow& o : data.odometry) out << o.t_s << '\t' << o.v_mps << '\t' << o.w_radps << '\n';
  });
  write_file(dir / (prefix + "Measurement.dat"), [&](std::ostream& out) {
    out << "# Time [s]\tBarcode #\trange [m]\tbearing [rad]\n";
    for (const std::vector<MeasurementFrame>* frames : {&data.frames, &data.robot_sightings}) {
      for (const MeasurementFrame& f : *frames) {
        for (const Detection& d : f.detections) {
          out << f.t_s << '\t' << d.subject << '\t' << d.range_m << '\t' << d.bearing_rad << '\n';
        }
      }
    }
  });
  if (!data.groundtruth.empty()) {
    write_file(dir / (prefix + "Groundtruth.dat"), [&](std::ostream& out) {
      out << "# Time [s]\tx [m]\ty [m]\torientation [rad]\n";
      for (const eval::TimedPose& g : data.groundtruth) {
        out << g.t_s << '\t' << g.x_m << '\t' << g.y_m << '\t' << g.theta_rad << '\n';
      }
    });
  }
}

void check_robot_list(const std::vector<int>& robots, const std::string& what) {
  for (std::size_t i = 0; i < robots.size(); ++i) {
    if (robots[i] < kFirstRobot || robots[i] > kLastRobot) {
      throw std::invalid_argument(what + ": " + std::to_string(robots[i]) + " is not a robot number " +
                                  std::to_string(kFirstRobot) + "-" + std::to_string(kLastRobot));
    }
    if (std::find(robots.begin(), robots.begin() + static_cast<std::ptrdiff_t>(i), robots[i]) !=
        robots.begin() + static_cast<std::ptrdiff_t>(i)) {
      throw std::invalid_argument(what + ": robot " + std::to_string(robots[i]) + " given twice");
    }
  }
}

}  // namespace pixyslam::mrclam
