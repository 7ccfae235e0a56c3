#include "pixyslam/log_tool/message_format.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <deque>
#include <limits>
#include <map>
#include <stdexcept>
#include <tuple>

#include "pixyslam/dds/wire_text.h"

namespace pixyslam::log_tool {

Value Value::number(double v) {
  Value r(Kind::kFloat);
  r.float_ = v;
  return r;
}
Value Value::integer(std::int64_t v) {
  Value r(Kind::kInt);
  r.int_ = v;
  return r;
}
Value Value::unsigned_integer(std::uint64_t v) {
  Value r(Kind::kUInt);
  r.uint_ = v;
  return r;
}
Value Value::boolean(bool v) {
  Value r(Kind::kBool);
  r.uint_ = v ? 1 : 0;
  return r;
}
Value Value::string(std::string v) {
  Value r(Kind::kString);
  r.text_ = std::move(v);
  return r;
}

Value& Value::add(std::string name, Value value) {
  if (kind_ != Kind::kStruct) throw std::logic_error("Value::add on a non-struct");
  fields_.emplace_back(std::move(name), std::move(value));
  return *this;
}

Value& Value::push(Value value) {
  if (kind_ != Kind::kList) throw std::logic_error("Value::push on a non-list");
  items_.push_back(std::move(value));
  return *this;
}

const Value* Value::find(const std::string& path) const {
  const auto dot = path.find('.');
  const std::string head = path.substr(0, dot);
  for (const auto& [name, value] : fields_) {
    if (name != head) continue;
    return dot == std::string::npos ? &value : value.find(path.substr(dot + 1));
  }
  return nullptr;
}

namespace {

Value header_value(const msg::MessageHeader& h) {
  Value v = Value::structure();
  v.add("stamp_ns", Value::unsigned_integer(h.stamp_ns()))
      .add("seq", Value::unsigned_integer(h.seq()))
      .add("robot_id", Value::string(h.robot_id()))
      .add("frame_id", Value::string(h.frame_id()));
  return v;
}

Value pose_value(const msg::Pose2D& p) {
  Value v = Value::structure();
  v.add("x_m", Value::number(p.x_m())).add("y_m", Value::number(p.y_m())).add("theta_rad", Value::number(p.theta_rad()));
  return v;
}

template <class Container, class Convert>
Value list_of(const Container& items, Convert convert) {
  Value v = Value::list();
  for (const auto& item : items) v.push(convert(item));
  return v;
}

Value block_value(const msg::PixyBlock& b) {
  Value v = Value::structure();
  v.add("signature", Value::unsigned_integer(b.signature()))
      .add("x_px", Value::unsigned_integer(b.x_px()))
      .add("y_px", Value::unsigned_integer(b.y_px()))
      .add("width_px", Value::unsigned_integer(b.width_px()))
      .add("height_px", Value::unsigned_integer(b.height_px()))
      .add("angle_deg", Value::integer(b.angle_deg()));
  return v;
}

Value detection_value(const msg::LandmarkDetection& d) {
  Value v = Value::structure();
  v.add("landmark_id", Value::integer(d.landmark_id()))
      .add("range_m", Value::number(d.range_m()))
      .add("bearing_rad", Value::number(d.bearing_rad()))
      .add("range_sigma_m", Value::number(d.range_sigma_m()))
      .add("bearing_sigma_rad", Value::number(d.bearing_sigma_rad()))
      .add("block", block_value(d.block()));
  return v;
}

Value landmark_estimate_value(const msg::LandmarkEstimate& l) {
  Value v = Value::structure();
  v.add("landmark_id", Value::integer(l.landmark_id()))
      .add("x_m", Value::number(l.x_m()))
      .add("y_m", Value::number(l.y_m()))
      .add("cov_xx_m2", Value::number(l.cov_xx_m2()))
      .add("cov_xy_m2", Value::number(l.cov_xy_m2()))
      .add("cov_yy_m2", Value::number(l.cov_yy_m2()))
      .add("times_observed", Value::unsigned_integer(l.times_observed()));
  return v;
}

Value true_landmark_value(const msg::TrueLandmark& l) {
  Value v = Value::structure();
  v.add("landmark_id", Value::integer(l.landmark_id()))
      .add("x_m", Value::number(l.x_m()))
      .add("y_m", Value::number(l.y_m()));
  return v;
}

Value keyframe_value(const msg::OptimisedKeyframe& k) {
  Value v = Value::structure();
  v.add("stamp_ns", Value::unsigned_integer(k.stamp_ns())).add("pose", pose_value(k.pose()));
  return v;
}

Value optimised_landmark_value(const msg::OptimisedLandmark& l) {
  Value v = Value::structure();
  v.add("landmark_id", Value::integer(l.landmark_id()))
      .add("x_m", Value::number(l.x_m()))
      .add("y_m", Value::number(l.y_m()))
      .add("cov_xx_m2", Value::number(l.cov_xx_m2()))
      .add("cov_xy_m2", Value::number(l.cov_xy_m2()))
      .add("cov_yy_m2", Value::number(l.cov_yy_m2()))
      .add("observations", Value::unsigned_integer(l.observations()));
  return v;
}

bool is_scalar(const Value& v) { return v.kind() != Value::Kind::kStruct && v.kind() != Value::Kind::kList; }

// JSON string literal (also a valid YAML double-quoted scalar). The text comes
// from the network: control characters (C0, DEL, C1, and U+2028, U+2029,
// U+FFFE, U+FFFF for YAML readers) are escaped, so none
// reaches the reader's terminal, and bytes that are not UTF-8 become U+FFFD,
// so the output stays valid JSON.
std::string quoted(const std::string& s) {
  std::string out = "\"";
  std::size_t i = 0;
  while (i < s.size()) {
    char32_t cp = 0;
    const std::size_t length = dds::utf8_sequence(s, i, &cp);
    if (length == 0) {
      out += "\\ufffd";
      ++i;
      continue;
    }
    switch (cp) {
      case '"': out += "\\\""; break;
      case '\\': out += "\\\\"; break;
      case '\n': out += "\\n"; break;
      case '\r': out += "\\r"; break;
      case '\t': out += "\\t"; break;
      default:
        // Also the characters YAML 1.1 readers take as line breaks or refuse.
        if (dds::control_code_point(cp) || cp == 0x2028 || cp == 0x2029 || cp == 0xfffe || cp == 0xffff) {
          char buf[8];
          std::snprintf(buf, sizeof(buf), "\\u%04x", static_cast<unsigned>(cp));
          out += buf;
        } else {
          out.append(s, i, length);
        }
    }
    i += length;
  }
  return out + "\"";
}

std::string scalar_text(const Value& v, bool json) {
  switch (v.kind()) {
    case Value::Kind::kFloat: {
      const double d = v.float_value();
      if (std::isnan(d)) return json ? "null" : ".nan";
      if (std::isinf(d)) return json ? "null" : (d > 0 ? ".inf" : "-.inf");
      return format_double(d);
    }
    case Value::Kind::kInt: return std::to_string(v.int_value());
    case Value::Kind::kUInt: return std::to_string(v.uint_value());
    case Value::Kind::kBool: return v.bool_value() ? "true" : "false";
    case Value::Kind::kString: return quoted(v.string_value());
    default: return "";
  }
}

void write_json(const Value& v, std::string& out) {
  if (v.kind() == Value::Kind::kStruct) {
    out += '{';
    bool first = true;
    for (const auto& [name, field] : v.fields()) {
      if (!first) out += ',';
      first = false;
      out += quoted(name);
      out += ':';
      write_json(field, out);
    }
    out += '}';
  } else if (v.kind() == Value::Kind::kList) {
    out += '[';
    for (std::size_t i = 0; i < v.items().size(); ++i) {
      if (i > 0) out += ',';
      write_json(v.items()[i], out);
    }
    out += ']';
  } else {
    out += scalar_text(v, true);
  }
}

// Flow-style list of scalars: [1, 2, 3].
std::string flow_list(const Value& v) {
  std::string out = "[";
  for (std::size_t i = 0; i < v.items().size(); ++i) {
    if (i > 0) out += ", ";
    out += scalar_text(v.items()[i], false);
  }
  return out + "]";
}

bool all_scalars(const Value& list) {
  return std::all_of(list.items().begin(), list.items().end(), [](const Value& i) { return is_scalar(i); });
}

void write_yaml_mapping(const Value& v, int indent, bool first_line_prefixed, std::string& out);

// "name: value" lines for one field at `indent`.
void write_yaml_field(const std::string& name, const Value& field, int indent, std::string& out) {
  out += name;
  out += ':';
  if (is_scalar(field)) {
    out += ' ' + scalar_text(field, false) + '\n';
  } else if (field.kind() == Value::Kind::kStruct) {
    if (field.fields().empty()) {
      out += " {}\n";
      return;
    }
    out += '\n';
    write_yaml_mapping(field, indent + 2, false, out);
  } else if (field.items().empty() || all_scalars(field)) {
    out += ' ' + flow_list(field) + '\n';
  } else {
    out += '\n';
    for (const Value& item : field.items()) {
      out.append(static_cast<std::size_t>(indent + 2), ' ');
      out += "- ";
      if (item.kind() == Value::Kind::kStruct && !item.fields().empty()) {
        write_yaml_mapping(item, indent + 4, true, out);
      } else if (item.kind() == Value::Kind::kList) {
        out += flow_list(item) + '\n';  // no nested lists of structs in the IDL
      } else {
        out += (item.kind() == Value::Kind::kStruct ? std::string("{}") : scalar_text(item, false)) + '\n';
      }
    }
  }
}

// The fields of a struct, one per line at `indent`; the first without its
// indentation when the caller already wrote "- ".
void write_yaml_mapping(const Value& v, int indent, bool first_line_prefixed, std::string& out) {
  bool first = true;
  for (const auto& [name, field] : v.fields()) {
    if (!(first && first_line_prefixed)) out.append(static_cast<std::size_t>(indent), ' ');
    first = false;
    write_yaml_field(name, field, indent, out);
  }
}

}  // namespace

Value to_value(const msg::Odometry& m) {
  Value v = Value::structure();
  v.add("header", header_value(m.header()))
      .add("v_mps", Value::number(m.v_mps()))
      .add("w_radps", Value::number(m.w_radps()))
      .add("period_s", Value::number(m.period_s()))
      .add("distance_m", Value::number(m.distance_m()))
      .add("rotation_rad", Value::number(m.rotation_rad()))
      .add("encoder_samples", Value::unsigned_integer(m.encoder_samples()));
  return v;
}

Value to_value(const msg::LandmarkObservation& m) {
  Value v = Value::structure();
  v.add("header", header_value(m.header()))
      .add("camera_frame", Value::unsigned_integer(m.camera_frame()))
      .add("blocks_in_frame", Value::unsigned_integer(m.blocks_in_frame()))
      .add("blocks_rejected", Value::unsigned_integer(m.blocks_rejected()))
      .add("detections", list_of(m.detections(), detection_value));
  return v;
}

Value to_value(const msg::MapState& m) {
  Value v = Value::structure();
  v.add("header", header_value(m.header()))
      .add("mean_pose", pose_value(m.mean_pose()))
      .add("pose_covariance", list_of(m.pose_covariance(), Value::number))
      .add("best_pose", pose_value(m.best_pose()))
      .add("effective_sample_size", Value::number(m.effective_sample_size()))
      .add("particle_count", Value::unsigned_integer(m.particle_count()))
      .add("particle_poses", list_of(m.particle_poses(), pose_value))
      .add("landmarks", list_of(m.landmarks(), landmark_estimate_value))
      .add("update_time_s", Value::number(m.update_time_s()))
      .add("odometry_sequence", Value::unsigned_integer(m.odometry_sequence()))
      .add("observation_sequence", Value::unsigned_integer(m.observation_sequence()))
      .add("observations_used", Value::unsigned_integer(m.observations_used()))
      .add("observations_gated", Value::unsigned_integer(m.observations_gated()))
      .add("observations_new_landmark", Value::unsigned_integer(m.observations_new_landmark()))
      .add("samples_late", Value::unsigned_integer(m.samples_late()));
  return v;
}

Value to_value(const msg::GroundTruth& m) {
  Value v = Value::structure();
  v.add("header", header_value(m.header()))
      .add("pose", pose_value(m.pose()))
      .add("v_mps", Value::number(m.v_mps()))
      .add("w_radps", Value::number(m.w_radps()))
      .add("landmarks", list_of(m.landmarks(), true_landmark_value));
  return v;
}

Value to_value(const msg::Diagnostics& m) {
  Value v = Value::structure();
  v.add("header", header_value(m.header()))
      .add("process", Value::string(m.process()))
      .add("pid", Value::unsigned_integer(m.pid()))
      .add("level", Value::unsigned_integer(m.level()))
      .add("status", Value::string(m.status()))
      .add("uptime_s", Value::number(m.uptime_s()))
      .add("counters", list_of(m.counters(), [](const msg::DiagnosticCounter& c) {
             Value e = Value::structure();
             e.add("name", Value::string(c.name())).add("value", Value::unsigned_integer(c.value()));
             return e;
           }));
  return v;
}

Value to_value(const msg::OptimisedMap& m) {
  Value v = Value::structure();
  v.add("header", header_value(m.header()))
      .add("current_pose", pose_value(m.current_pose()))
      .add("keyframe_count", Value::unsigned_integer(m.keyframe_count()))
      .add("keyframes", list_of(m.keyframes(), keyframe_value))
      .add("landmarks", list_of(m.landmarks(), optimised_landmark_value))
      .add("whole_problem", Value::boolean(m.whole_problem()))
      .add("converged", Value::boolean(m.converged()))
      .add("iterations", Value::unsigned_integer(m.iterations()))
      .add("initial_cost", Value::number(m.initial_cost()))
      .add("final_cost", Value::number(m.final_cost()))
      .add("solve_time_s", Value::number(m.solve_time_s()))
      .add("cpu_time_s", Value::number(m.cpu_time_s()))
      .add("keyframes_free", Value::unsigned_integer(m.keyframes_free()))
      .add("residuals", Value::unsigned_integer(m.residuals()))
      .add("odometry_sequence", Value::unsigned_integer(m.odometry_sequence()))
      .add("observation_sequence", Value::unsigned_integer(m.observation_sequence()));
  return v;
}

Value to_value(const msg::RobotSighting& m) {
  Value v = Value::structure();
  v.add("header", header_value(m.header()))
      .add("detections", list_of(m.detections(), [](const msg::RobotDetection& d) {
             Value e = Value::structure();
             e.add("seen_robot_id", Value::string(d.seen_robot_id()))
                 .add("range_m", Value::number(d.range_m()))
                 .add("bearing_rad", Value::number(d.bearing_rad()))
                 .add("range_sigma_m", Value::number(d.range_sigma_m()))
                 .add("bearing_sigma_rad", Value::number(d.bearing_sigma_rad()));
             return e;
           }));
  return v;
}

Value to_value(const msg::FleetMap& m) {
  Value v = Value::structure();
  v.add("header", header_value(m.header()))
      .add("landmarks", list_of(m.landmarks(), [](const msg::FleetLandmark& l) {
             Value e = Value::structure();
             e.add("landmark_id", Value::integer(l.landmark_id()))
                 .add("x_m", Value::number(l.x_m()))
                 .add("y_m", Value::number(l.y_m()))
                 .add("cov_xx_m2", Value::number(l.cov_xx_m2()))
                 .add("cov_xy_m2", Value::number(l.cov_xy_m2()))
                 .add("cov_yy_m2", Value::number(l.cov_yy_m2()))
                 .add("robots", Value::unsigned_integer(l.robots()));
             return e;
           }))
      .add("robots", list_of(m.robots(), [](const msg::RobotFrameCheck& c) {
             Value e = Value::structure();
             e.add("robot_id", Value::string(c.robot_id()))
                 .add("map_stamp_ns", Value::unsigned_integer(c.map_stamp_ns()))
                 .add("landmarks", Value::unsigned_integer(c.landmarks()))
                 .add("common", Value::unsigned_integer(c.common()))
                 .add("verdict", Value::string(c.verdict()))
                 .add("f_statistic", Value::number(c.f_statistic()))
                 .add("threshold", Value::number(c.threshold()))
                 .add("offset_m", Value::number(c.offset_m()))
                 .add("rotation_rad", Value::number(c.rotation_rad()))
                 .add("residual_m", Value::number(c.residual_m()))
                 .add("fused", Value::boolean(c.fused()))
                 .add("moved_rotation_rad", Value::number(c.moved_rotation_rad()))
                 .add("moved_shift_m", Value::number(c.moved_shift_m()));
             return e;
           }));
  return v;
}

std::string diagnostics_table(std::vector<msg::Diagnostics> reports) {
  std::sort(reports.begin(), reports.end(), [](const msg::Diagnostics& a, const msg::Diagnostics& b) {
    return std::make_tuple(a.header().robot_id(), a.process(), a.pid()) <
           std::make_tuple(b.header().robot_id(), b.process(), b.pid());
  });
  static const char* const kLevels[] = {"OK", "WARN", "ERROR"};
  std::string out;
  for (const msg::Diagnostics& d : reports) {
    char head[256];
    // Every text in a report is another participant's: no control byte reaches the terminal.
    std::snprintf(head, sizeof(head), "%s %s (pid %u): %s, up %.0f s", dds::printable(d.header().robot_id()).c_str(),
                  dds::printable(d.process()).c_str(), static_cast<unsigned>(d.pid()),
                  d.level() < 3 ? kLevels[d.level()] : "?", d.uptime_s());
    out += head;
    if (!d.status().empty()) out += ": " + dds::printable(d.status(), 240);
    out += "\n";
    std::string line = "   ";
    for (const msg::DiagnosticCounter& c : d.counters()) {
      const std::string item = " " + dds::printable(c.name()) + " " + std::to_string(c.value());
      if (line.size() + item.size() > 100) {
        out += line + "\n";
        line = "   ";
      }
      line += item;
    }
    if (line.size() > 3) out += line + "\n";
  }
  return out;
}

std::string format_double(double v) {
  char buf[64];
  const auto result = std::to_chars(buf, buf + sizeof(buf), v);
  return std::string(buf, result.ptr);
}

std::string to_yaml_document(const Value& value) {
  std::string out = "---\n";
  if (value.kind() == Value::Kind::kStruct) {
    write_yaml_mapping(value, 0, false, out);
  } else {
    write_yaml_field("value", value, 0, out);
  }
  return out;
}

std::string to_json_line(const Value& value) {
  std::string out;
  write_json(value, out);
  return out;
}

namespace {

std::string without_indices(const std::string& path) {
  std::string out;
  bool in_index = false;
  for (char c : path) {
    if (c == '[') in_index = true;
    if (!in_index) out += c;
    if (c == ']') in_index = false;
  }
  return out;
}

bool same_scalar(const Value& a, const Value& b, double tolerance) {
  if (a.kind() != b.kind()) return false;
  switch (a.kind()) {
    case Value::Kind::kFloat: {
      const double x = a.float_value();
      const double y = b.float_value();
      if (std::isnan(x) || std::isnan(y)) return std::isnan(x) && std::isnan(y);
      if (tolerance == 0.0) return x == y;
      return std::abs(x - y) <= tolerance * std::max({1.0, std::abs(x), std::abs(y)});
    }
    case Value::Kind::kInt:
      return a.int_value() == b.int_value();
    case Value::Kind::kUInt:
    case Value::Kind::kBool:
      return a.uint_value() == b.uint_value();
    default:
      return a.string_value() == b.string_value();
  }
}

struct Comparison {
  const std::vector<std::string>& ignored;
  double tolerance;
  std::size_t max_lines;
  std::vector<std::string> lines;

