#include "pixyslam/eval/csv_io.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <fstream>
#include <initializer_list>
#include <iterator>
#include <stdexcept>
#include <string>
#include <string_view>
#include <system_error>
#include <vector>

namespace pixyslam::eval {
namespace {

constexpr std::string_view kTrajectoryHeader = "t,x,y,theta";
constexpr std::string_view kLandmarkHeader = "id,x,y,cov_xx,cov_xy,cov_yy";

std::string_view trim(std::string_view s) {
  constexpr std::string_view kSpace = " \t\r";
  const std::size_t first = s.find_first_not_of(kSpace);
  if (first == std::string_view::npos) return {};
  return s.substr(first, s.find_last_not_of(kSpace) - first + 1);
}

[[noreturn]] void fail_line(const std::string& path, std::size_t line_no, const std::string& what,
                            std::string_view line) {
  throw std::runtime_error(path + ":" + std::to_string(line_no) + ": " + what + " in line '" +
                           std::string(trim(line)) + "'");
}

// Location of one data line, for error messages.
struct LineRef {
  const std::string& path;
  std::size_t line_no;
  std::string_view text;
};

double parse_real(std::string_view field, const char* column, const LineRef& at) {
  const std::string_view f = trim(field);
  double value = 0.0;
  const auto [end, ec] = std::from_chars(f.data(), f.data() + f.size(), value);
  if (f.empty() || ec != std::errc() || end != f.data() + f.size()) {
    fail_line(at.path, at.line_no, std::string("column '") + column + "' is not a number: '" + std::string(f) + "'",
              at.text);
  }
  if (!std::isfinite(value)) {
    fail_line(at.path, at.line_no, std::string("column '") + column + "' is not finite: '" + std::string(f) + "'",
              at.text);
  }
  return value;
}

int parse_int(std::string_view field, const char* column, const LineRef& at) {
  const std::string_view f = trim(field);
  int value = 0;
  const auto [end, ec] = std::from_chars(f.data(), f.data() + f.size(), value);
  if (f.empty() || ec != std::errc() || end != f.data() + f.size()) {
    fail_line(at.path, at.line_no, std::string("column '") + column + "' is not an integer: '" + std::string(f) + "'",
              at.text);
  }
  return value;
}

// Reads `path`, checks that the first line equals `header`, and calls
// on_row(fields, line_ref) for every non-blank data line after checking that it
// has exactly as many comma-separated fields as the header.
template <class OnRow>
void read_csv(const std::string& path, std::string_view header, OnRow&& on_row) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error(path + ": cannot open file for reading");
  const std::string content((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (in.bad()) throw std::runtime_error(path + ": read error");

  const std::size_t n_fields = static_cast<std::size_t>(std::count(header.begin(), header.end(), ',')) + 1;
  std::vector<std::string_view> fields;
  std::size_t line_no = 0;
  std::size_t pos = 0;
  bool header_seen = false;
  while (pos < content.size()) {
    std::size_t eol = content.find('\n', pos);
    if (eol == std::string::npos) eol = content.size();
    std::string_view line(content.data() + pos, eol - pos);
    pos = eol + 1;
    ++line_no;
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);

    if (!header_seen) {
      if (line != header) {
        fail_line(path, line_no, "expected header '" + std::string(header) + "'", line);
      }
      header_seen = true;
      continue;
    }
    if (trim(line).empty()) continue;

    fields.clear();
    std::size_t start = 0;
    while (true) {
      const std::size_t comma = line.find(',', start);
      fields.push_back(line.substr(start, comma == std::string_view::npos ? std::string_view::npos : comma - start));
      if (comma == std::string_view::npos) break;
      start = comma + 1;
    }
    if (fields.size() != n_fields) {
      fail_line(path, line_no,
                "expected " + std::to_string(n_fields) + " fields, found " + std::to_string(fields.size()), line);
    }
    on_row(fields, LineRef{path, line_no, line});
  }
  if (!header_seen) {
    throw std::runtime_error(path + ":1: file is empty, expected header '" + std::string(header) + "'");
  }
}

// Appends the shortest decimal text that parses back to exactly `value`.
void append_number(std::string& out, double value) {
  char buf[64];
  const auto [end, ec] = std::to_chars(buf, buf + sizeof(buf), value);
  if (ec != std::errc()) throw std::runtime_error("csv: cannot format number");  // cannot happen for 64 chars
  out.append(buf, end);
}

void append_number(std::string& out, int value) { out += std::to_string(value); }

template <class First, class... Rest>
void append_row(std::string& out, const First& first, const Rest&... rest) {
  append_number(out, first);
  ((out += ',', append_number(out, rest)), ...);
  out += '\n';
}

void require_finite(const std::string& path, std::size_t index, std::initializer_list<double> values) {
  for (const double v : values) {
    if (!std::isfinite(v)) {
      throw std::runtime_error(path + ": refusing to write a non-finite value (row index " + std::to_string(index) +
                               ")");
    }
  }
}

void write_file(const std::string& path, const std::string& content) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  if (!out) throw std::runtime_error(path + ": cannot open file for writing");
  out.write(content.data(), static_cast<std::streamsize>(content.size()));
  out.close();
  if (!out) throw std::runtime_error(path + ": write failed");
}

}  // namespace

