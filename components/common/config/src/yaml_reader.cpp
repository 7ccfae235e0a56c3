#include "pixyslam/config/yaml_reader.h"

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <sstream>

namespace pixyslam::config {
namespace {

std::string describe(const YAML::Node& node) {
  if (node.IsScalar()) return "'" + node.Scalar() + "'";
  if (node.IsSequence()) return "a list";
  if (node.IsMap()) return "a mapping";
  return "null";
}

template <class Load>
YamlReader parse(const std::string& origin, const Load& load) {
  try {
    YAML::Node root = load();
    if (root.IsNull()) root = YAML::Node(YAML::NodeType::Map);
    if (!root.IsMap()) throw ConfigError(origin + ": top level must be a mapping of keys");
    return YamlReader(root, origin, "");
  } catch (const YAML::BadFile&) {
    throw ConfigError(origin + ": cannot open file");
  } catch (const YAML::ParserException& e) {
    std::ostringstream os;
    os << origin << ": YAML syntax error at line " << e.mark.line + 1 << ", column "
       << e.mark.column + 1 << ": " << e.msg;
    throw ConfigError(os.str());
  }
}

}  // namespace

YamlReader YamlReader::from_file(const std::string& path) {
  return parse(path, [&] { return YAML::LoadFile(path); });
}

YamlReader YamlReader::from_string(const std::string& text, const std::string& origin) {
  return parse(origin, [&] { return YAML::Load(text); });
}

YamlReader::YamlReader(YAML::Node node, std::string origin, std::string key_path)
    : node_(std::move(node)), origin_(std::move(origin)), path_(std::move(key_path)) {}

std::string YamlReader::key_path(const std::string& key) const {
  return path_.empty() ? key : path_ + "." + key;
}

void YamlReader::fail(const std::string& key, const std::string& what) const {
  throw ConfigError(origin_ + ": key '" + key_path(key) + "': " + what);
}

bool YamlReader::has(const std::string& key) const { return static_cast<bool>(node_[key]); }

std::string YamlReader::key_text(const YAML::Node& key) const {
  if (key.IsScalar()) return key.Scalar();
  // YAML allows a mapping or a sequence as a key ("? [a, b]: 1"); no option is one.
  const YAML::Mark mark = key.Mark();
  const std::string where = mark.is_null() ? std::string("?") : std::to_string(mark.line + 1);
  throw ConfigError(origin_ + ": mapping '" + path() + "': a key at line " + where + " is " + describe(key) +
                    ", not a plain name");
}

std::vector<std::string> YamlReader::keys() const {
  std::vector<std::string> out;
  for (const auto& kv : node_) out.push_back(key_text(kv.first));
  return out;
}

YamlReader YamlReader::child(const std::string& key) {
  used_.insert(key);
  YAML::Node n = node_[key];
  if (!n) fail(key, "missing (a mapping is required)");
  if (!n.IsMap()) fail(key, "expected a mapping, got " + describe(n));
  return YamlReader(n, origin_, key_path(key));
}

std::vector<YamlReader> YamlReader::mapping_list(const std::string& key) {
  used_.insert(key);
  YAML::Node n = node_[key];
  if (!n) fail(key, "missing (a list is required)");
  if (!n.IsSequence()) fail(key, "expected a list, got " + describe(n));
  std::vector<YamlReader> out;
  for (std::size_t i = 0; i < n.size(); ++i) {
    const std::string item = key + "[" + std::to_string(i) + "]";
    if (!n[i].IsMap()) fail(item, "expected a mapping, got " + describe(n[i]));
    out.emplace_back(n[i], origin_, key_path(item));
  }
  return out;
}

std::vector<std::string> YamlReader::text_list(const std::string& key) {
  used_.insert(key);
  YAML::Node n = node_[key];
  if (!n) fail(key, "missing (a list is required)");
  if (!n.IsSequence()) fail(key, "expected a list, got " + describe(n));
  std::vector<std::string> out;
  for (std::size_t i = 0; i < n.size(); ++i) {
    if (!n[i].IsScalar()) fail(key + "[" + std::to_string(i) + "]", "expected a single value, got " + describe(n[i]));
    out.push_back(n[i].Scalar());
  }
  return out;
}

YAML::Node YamlReader::scalar(const std::string& key) {
  used_.insert(key);
  YAML::Node n = node_[key];
  if (!n) fail(key, "missing (required)");
  if (!n.IsScalar()) fail(key, "expected a single value, got " + describe(n));
  return n;
}

double YamlReader::number(const std::string& key, double min, double max) {
  const std::string s = scalar(key).Scalar();
  errno = 0;
  char* end = nullptr;
  const double v = std::strtod(s.c_str(), &end);
  if (s.empty() || end != s.c_str() + s.size() || errno == ERANGE || !std::isfinite(v)) {
    fail(key, "expected a finite number, got '" + s + "'");
  }
  if (v < min || v > max) {
    std::ostringstream os;
    os << "value " << s << " is out of range [" << min << ", " << max << "]";
    fail(key, os.str());
  }
  return v;
}

double YamlReader::number(const std::string& key, double min, double max, double fallback) {
  return or_fallback(key, fallback, [&] { return number(key, min, max); });
}

std::int64_t YamlReader::integer(const std::string& key, std::int64_t min, std::int64_t max) {
  const std::string s = scalar(key).Scalar();
  errno = 0;
  char* end = nullptr;
  const long long v = std::strtoll(s.c_str(), &end, 10);
  if (s.empty() || end != s.c_str() + s.size() || errno == ERANGE) {
    fail(key, "expected an integer, got '" + s + "'");
  }
  if (v < min || v > max) {
    std::ostringstream os;
    os << "value " << s << " is out of range [" << min << ", " << max << "]";
    fail(key, os.str());
  }
  return v;
}

std::int64_t YamlReader::integer(const std::string& key, std::int64_t min, std::int64_t max,
                                 std::int64_t fallback) {
  return or_fallback(key, fallback, [&] { return integer(key, min, max); });
}

bool YamlReader::boolean(const std::string& key) {
  const std::string s = scalar(key).Scalar();
  if (s == "true") return true;
  if (s == "false") return false;
  fail(key, "expected true or false, got '" + s + "'");
}

bool YamlReader::boolean(const std::string& key, bool fallback) {
  return or_fallback(key, fallback, [&] { return boolean(key); });
}

std::string YamlReader::text(const std::string& key) { return scalar(key).Scalar(); }

std::string YamlReader::text(const std::string& key, const std::string& fallback) {
  return or_fallback(key, fallback, [&] { return text(key); });
}

std::string YamlReader::choice(const std::string& key, std::initializer_list<const char*> allowed) {
  const std::string s = text(key);
  std::string list;
  for (const char* a : allowed) {
    if (s == a) return s;
    list += list.empty() ? a : std::string(", ") + a;
  }
  fail(key, "value '" + s + "' is not one of: " + list);
}

std::string YamlReader::choice(const std::string& key, std::initializer_list<const char*> allowed,
                               const std::string& fallback) {
  return or_fallback(key, fallback, [&] { return choice(key, allowed); });
}

void YamlReader::finish() const {
  for (const auto& kv : node_) {
    const std::string key = key_text(kv.first);
    if (!used_.count(key)) fail(key, "unknown key (check the spelling; see the documented options)");
  }
}

}  // namespace pixyslam::config
