#include "pixyslam/config/yaml_reader.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <map>
#include <sstream>
#include <utility>
#include <vector>

namespace pixyslam::config {
namespace {

// What a non-regular file is, for the error message.
const char* file_kind(mode_t mode) {
  if (S_ISDIR(mode)) return "a directory";
  if (S_ISFIFO(mode)) return "a pipe";
  if (S_ISCHR(mode)) return "a character device";
  if (S_ISBLK(mode)) return "a block device";
  if (S_ISSOCK(mode)) return "a socket";
  return "not a plain file";
}

[[noreturn]] void fail_not_regular(const std::string& path, mode_t mode) {
  throw ConfigError(path + ": not a regular file (" + file_kind(mode) + ")");
}

[[noreturn]] void fail_too_large(const std::string& path, unsigned long long size, std::size_t max_bytes) {
  throw ConfigError(path + ": file is " + std::to_string(size) + " bytes, more than the limit of " +
                    std::to_string(max_bytes) + " bytes for a configuration file");
}

class FileDescriptor {
 public:
  explicit FileDescriptor(int fd) : fd_(fd) {}
  ~FileDescriptor() {
    if (fd_ >= 0) ::close(fd_);
  }
  FileDescriptor(const FileDescriptor&) = delete;
  FileDescriptor& operator=(const FileDescriptor&) = delete;
  int get() const { return fd_; }

 private:
  int fd_;
};

// The line of a mark, 1-based ("?" for a node built in code).
std::string line_of(const YAML::Mark& mark) {
  return mark.is_null() ? std::string("?") : std::to_string(mark.line + 1);
}

// Throws a ConfigError for the first key that appears twice in one mapping,
// anywhere in the document. yaml-cpp keeps both entries of a duplicated key
// (a lookup finds the first), so this walks every mapping's entries. Iterative
// (no recursion on nesting), and every container is walked once: an alias
// (*name) is the anchored node itself, recognised by its position in the text,
// so neither "billion laughs" nor a self-referencing anchor multiplies the work.
void reject_duplicate_keys(const YAML::Node& root, const std::string& origin) {
  std::vector<std::pair<YAML::Node, std::string>> pending{{root, ""}};
  std::set<std::pair<int, int>> visited;  // (position, type) of walked containers
  while (!pending.empty()) {
    const YAML::Node node = pending.back().first;
    const std::string path = std::move(pending.back().second);
    pending.pop_back();
    if (!node.IsMap() && !node.IsSequence()) continue;
    const YAML::Mark mark = node.Mark();
    if (!mark.is_null() && !visited.insert({mark.pos, static_cast<int>(node.Type())}).second) continue;
    if (node.IsSequence()) {
      for (std::size_t i = 0; i < node.size(); ++i) {
        pending.emplace_back(node[i], path + "[" + std::to_string(i) + "]");
      }
      continue;
    }
    std::map<std::string, YAML::Mark> seen;
    for (const auto& kv : node) {
      // A mapping or list used as a key is reported by key_text() when read.
      if (!kv.first.IsScalar()) continue;
      const std::string& key = kv.first.Scalar();
      const std::string key_path = path.empty() ? key : path + "." + key;
      const auto [first, inserted] = seen.emplace(key, kv.first.Mark());
      if (!inserted) {
        const YAML::Mark& a = first->second;
        const YAML::Mark& b = kv.first.Mark();
        // Both on one line ("{a: 1, a: 2}"): the columns tell them apart.
        const bool same_line = !a.is_null() && !b.is_null() && a.line == b.line;
        auto where = [&](const YAML::Mark& m) {
          return "line " + line_of(m) + (same_line ? ", column " + std::to_string(m.column + 1) : std::string());
        };
        throw ConfigError(origin + ": key '" + key_path + "': duplicate at " + where(b) + " (first at " + where(a) +
                          ")");
      }
      pending.emplace_back(kv.second, key_path);
    }
  }
}

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
    reject_duplicate_keys(root, origin);
    return YamlReader(root, origin, "");
  } catch (const YAML::ParserException& e) {
    std::ostringstream os;
    os << origin << ": YAML syntax error at line " << e.mark.line + 1 << ", column "
       << e.mark.column + 1 << ": " << e.msg;
    throw ConfigError(os.str());
  }
}

}  // namespace

std::string folder_of(const std::string& path) {
  const auto slash = path.find_last_of('/');
  if (slash == std::string::npos) return ".";
  return slash == 0 ? "/" : path.substr(0, slash);
}

std::string read_config_text(const std::string& path, std::size_t max_bytes) {
  // stat() first: a directory, FIFO or device is never opened (opening a FIFO
  // would wait for a writer); fstat() of the open file closes the race.
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) {
    throw ConfigError(path + ": cannot open file (" + std::strerror(errno) + ")");
  }
  if (!S_ISREG(st.st_mode)) fail_not_regular(path, st.st_mode);
  const FileDescriptor fd(::open(path.c_str(), O_RDONLY | O_CLOEXEC | O_NOCTTY | O_NONBLOCK));
  if (fd.get() < 0) throw ConfigError(path + ": cannot open file (" + std::strerror(errno) + ")");
  if (::fstat(fd.get(), &st) != 0) throw ConfigError(path + ": cannot read file (" + std::strerror(errno) + ")");
  if (!S_ISREG(st.st_mode)) fail_not_regular(path, st.st_mode);
  if (static_cast<unsigned long long>(st.st_size) > max_bytes) {
    fail_too_large(path, static_cast<unsigned long long>(st.st_size), max_bytes);
  }
  // Read at most max_bytes + 1: a file that grew since fstat() is still caught.
  std::string text(static_cast<std::size_t>(st.st_size) + 1, '\0');
  std::size_t done = 0;
  for (;;) {
    if (done == text.size()) {
      if (text.size() > max_bytes) fail_too_large(path, text.size(), max_bytes);
      text.resize(std::min(max_bytes + 1, text.size() * 2));
    }
    const ssize_t n = ::read(fd.get(), &text[done], text.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) throw ConfigError(path + ": cannot read file (" + std::strerror(errno) + ")");
    if (n == 0) break;
    done += static_cast<std::size_t>(n);
  }
  text.resize(done);
  return text;
}

YamlReader YamlReader::from_file(const std::string& path, std::size_t max_bytes) {
  const std::string text = read_config_text(path, max_bytes);
  return parse(path, [&] { return YAML::Load(text); });
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

std::string YamlReader::choice(const std::string& key, const std::vector<std::string>& allowed,
                               const std::string& fallback) {
  return or_fallback(key, fallback, [&] {
    const std::string s = text(key);
    std::string list;
    for (const std::string& a : allowed) {
      if (s == a) return s;
      list += list.empty() ? a : ", " + a;
    }
    fail(key, "value '" + s + "' is not one of: " + list);
  });
}

void YamlReader::finish() const {
  for (const auto& kv : node_) {
    const std::string key = key_text(kv.first);
    if (!used_.count(key)) fail(key, "unknown key (check the spelling; see the documented options)");
  }
}

}  // namespace pixyslam::config
