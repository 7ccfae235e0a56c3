// The logger's options from YAML and its rotated file names (pure: no DDS
// traffic). A unit test, so that the armhf build runs it too: there a 32-bit
// size_t once turned a range bound of 4 GiB into 0 and the shipped config no
// longer loaded.
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "pixyslam/config/yaml_reader.h"
#include "pixyslam/dds/topics.h"
#include "pixyslam/logger_node/logger_node.h"
#include "pixyslam/logger_node/logger_options.h"

namespace pixyslam::logger_node {
namespace {

using dds::known_topics;
using dds::TopicInfo;

// ---------------------------------------------------------------- file names

TEST(RotatedFileName, IndexGoesBeforeTheExtension) {
  EXPECT_EQ(rotated_file_name("run.mcap", 0), "run_000.mcap");
  EXPECT_EQ(rotated_file_name("run.mcap", 12), "run_012.mcap");
  EXPECT_EQ(rotated_file_name("run.mcap", 1234), "run_1234.mcap");
  EXPECT_EQ(rotated_file_name("/tmp/a.b/run", 1), "/tmp/a.b/run_001");
  EXPECT_EQ(rotated_file_name("dir/.hidden", 2), "dir/.hidden_002");
  EXPECT_EQ(rotated_file_name("dir/run.x.mcap", 3), "dir/run.x_003.mcap");
}

TEST(RotatedFileName, TheIndexIsReadBackOnlyFromItsOwnNames) {
  EXPECT_EQ(rotated_file_index("run.mcap", "run_000.mcap"), std::optional<std::size_t>(0));
  EXPECT_EQ(rotated_file_index("run.mcap", "run_1234.mcap"), std::optional<std::size_t>(1234));
  EXPECT_EQ(rotated_file_index("dir/run.x.mcap", "dir/run.x_003.mcap"), std::optional<std::size_t>(3));
  EXPECT_EQ(rotated_file_index("/tmp/a.b/run", "/tmp/a.b/run_001"), std::optional<std::size_t>(1));
  for (const char* other : {"run.mcap", "run_01.mcap", "run_0012.mcap", "run_abc.mcap", "run_001.mcap.tmp",
                            "walk_001.mcap", "run_001.txt", "run__001.mcap"}) {
    EXPECT_FALSE(rotated_file_index("run.mcap", other).has_value()) << other;
  }
}

// ---------------------------------------------------------------- options

std::string config_error(const std::string& yaml) {
  auto root = config::YamlReader::from_string(yaml, "logger_test.yaml");
  try {
    read_logger_options(root, "/cfg");
  } catch (const config::ConfigError& e) {
    return e.what();
  }
  return "(no error)";
}

TEST(LoggerOptions, ShippedConfigLoads) {
  const LoggerOptions o = read_logger_options_file(std::string(PIXYSLAM_CONFIG_DIR) + "/logger.yaml");
  EXPECT_EQ(o.output_file, "pixyslam_run.mcap");
  std::vector<std::string> every_topic;  // the shipped config records them all
  for (const TopicInfo& t : known_topics()) every_topic.push_back(t.topic);
  EXPECT_EQ(o.topics, every_topic);
  EXPECT_EQ(o.chunk_size_bytes, 1048576u);
  EXPECT_EQ(o.compression, default_compression());
  EXPECT_DOUBLE_EQ(o.flush_period_s, 1.0);
  EXPECT_FALSE(o.fsync);
  EXPECT_EQ(o.dds.profiles_file, std::string(PIXYSLAM_CONFIG_DIR) + "/dds/profiles.xml");
  EXPECT_TRUE(std::filesystem::exists(o.dds.profiles_file));
}

TEST(LoggerOptions, DefaultsRecordEveryTopic) {
  auto root = config::YamlReader::from_string("logger: {}\n", "logger_test.yaml");
  const LoggerOptions o = read_logger_options(root, "/cfg");
  ASSERT_EQ(o.topics.size(), known_topics().size());
  EXPECT_EQ(o.topics[3], "pixyslam/ground_truth");
  EXPECT_EQ(o.compression, default_compression());
  EXPECT_DOUBLE_EQ(o.flush_period_s, 1.0);
}

TEST(LoggerOptions, SelectedTopicsAndCompression) {
  auto root = config::YamlReader::from_string(
      "logger:\n  topics: [pixyslam/map_state]\n  compression: none\n  fsync: true\n"
      "dds:\n  profiles_file: dds/profiles.xml\n",
      "logger_test.yaml");
  const LoggerOptions o = read_logger_options(root, "/cfg");
  EXPECT_EQ(o.topics, std::vector<std::string>{"pixyslam/map_state"});
  EXPECT_EQ(o.compression, mcap::McapCompression::kNone);
  EXPECT_TRUE(o.fsync);
  EXPECT_EQ(o.dds.profiles_file, "/cfg/dds/profiles.xml");
}

TEST(LoggerOptions, TopicPatternsAndRotation) {
  auto root = config::YamlReader::from_string(
      "logger:\n  topics: ['pixyslam/*', '!pixyslam/ground_truth']\n  rotate_size_bytes: 1000000\n"
      "  rotate_period_s: 60\n",
      "logger_test.yaml");
  const LoggerOptions o = read_logger_options(root, "/cfg");
  EXPECT_EQ(o.topics,
            (std::vector<std::string>{"pixyslam/odometry", "pixyslam/landmark_observation", "pixyslam/map_state",
                                      "pixyslam/diagnostics", "pixyslam/optimised_map", "pixyslam/robot_sighting",
                                      "pixyslam/fleet_map"}));
  EXPECT_EQ(o.rotate_size_bytes, 1000000u);
  EXPECT_DOUBLE_EQ(o.rotate_period_s, 60.0);
  EXPECT_TRUE(rotation_enabled(o));
  // The effective configuration reads back the same.
  auto again = config::YamlReader::from_string(to_yaml(o), "effective.yaml");
  const LoggerOptions back = read_logger_options(again, "/cfg");
  EXPECT_EQ(back.topics, o.topics);
  EXPECT_EQ(back.rotate_size_bytes, o.rotate_size_bytes);
  EXPECT_DOUBLE_EQ(back.rotate_period_s, o.rotate_period_s);

  const LoggerOptions shipped = read_logger_options_file(std::string(PIXYSLAM_CONFIG_DIR) + "/logger.yaml");
  EXPECT_FALSE(rotation_enabled(shipped));
}

TEST(LoggerOptions, ErrorsNameTheFileAndTheKey) {
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"logger:\n  flush_period_sec: 1\n", "key 'logger.flush_period_sec': unknown key"},
      {"logger:\n  topics: [pixyslam/odometry, pixyslam/odometri]\n", "key 'logger.topics[1]': unknown topic"},
      {"logger:\n  topics: [pixyslam/odometry, pixyslam/odometry]\n", "key 'logger.topics[1]': topic"},
      {"logger:\n  topics: []\n", "key 'logger.topics': empty list"},
      {"logger:\n  topics: ['pixyslam/*', 'other/*']\n", "key 'logger.topics[1]': pattern 'other/*' matches no"},
      {"logger:\n  topics: ['pixyslam/*', '!pixyslam/*']\n", "key 'logger.topics[1]': the patterns select no topic"},
      {"logger:\n  rotate_size_bytes: 1000\n", "key 'logger.rotate_size_bytes': value 1000 is too small"},
      {"logger:\n  rotate_size_bytes: -1\n", "key 'logger.rotate_size_bytes'"},
      {"logger:\n  rotate_period_s: 0.5\n", "key 'logger.rotate_period_s'"},
      {"logger:\n  keep_files: 3\n", "key 'logger.keep_files': value 3 needs rotation"},
      {"logger:\n  compression: gzip\n", "key 'logger.compression': value 'gzip' is not one of"},
      {"logger:\n  flush_period_s: -1\n", "key 'logger.flush_period_s': value -1 is out of range"},
      {"logger:\n  chunk_size_bytes: 10\n", "key 'logger.chunk_size_bytes'"},
      {"logger:\n  output_file: ''\n", "key 'logger.output_file': value '' is empty"},
      {"logger:\n  fsync: maybe\n", "key 'logger.fsync'"},
      {"dds: {}\n", "key 'logger': missing"},
      {"logger: {}\ndds:\n  domain_id: 999\n", "key 'dds.domain_id'"},
      {"logger: {}\nextra: 1\n", "key 'extra': unknown key"},
  };
  for (const auto& [yaml, expected] : cases) {
    const std::string error = config_error(yaml);
    EXPECT_EQ(error.rfind("logger_test.yaml: ", 0), 0u) << error;
    EXPECT_NE(error.find(expected), std::string::npos) << "YAML:\n" << yaml << "error: " << error;
  }
}

}  // namespace
}  // namespace pixyslam::logger_node