  bool skipped(const std::string& path) const {
    return std::find(ignored.begin(), ignored.end(), path) != ignored.end() ||
           std::find(ignored.begin(), ignored.end(), without_indices(path)) != ignored.end();
  }
  void differ(const std::string& path, const std::string& what) {
    if (lines.size() < max_lines) lines.push_back(path + ": " + what);
  }
  void compare(const Value& a, const Value& b, const std::string& path) {
    if (lines.size() >= max_lines || (!path.empty() && skipped(path))) return;
    if (a.kind() != b.kind()) return differ(path, "different kinds of value");
    if (a.kind() == Value::Kind::kStruct) {
      for (const auto& [name, field] : a.fields()) {
        const std::string child = path.empty() ? name : path + "." + name;
        const Value* other = b.find(name);
        if (other == nullptr) {
          if (!skipped(child)) differ(child, "missing in the second");
          continue;
        }
        compare(field, *other, child);
      }
    } else if (a.kind() == Value::Kind::kList) {
      if (a.items().size() != b.items().size()) {
        return differ(path, std::to_string(a.items().size()) + " items != " + std::to_string(b.items().size()));
      }
      for (std::size_t i = 0; i < a.items().size(); ++i) {
        compare(a.items()[i], b.items()[i], path + "[" + std::to_string(i) + "]");
      }
    } else if (!same_scalar(a, b, tolerance)) {
      differ(path, scalar_text(a, false) + " != " + scalar_text(b, false));
    }
  }
};

}  // namespace

MessagePairs pair_messages(const std::vector<Value>& first, const std::vector<Value>& second,
                           const std::vector<std::string>& key_fields) {
  MessagePairs out;
  if (key_fields.empty()) {
    const std::size_t n = std::min(first.size(), second.size());
    for (std::size_t i = 0; i < n; ++i) out.pairs.emplace_back(i, i);
    for (std::size_t i = n; i < first.size(); ++i) out.only_first.push_back(i);
    for (std::size_t i = n; i < second.size(); ++i) out.only_second.push_back(i);
    return out;
  }
  const auto key_of = [&](const Value& v) {
    std::string key;
    for (const std::string& f : key_fields) {
      const Value* field = v.find(f);
      key += (field ? to_json_line(*field) : std::string("-")) + "\x1f";
    }
    return key;
  };
  std::map<std::string, std::deque<std::size_t>> waiting;  // second's indices by key, in order
  for (std::size_t j = 0; j < second.size(); ++j) waiting[key_of(second[j])].push_back(j);
  std::vector<bool> paired(second.size(), false);
  for (std::size_t i = 0; i < first.size(); ++i) {
    auto it = waiting.find(key_of(first[i]));
    if (it == waiting.end() || it->second.empty()) {
      out.only_first.push_back(i);
      continue;
    }
    out.pairs.emplace_back(i, it->second.front());
    paired[it->second.front()] = true;
    it->second.pop_front();
  }
  for (std::size_t j = 0; j < second.size(); ++j) {
    if (!paired[j]) out.only_second.push_back(j);
  }
  return out;
}

std::size_t pairs_before_first_unmatched(const MessagePairs& p) {
  const std::size_t none = std::numeric_limits<std::size_t>::max();
  const std::size_t first = p.only_first.empty() ? none : p.only_first.front();
  const std::size_t second = p.only_second.empty() ? none : p.only_second.front();
  std::size_t k = 0;
  while (k < p.pairs.size() && p.pairs[k].first < first && p.pairs[k].second < second) ++k;
  return k;
}

bool until_unmatched_passes(std::size_t pairs, std::size_t differing_before, std::size_t differing_after) {
  if (differing_before > 0 || differing_after > pairs) return false;
  return 2 * (pairs - differing_after) >= pairs;
}

std::vector<std::string> compare_values(const Value& a, const Value& b, const std::vector<std::string>& ignored,
                                        double tolerance, std::size_t max_lines) {
  Comparison comparison{ignored, tolerance, max_lines, {}};
  comparison.compare(a, b, "");
  return comparison.lines;
}

void GapAccumulator::add(double t_s) {
  if (messages_++ > 0) {
    const double gap = t_s - last_s_;
    const auto n = static_cast<double>(messages_ - 1);  // gaps so far, this one included
    if (messages_ == 2) {
      min_s_ = max_s_ = gap;
    } else {
      min_s_ = std::min(min_s_, gap);
      max_s_ = std::max(max_s_, gap);
    }
    const double delta = gap - mean_s_;
    mean_s_ += delta / n;
    m2_ += delta * (gap - mean_s_);
  }
  last_s_ = t_s;
}

GapStats GapAccumulator::stats() const {
  GapStats s;
  s.messages = messages_;
  if (messages_ < 2) return s;
  s.mean_s = mean_s_;
  s.min_s = min_s_;
  s.max_s = max_s_;
  s.std_s = std::sqrt(std::max(0.0, m2_ / static_cast<double>(messages_ - 1)));
  s.rate_hz = s.mean_s > 0.0 ? 1.0 / s.mean_s : 0.0;
  return s;
}

GapStats gap_stats(const std::vector<double>& arrivals_s) {
  GapAccumulator a;
  for (const double t : arrivals_s) a.add(t);
  return a.stats();
}

bool field_path_exists(const Value& message, const std::string& path) {
  const std::string plain = without_indices(path);
  const Value* at = &message;
  std::size_t start = 0;
  while (start <= plain.size()) {
    while (at->kind() == Value::Kind::kList) {
      if (at->items().empty()) return true;  // nothing to look into
      at = &at->items().front();
    }
    const std::size_t dot = std::min(plain.find('.', start), plain.size());
    const std::string name = plain.substr(start, dot - start);
    if (name.empty() || at->kind() != Value::Kind::kStruct) return false;
    const Value* next = nullptr;
    for (const auto& [field, value] : at->fields()) {
      if (field == name) next = &value;
    }
    if (next == nullptr) return false;
    at = next;
    start = dot + 1;
  }
  return true;
}

}  // namespace pixyslam::log_tool
