#include "pixyslam/logger_node/logger_options.h"

#include <sstream>

#include "pixyslam/app/command_line.h"
#include "pixyslam/logger_node/cdr_payload.h"
#include "pixyslam/logger_node/topic_selection.h"

namespace pixyslam::logger_node {

logger::McapCompression default_compression() {
  return logger::mcap_compression_available(logger::McapCompression::kZstd) ? logger::McapCompression::kZstd
                                                                            : logger::McapCompression::kNone;
}

namespace {

std::vector<std::string> all_topics() {
  std::vector<std::string> out;
  for (const TopicInfo& t : known_topics()) out.push_back(t.topic);
  return out;
}

constexpr std::uint64_t kMinRotateSizeBytes = 65536;

logger::McapCompression read_compression(config::YamlReader& reader, logger::McapCompression fallback) {
  const std::string fallback_name =
      fallback == logger::McapCompression::kNone ? "none" : logger::mcap_compression_name(fallback);
  const std::string name = reader.choice("compression", {"none", "zstd", "lz4"}, fallback_name);
  const logger::McapCompression c = name == "zstd"  ? logger::McapCompression::kZstd
                                    : name == "lz4" ? logger::McapCompression::kLz4
                                                    : logger::McapCompression::kNone;
  if (!logger::mcap_compression_available(c)) {
    reader.fail("compression", "'" + name + "' is not available in this build (install lib" + name +
                                   "-dev and rebuild, or use none)");
  }
  return c;
}

}  // namespace

bool rotation_enabled(const LoggerOptions& options) {
  return options.rotate_size_bytes > 0 || options.rotate_period_s > 0.0;
}

LoggerOptions read_logger_options(config::YamlReader& root, const std::string& config_dir) {
  LoggerOptions o;
  config::YamlReader section = root.child("logger");
  o.output_file = section.text("output_file", o.output_file);
  if (o.output_file.empty()) section.fail("output_file", "must not be empty");
  if (section.has("topics")) {
    const std::vector<std::string> patterns = section.text_list("topics");
    if (patterns.empty()) section.fail("topics", "empty list (leave the key out to record every topic)");
    const TopicSelection selection = select_topics(patterns, all_topics());
    if (!selection.error.empty()) {
      section.fail("topics[" + std::to_string(selection.bad_pattern) + "]", selection.error);
    }
    o.topics = selection.topics;
  } else {
    o.topics = all_topics();
  }
  o.rotate_size_bytes = static_cast<std::uint64_t>(
      section.integer("rotate_size_bytes", 0, std::int64_t{1} << 40, static_cast<std::int64_t>(o.rotate_size_bytes)));
  if (o.rotate_size_bytes != 0 && o.rotate_size_bytes < kMinRotateSizeBytes) {
    section.fail("rotate_size_bytes", "value " + std::to_string(o.rotate_size_bytes) + " is too small: 0 (off) or at least " +
                                          std::to_string(kMinRotateSizeBytes));
  }
  o.rotate_period_s = section.number("rotate_period_s", 0.0, 7 * 86400.0, o.rotate_period_s);
  if (o.rotate_period_s != 0.0 && o.rotate_period_s < 1.0) {
    section.fail("rotate_period_s", "value " + std::to_string(o.rotate_period_s) + " is too small: 0 (off) or at least 1");
  }
  o.chunk_size_bytes = static_cast<std::size_t>(
      section.integer("chunk_size_bytes", 4096, std::int64_t{1} << 28, static_cast<std::int64_t>(o.chunk_size_bytes)));
  o.compression = read_compression(section, o.compression);
  o.flush_period_s = section.number("flush_period_s", 0.0, 3600.0, o.flush_period_s);
  o.fsync = section.boolean("fsync", o.fsync);
  o.queue_max_bytes = static_cast<std::size_t>(section.integer(
      "queue_max_bytes", std::int64_t{1} << 20, std::int64_t{1} << 32, static_cast<std::int64_t>(o.queue_max_bytes)));
  o.retry_period_s = section.number("retry_period_s", 0.1, 3600.0, o.retry_period_s);
  o.fallback_dir = section.text("fallback_dir", o.fallback_dir);
  section.finish();

  if (root.has("dds")) {
    config::YamlReader dds = root.child("dds");
    o.dds = dds::read_dds_options(dds, config_dir);
  }
  root.finish();
  return o;
}

LoggerOptions read_logger_options_file(const std::string& path) {
  config::YamlReader root = config::YamlReader::from_file(path);
  return read_logger_options(root, app::folder_of(path));
}

std::string to_yaml(const LoggerOptions& o) {
  std::ostringstream os;
  os << "logger:\n"
     << "  output_file: '" << o.output_file << "'\n"
     << "  topics: [";
  for (std::size_t i = 0; i < o.topics.size(); ++i) os << (i ? ", " : "") << o.topics[i];
  os << "]\n"
     << "  rotate_size_bytes: " << o.rotate_size_bytes << "\n"
     << "  rotate_period_s: " << o.rotate_period_s << "\n"
     << "  chunk_size_bytes: " << o.chunk_size_bytes << "\n"
     << "  compression: "
     << (o.compression == logger::McapCompression::kNone ? "none" : logger::mcap_compression_name(o.compression))
     << "\n"
     << "  flush_period_s: " << o.flush_period_s << "\n"
     << "  fsync: " << (o.fsync ? "true" : "false") << "\n"
     << "  queue_max_bytes: " << o.queue_max_bytes << "\n"
     << "  retry_period_s: " << o.retry_period_s << "\n"
     << "  fallback_dir: '" << o.fallback_dir << "'\n"
     << dds::to_yaml(o.dds);
  return os.str();
}

}  // namespace pixyslam::logger_node
