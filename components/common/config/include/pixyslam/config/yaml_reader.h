#pragma once

#include <cstddef>
#include <cstdint>
#include <initializer_list>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

#include <yaml-cpp/yaml.h>

namespace pixyslam::config {

// A configuration problem: the message names the file, the full key path, the
// bad value and what was expected, e.g.
//   "config/slam.yaml: key 'filter.particles': value 0 is out of range [1, 1000000]".
class ConfigError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// The largest file from_file() reads by default (1 MiB; the shipped configs are
// a few KiB). Checked before parsing: yaml-cpp needs ~85 bytes of memory per byte
// of YAML, so 48 MB of text took 4 GB.
inline constexpr std::size_t kMaxConfigFileBytes = std::size_t{1} << 20;

// The text of the file at `path` for a YAML parse: a ConfigError naming the file
// if it cannot be opened or read, is not a regular file (a directory, a FIFO, a
// device: "<path>: not a regular file (a directory)") or is larger than
// `max_bytes`. Nothing but ConfigError escapes.
std::string read_config_text(const std::string& path, std::size_t max_bytes = kMaxConfigFileBytes);

// Folder of a file path ("." for a bare file name), for resolving paths that a
// config file gives relative to itself.
std::string folder_of(const std::string& path);

// Typed, validated access to one YAML mapping. Every key read is remembered;
// finish() rejects keys that were never read, so a typo is an error, not a
// silently ignored setting. Children share the file name and extend the key path.
// Thread-compatible.
class YamlReader {
 public:
  // Parses a file read with read_config_text(path, max_bytes); a syntax error
  // names the file, line and column. Both parsers reject a key that appears twice
  // in one mapping anywhere in the document (yaml-cpp would keep both and the
  // first would win): "<file>: key 'a.b': duplicate at line 7 (first at line 3)".
  static YamlReader from_file(const std::string& path, std::size_t max_bytes = kMaxConfigFileBytes);
  // Parses text (tests, embedded defaults); `origin` stands in for a file name.
  static YamlReader from_string(const std::string& text, const std::string& origin);

  YamlReader(YAML::Node node, std::string origin, std::string key_path);

  bool has(const std::string& key) const;
  // The keys of this mapping, in file order (for mappings keyed by data, e.g. ids).
  std::vector<std::string> keys() const;
  // Required sub-mapping; an absent key is an error.
  YamlReader child(const std::string& key);
  // Required list of mappings (key path "key[i]" in errors); may be empty.
  std::vector<YamlReader> mapping_list(const std::string& key);
  // Required list of single values, as text.
  std::vector<std::string> text_list(const std::string& key);

  double number(const std::string& key, double min, double max);
  double number(const std::string& key, double min, double max, double fallback);
  std::int64_t integer(const std::string& key, std::int64_t min, std::int64_t max);
  std::int64_t integer(const std::string& key, std::int64_t min, std::int64_t max,
                       std::int64_t fallback);
  bool boolean(const std::string& key);
  bool boolean(const std::string& key, bool fallback);
  std::string text(const std::string& key);
  std::string text(const std::string& key, const std::string& fallback);
  // A string that must be one of `allowed`.
  std::string choice(const std::string& key, std::initializer_list<const char*> allowed);
  std::string choice(const std::string& key, std::initializer_list<const char*> allowed,
                     const std::string& fallback);
  std::string choice(const std::string& key, const std::vector<std::string>& allowed, const std::string& fallback);

  // Throws ConfigError naming the first key of this mapping that was never read.
  void finish() const;
  // Runs `check` (e.g. validate() of the options read from this mapping); a
  // std::invalid_argument it throws becomes a ConfigError naming the file and
  // this mapping: "<origin>: mapping '<path>': <what>".
  template <class Check>
  void check_mapping(const Check& check) const {
    try {
      check();
    } catch (const std::invalid_argument& e) {
      throw ConfigError(origin_ + ": mapping '" + path_ + "': " + e.what());
    }
  }

  const std::string& origin() const { return origin_; }
  const std::string& path() const { return path_; }
  std::string key_path(const std::string& key) const;
  [[noreturn]] void fail(const std::string& key, const std::string& what) const;

 private:
  YAML::Node scalar(const std::string& key);
  // The text of a mapping key; a ConfigError if the key is not a plain scalar.
  std::string key_text(const YAML::Node& key) const;
  // An absent optional key counts as read and yields `fallback`.
  template <class T, class Read>
  T or_fallback(const std::string& key, const T& fallback, const Read& read) {
    if (!has(key)) {
      used_.insert(key);
      return fallback;
    }
    return read();
  }

  YAML::Node node_;
  std::string origin_;
  std::string path_;
  std::set<std::string> used_;
};

// read() of the file that `key` of config file `path` names (e.g. filter_config):
// a ConfigError from it also names `path` and `key`, which sent the user there.
template <class Read>
auto read_referenced(const std::string& path, const std::string& key, Read read) -> decltype(read()) {
  try {
    return read();
  } catch (const ConfigError& e) {
    throw ConfigError(path + ": " + key + ": " + e.what());
  }
}

}  // namespace pixyslam::config
