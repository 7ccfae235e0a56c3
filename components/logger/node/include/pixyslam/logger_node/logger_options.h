#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "pixyslam/config/yaml_reader.h"
#include "pixyslam/dds/participant.h"
#include "pixyslam/mcap/mcap_writer.h"

namespace pixyslam::logger_node {

// zstd when the MCAP library was built with it, else none.
mcap::McapCompression default_compression();

// Everything the logger process is configured with (config/logger.yaml).
struct LoggerOptions {
  // `logger.output_file`: the MCAP file, created; if it already holds data (a
  // restarted logger, a reused folder) it is kept and the indexed name after
  // the highest one holding a recording (run_001.mcap, ...) is written instead. A relative path is relative
  // to the working directory. `logger --out` overrides it. With
  // rotation on, the files are named rotated_file_name(output_file, 0, 1, ...):
  // run.mcap -> run_000.mcap, run_001.mcap, ...
  std::string output_file = "pixyslam_run.mcap";
  // `logger.topics`: the DDS topics to record (known_topics()), as patterns
  // (select_topics(): names, globs, "!" exclusions); empty = all. The reader
  // resolves them into names, in the order of known_topics().
  std::vector<std::string> topics;
  // `logger.rotate_size_bytes`: start a new file once this one holds this many
  // bytes (written plus the open chunk uncompressed; 0 = never). A file may
  // exceed it by one message and its summary.
  std::uint64_t rotate_size_bytes = 0;
  // `logger.rotate_period_s`: start a new file after this long (0 = never).
  double rotate_period_s = 0.0;
  // `logger.keep_files`: with rotation, at most this many of this run's files
  // stay on disk: after a new file opens the oldest are deleted (0 = all), so
  // a station that records for weeks does not fill its disk.
  std::size_t keep_files = 0;
  // `logger.chunk_size_bytes`: uncompressed bytes per MCAP chunk before it is written.
  std::size_t chunk_size_bytes = std::size_t{1} << 20;
  // `logger.compression`: none | zstd | lz4 (chunk compression).
  mcap::McapCompression compression = default_compression();
  // `logger.flush_period_s`: the open chunk is written at least this often, so
  // a crash loses at most about this much (0: only when a chunk is full).
  double flush_period_s = 1.0;
  // `logger.fsync`: fsync(2) after every chunk, not only fflush (survives a power cut).
  bool fsync = false;
  // `logger.queue_max_bytes`: payload bytes waiting for the writer thread;
  // samples beyond it are dropped and counted.
  std::size_t queue_max_bytes = std::size_t{64} << 20;
  // `logger.retry_period_s`: after a write failure (disk full, ...) the file
  // written so far is kept as it is (readable up to its last complete chunk),
  // samples are dropped and counted, and a new file (the next rotated name) is
  // tried this often.
  double retry_period_s = 5.0;
  // `logger.fallback_dir`: a second directory the retries alternate with
  // ("" = retry in the output file's own directory only).
  std::string fallback_dir;
  dds::DdsOptions dds;  // `dds:`
};

// True when rotate_size_bytes or rotate_period_s is set.
bool rotation_enabled(const LoggerOptions& options);

// The `logger:` keys but topics (patterns, read apart): range, unit, help.
const parameters::Table<LoggerOptions>& logger_parameters();

// Ranges and the rules between keys; throws std::invalid_argument naming the key.
void validate(const LoggerOptions& options);

// `--set` assignments "logger.KEY=V", "dds.KEY=V" applied and validated; the
// DDS settings resolved (the environment, then these). Throws
// std::invalid_argument / config::ConfigError naming the assignment.
void apply_overrides(LoggerOptions& options, const std::vector<std::string>& assignments);

// Reads `logger:` (required) and `dds:` (optional) from the top level and calls
// root.finish(). `config_dir` resolves a relative dds.profiles_file. Throws
// config::ConfigError naming the file and key path.
LoggerOptions read_logger_options(config::YamlReader& root, const std::string& config_dir);
LoggerOptions read_logger_options_file(const std::string& path);

// The effective configuration, in the layout read_logger_options() reads.
std::string to_yaml(const LoggerOptions& options);

// The name of rotated file `index` for `base`: "run.mcap", 3 -> "run_003.mcap"
// (at least three digits; "dir/run" -> "dir/run_003"). Pure.
std::string rotated_file_name(const std::string& base, std::size_t index);
// The index of `name` if it is a rotated file name of `base` (its inverse), else none.
std::optional<std::size_t> rotated_file_index(const std::string& base, const std::string& name);

}  // namespace pixyslam::logger_node
