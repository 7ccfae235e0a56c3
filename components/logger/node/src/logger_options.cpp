#include "pixyslam/logger_node/logger_options.h"

#include <algorithm>
#include <cstdio>
#include <sstream>
#include <utility>

#include "pixyslam/config/yaml_reader.h"
#include "pixyslam/config/parameters_yaml.h"
#include "pixyslam/dds/cdr_payload.h"
#include "pixyslam/dds/topic_config.h"

namespace pixyslam::logger_node {

mcap::McapCompression default_compression() {
  return mcap::mcap_compression_available(mcap::McapCompression::kZstd) ? mcap::McapCompression::kZstd
                                                                            : mcap::McapCompression::kNone;
}

namespace {

constexpr std::uint64_t kMinRotateSizeBytes = 65536;

std::string compression_name(mcap::McapCompression c) {
  return c == mcap::McapCompression::kNone ? "none" : mcap::mcap_compression_name(c);
}

}  // namespace

bool rotation_enabled(const LoggerOptions& options) {
  return options.rotate_size_bytes > 0 || options.rotate_period_s > 0.0;
}

const parameters::Table<LoggerOptions>& logger_parameters() {
  using O = LoggerOptions;
  using C = mcap::McapCompression;
  namespace P = parameters;
  static const P::Table<O> table = {
      P::text<O>("output_file", "the MCAP file (kept if it holds data: the name after the highest indexed one is used)",
                 [](O& o) -> std::string& { return o.output_file; },
                 [](const std::string& v) {
                   if (v.empty()) throw std::invalid_argument("empty");
                 }),
      P::integer<O, std::uint64_t>("rotate_size_bytes", 0, std::uint64_t{1} << 40, "B",
                                   "a new file once this one holds this many bytes (0: never, else >= 65536)",
                                   [](O& o) -> std::uint64_t& { return o.rotate_size_bytes; }),
      P::real<O>("rotate_period_s", 0.0, 7 * 86400.0, "s", "a new file after this long (0: never, else >= 1)",
                 [](O& o) -> double& { return o.rotate_period_s; }),
      P::integer<O, std::size_t>("keep_files", 0, 1000000, "",
                                 "with rotation, this run's newest files kept; older ones deleted (0: all)",
                                 [](O& o) -> std::size_t& { return o.keep_files; }),
      P::integer<O, std::size_t>("chunk_size_bytes", 4096, std::size_t{1} << 28, "B",
                                 "uncompressed bytes per MCAP chunk",
                                 [](O& o) -> std::size_t& { return o.chunk_size_bytes; }),
      P::choice<O, C>("compression", {{"none", C::kNone}, {"zstd", C::kZstd}, {"lz4", C::kLz4}},
                      "chunk compression (zstd and lz4 when built with them)",
                      [](O& o) -> C& { return o.compression; }),
      P::real<O>("flush_period_s", 0.0, 3600.0, "s", "the open chunk written at least this often (0: when full)",
                 [](O& o) -> double& { return o.flush_period_s; }),
      P::boolean<O>("fsync", "fsync(2) after every chunk (survives a power cut)", [](O& o) -> bool& { return o.fsync; }),
      P::integer<O, std::size_t>("queue_max_bytes", std::size_t{1} << 20, P::kMaxBytes4GiB, "B",
                                 "payload bytes waiting for the writer; beyond: dropped and counted",
                                 [](O& o) -> std::size_t& { return o.queue_max_bytes; }),
      P::real<O>("retry_period_s", 0.1, 3600.0, "s", "after a write failure, a new file tried this often",
                 [](O& o) -> double& { return o.retry_period_s; }),
      P::text<O>("fallback_dir", "folder tried in turn with the output file's after a failure ('': none)",
                 [](O& o) -> std::string& { return o.fallback_dir; }),
  };
  return table;
}

void validate(const LoggerOptions& o) {
  parameters::check_ranges(o, logger_parameters(), "logger");
  if (o.rotate_size_bytes != 0 && o.rotate_size_bytes < kMinRotateSizeBytes) {
    throw parameters::RuleError("logger", "rotate_size_bytes",
                                "value " + std::to_string(o.rotate_size_bytes) + " is too small: 0 (off) or at least " +
                                    std::to_string(kMinRotateSizeBytes));
  }
  if (o.rotate_period_s != 0.0 && o.rotate_period_s < 1.0) {
    throw parameters::RuleError("logger", "rotate_period_s",
                                "value " + parameters::number_text(o.rotate_period_s) +
                                    " is too small: 0 (off) or at least 1");
  }
  if (o.keep_files > 0 && !rotation_enabled(o)) {
    throw parameters::RuleError("logger", "keep_files",
                                "value " + std::to_string(o.keep_files) +
                                    " needs rotation (rotate_size_bytes or rotate_period_s): one file is never deleted");
  }
  if (!mcap::mcap_compression_available(o.compression)) {
    const std::string name = compression_name(o.compression);
    throw parameters::RuleError("logger", "compression",
                                "'" + name + "' is not available in this build (install lib" + name +
                                    "-dev and rebuild, or use none)");
  }
}

void apply_overrides(LoggerOptions& o, const std::vector<std::string>& assignments) {
  std::vector<std::string> rest = assignments;
  const std::vector<std::string> dds = parameters::take_section(rest, "dds");
  for (const std::string& a : rest) parameters::apply_override(o, logger_parameters(), "logger", a);
  validate(o);
  dds::resolve_settings(o.dds, dds);
}

LoggerOptions read_logger_options(config::YamlReader& root, const std::string& config_dir) {
  LoggerOptions o;
  config::YamlReader section = root.child("logger");
  o.topics = dds::read_topic_patterns(section);
  config::read_parameters(section, logger_parameters(), o);
  config::check_rules(section, [&] { validate(o); });
  section.finish();

  o.dds = dds::read_dds_section(root, config_dir);
  root.finish();
  return o;
}

LoggerOptions read_logger_options_file(const std::string& path) {
  config::YamlReader root = config::YamlReader::from_file(path);
  return read_logger_options(root, config::folder_of(path));
}

std::string to_yaml(const LoggerOptions& o) {
  std::string topics;
  for (const std::string& t : o.topics) topics += (topics.empty() ? "" : ", ") + t;
  return parameters::to_yaml(o, logger_parameters(), "logger") + "  topics: [" + topics + "]\n" + dds::to_yaml(o.dds);
}

namespace {
// "dir/run.mcap" -> {"dir/run", ".mcap"}; "dir/.hidden" -> {"dir/.hidden", ""}.
std::pair<std::string, std::string> stem_and_extension(const std::string& base) {
  const std::size_t slash = base.find_last_of('/');
  const std::size_t dot = base.find_last_of('.');
  const bool has_extension = dot != std::string::npos && (slash == std::string::npos || dot > slash + 1);
  return {has_extension ? base.substr(0, dot) : base, has_extension ? base.substr(dot) : ""};
}
}  // namespace

std::string rotated_file_name(const std::string& base, std::size_t index) {
  const auto [stem, extension] = stem_and_extension(base);
  char number[32];
  std::snprintf(number, sizeof(number), "_%03zu", index);
  return stem + number + extension;
}

std::optional<std::size_t> rotated_file_index(const std::string& base, const std::string& name) {
  const auto [stem, extension] = stem_and_extension(base);
  const std::size_t prefix = stem.size() + 1;
  if (name.size() < prefix + 3 + extension.size() || name.compare(0, stem.size(), stem) != 0 ||
      name[stem.size()] != '_' || name.compare(name.size() - extension.size(), extension.size(), extension) != 0) {
    return std::nullopt;
  }
  const std::string digits = name.substr(prefix, name.size() - prefix - extension.size());
  if (digits.size() > 18 || !std::all_of(digits.begin(), digits.end(), [](char c) { return c >= '0' && c <= '9'; })) {
    return std::nullopt;
  }
  const std::size_t index = std::stoull(digits);
  if (rotated_file_name(base, index) != name) return std::nullopt;  // "run_0012" is not index 12's name
  return index;
}

}  // namespace pixyslam::logger_node