std::vector<TimedPose> read_trajectory_csv(const std::string& path) {
  std::vector<TimedPose> poses;
  read_csv(path, kTrajectoryHeader, [&](const std::vector<std::string_view>& f, const LineRef& at) {
    poses.push_back(TimedPose{parse_real(f[0], "t", at), parse_real(f[1], "x", at), parse_real(f[2], "y", at),
                              parse_real(f[3], "theta", at)});
  });
  return poses;
}

void write_trajectory_csv(const std::string& path, const std::vector<TimedPose>& poses) {
  std::string text(kTrajectoryHeader);
  text += '\n';
  for (std::size_t i = 0; i < poses.size(); ++i) {
    const TimedPose& p = poses[i];
    require_finite(path, i, {p.t_s, p.x_m, p.y_m, p.theta_rad});
    append_row(text, p.t_s, p.x_m, p.y_m, p.theta_rad);
  }
  write_file(path, text);
}

TrajectoryCsvWriter::TrajectoryCsvWriter(const std::string& path)
    : path_(path), out_(path, std::ios::binary | std::ios::trunc) {
  if (!out_) throw std::runtime_error(path + ": cannot open file for writing");
  out_ << kTrajectoryHeader << '\n';
  flush();
}

void TrajectoryCsvWriter::append(const TimedPose& p) {
  if (!std::isfinite(p.t_s) || !std::isfinite(p.x_m) || !std::isfinite(p.y_m) || !std::isfinite(p.theta_rad)) {
    ++skipped_;
    return;
  }
  line_.clear();
  append_row(line_, p.t_s, p.x_m, p.y_m, p.theta_rad);
  out_.write(line_.data(), static_cast<std::streamsize>(line_.size()));
  if (!out_) throw std::runtime_error(path_ + ": write failed");
  ++rows_;
}

void TrajectoryCsvWriter::flush() {
  out_.flush();
  if (!out_) throw std::runtime_error(path_ + ": write failed");
}

std::vector<LandmarkRow> read_landmarks_csv(const std::string& path) {
  std::vector<LandmarkRow> rows;
  read_csv(path, kLandmarkHeader, [&](const std::vector<std::string_view>& f, const LineRef& at) {
    rows.push_back(LandmarkRow{parse_int(f[0], "id", at), parse_real(f[1], "x", at), parse_real(f[2], "y", at),
                               parse_real(f[3], "cov_xx", at), parse_real(f[4], "cov_xy", at),
                               parse_real(f[5], "cov_yy", at)});
  });
  return rows;
}

void write_landmarks_csv(const std::string& path, const std::vector<LandmarkRow>& rows) {
  std::string text(kLandmarkHeader);
  text += '\n';
  for (std::size_t i = 0; i < rows.size(); ++i) {
    const LandmarkRow& r = rows[i];
    require_finite(path, i, {r.x_m, r.y_m, r.cov_xx, r.cov_xy, r.cov_yy});
    append_row(text, r.id, r.x_m, r.y_m, r.cov_xx, r.cov_xy, r.cov_yy);
  }
  write_file(path, text);
}

}  // namespace pixyslam::eval
