// Tests of read_filter_options: values round-trip from YAML, and every kind of
// configuration mistake is a config::ConfigError naming the origin and key path.

#include <cmath>
#include <filesystem>
#include <stdexcept>
#include <string>

#include <gtest/gtest.h>

#include "pixyslam/config/yaml_reader.h"
#include "pixyslam/slam/slam_options.h"
#include "pixyslam/slam/slam_options_yaml.h"

namespace pixyslam::slam {
namespace {

using config::ConfigError;
using config::YamlReader;

constexpr const char* kOrigin = "test_filter.yaml";

// Parses a document holding a `filter:` mapping and reads it like the apps do.
FilterOptions read(const std::string& text) {
  YamlReader root = YamlReader::from_string(text, kOrigin);
  YamlReader filter = root.child("filter");
  FilterOptions o = read_filter_options(filter);
  root.finish();
  return o;
}

std::string error_of(const std::string& text) {
  try {
    read(text);
  } catch (const ConfigError& e) {
    return e.what();
  }
  ADD_FAILURE() << "expected ConfigError for:\n" << text;
  return "";
}

bool contains(const std::string& s, const std::string& part) { return s.find(part) != std::string::npos; }

TEST(SlamOptionsYaml, FullConfigRoundTripsEveryValue) {
  // Given a config where every key differs from the FilterOptions default,
  const FilterOptions o = read(
      "filter:\n"
      "  particles: 321\n"
      "  seed: 987654321\n"
      "  motion:\n"
      "    v_sigma_m_per_sqrt_s: 0.0125\n"
      "    w_sigma_rad_per_sqrt_s: 0.0225\n"
      "    distance_sigma_per_sqrt_m: 0.05\n"
      "    heading_sigma_rad_per_sqrt_m: 0.06\n"
      "    rotation_sigma_per_sqrt_rad: 0.07\n"
      "  max_speed_mps: 3.5\n"
      "  max_turn_rate_radps: 6.5\n"
      "  control_timeout_s: 2.5\n"
      "  observation:\n"
      "    range_sigma_m: 0.11\n"
      "    range_sigma_per_m: 0.02\n"
      "    bearing_sigma_rad: 0.031\n"
      "    min_range_m: 0.3\n"
      "    max_range_m: 12.5\n"
      "  gate:\n"
      "    enabled: false\n"
      "    probability: 0.99\n"
      "    readmit_after: 7\n"
      "  resample:\n"
      "    mode: every_frame\n"
      "    neff_fraction: 0.4\n"
      "  delayed_sampling:\n"
      "    enabled: true\n"
      "    enter_heading_sigma_rad: 0.2\n"
      "    enter_position_sigma_m: 0.4\n"
      "    exit_heading_sigma_rad: 0.03\n"
      "    exit_position_sigma_m: 0.07\n"
      "    max_landmarks: 24\n"
      "  frame_uncertainty:\n"
      "    enabled: true\n"
      "    landmarks: true\n");
  // then each value arrives in its field.
  const FilterOptions d;
  EXPECT_EQ(o.particles, 321);
  EXPECT_EQ(o.seed, 987654321u);
  EXPECT_DOUBLE_EQ(o.motion.v_sigma_m_per_sqrt_s, 0.0125);
  EXPECT_DOUBLE_EQ(o.motion.w_sigma_rad_per_sqrt_s, 0.0225);
  EXPECT_DOUBLE_EQ(o.motion.distance_sigma_per_sqrt_m, 0.05);
  EXPECT_DOUBLE_EQ(o.motion.heading_sigma_rad_per_sqrt_m, 0.06);
  EXPECT_DOUBLE_EQ(o.motion.rotation_sigma_per_sqrt_rad, 0.07);
  EXPECT_DOUBLE_EQ(o.max_speed_mps, 3.5);
  EXPECT_DOUBLE_EQ(o.max_turn_rate_radps, 6.5);
  EXPECT_DOUBLE_EQ(o.control_timeout_s, 2.5);
  EXPECT_DOUBLE_EQ(o.range_sigma_m, 0.11);
  EXPECT_DOUBLE_EQ(o.range_sigma_per_m, 0.02);
  EXPECT_DOUBLE_EQ(o.bearing_sigma_rad, 0.031);
  EXPECT_DOUBLE_EQ(o.min_range_m, 0.3);
  EXPECT_DOUBLE_EQ(o.max_range_m, 12.5);
  EXPECT_FALSE(o.gate_enabled);
  EXPECT_NE(o.gate_enabled, d.gate_enabled);
  EXPECT_DOUBLE_EQ(o.gate_probability, 0.99);
  EXPECT_EQ(o.gate_readmit_after, 7);
  EXPECT_EQ(o.resample_mode, ResampleMode::kEveryFrame);
  EXPECT_NE(o.resample_mode, d.resample_mode);
  EXPECT_DOUBLE_EQ(o.resample_neff_fraction, 0.4);
  EXPECT_TRUE(o.delayed_sampling.enabled);
  EXPECT_NE(o.delayed_sampling.enabled, d.delayed_sampling.enabled);
  EXPECT_DOUBLE_EQ(o.delayed_sampling.enter_heading_sigma_rad, 0.2);
  EXPECT_DOUBLE_EQ(o.delayed_sampling.enter_position_sigma_m, 0.4);
  EXPECT_DOUBLE_EQ(o.delayed_sampling.exit_heading_sigma_rad, 0.03);
  EXPECT_DOUBLE_EQ(o.delayed_sampling.exit_position_sigma_m, 0.07);
  EXPECT_EQ(o.delayed_sampling.max_landmarks, 24);
  EXPECT_TRUE(o.frame_uncertainty);
  EXPECT_NE(o.frame_uncertainty, d.frame_uncertainty);
  EXPECT_TRUE(o.landmark_uncertainty);
  EXPECT_NE(o.landmark_uncertainty, d.landmark_uncertainty);
  EXPECT_NO_THROW(validate(o));
}

TEST(SlamOptionsYaml, MissingKeysKeepDefaults) {
  const FilterOptions o = read("filter:\n  particles: 17\n  resample:\n    mode: effective_sample_size\n");
  const FilterOptions d;
  EXPECT_EQ(o.particles, 17);
  EXPECT_EQ(o.seed, d.seed);
  EXPECT_DOUBLE_EQ(o.motion.v_sigma_m_per_sqrt_s, d.motion.v_sigma_m_per_sqrt_s);
  EXPECT_DOUBLE_EQ(o.range_sigma_m, d.range_sigma_m);
  EXPECT_EQ(o.gate_enabled, d.gate_enabled);
  EXPECT_DOUBLE_EQ(o.gate_probability, d.gate_probability);
  EXPECT_EQ(o.resample_mode, ResampleMode::kEffectiveSampleSize);
  EXPECT_DOUBLE_EQ(o.resample_neff_fraction, d.resample_neff_fraction);
}

TEST(SlamOptionsYaml, ReadsTheShippedSimConfig) {
  // The repository's own sim config must load (its `world:` part is not ours).
  const std::filesystem::path config = std::filesystem::path(PIXYSLAM_CONFIG_DIR) / "slam_sim.yaml";
  YamlReader root = YamlReader::from_file(config.string());
  YamlReader filter = root.child("filter");
  const FilterOptions o = read_filter_options(filter);
  EXPECT_EQ(o.particles, 100);
  EXPECT_DOUBLE_EQ(o.motion.v_sigma_m_per_sqrt_s, 0.0095);
}

TEST(SlamOptionsYaml, UnknownNestedKeyNamesOriginAndFullPath) {
  const std::string m = error_of("filter:\n  motion:\n    v_sigma: 0.01\n");
  EXPECT_TRUE(contains(m, kOrigin)) << m;
  EXPECT_TRUE(contains(m, "filter.motion.v_sigma")) << m;
  EXPECT_TRUE(contains(m, "unknown")) << m;
}

TEST(SlamOptionsYaml, UnknownTopLevelFilterKeyIsAnError) {
  const std::string m = error_of("filter:\n  particle: 10\n");
  EXPECT_TRUE(contains(m, kOrigin)) << m;
  EXPECT_TRUE(contains(m, "filter.particle")) << m;
}

TEST(SlamOptionsYaml, WrongTypeNamesTheKey) {
  const std::string m = error_of("filter:\n  particles: abc\n");
  EXPECT_TRUE(contains(m, kOrigin)) << m;
  EXPECT_TRUE(contains(m, "filter.particles")) << m;
  EXPECT_TRUE(contains(m, "abc")) << m;

  const std::string m2 = error_of("filter:\n  gate:\n    enabled: maybe\n");
  EXPECT_TRUE(contains(m2, "filter.gate.enabled")) << m2;

  const std::string m3 = error_of("filter:\n  observation:\n    range_sigma_m: far\n");
  EXPECT_TRUE(contains(m3, "filter.observation.range_sigma_m")) << m3;
}

TEST(SlamOptionsYaml, OutOfRangeNamesKeyAndRange) {
  const std::string m = error_of("filter:\n  particles: 0\n");
  EXPECT_TRUE(contains(m, kOrigin)) << m;
  EXPECT_TRUE(contains(m, "filter.particles")) << m;
  EXPECT_TRUE(contains(m, "[1, 1000000]")) << m;

  const std::string m2 = error_of("filter:\n  motion:\n    v_sigma_m_per_sqrt_s: -0.1\n");
  EXPECT_TRUE(contains(m2, "filter.motion.v_sigma_m_per_sqrt_s")) << m2;
  EXPECT_TRUE(contains(m2, "out of range")) << m2;

  const std::string m3 = error_of("filter:\n  gate:\n    probability: 1\n");
  EXPECT_TRUE(contains(m3, "filter.gate.probability")) << m3;
}

TEST(SlamOptionsYaml, CrossFieldViolationIsAConfigErrorNamingTheField) {
  // Each value is within its own range, but max_range_m <= min_range_m.
  const std::string m = error_of("filter:\n  observation:\n    min_range_m: 5\n    max_range_m: 2\n");
  EXPECT_TRUE(contains(m, kOrigin)) << m;
  EXPECT_TRUE(contains(m, "max_range_m")) << m;
}

TEST(SlamOptionsYaml, ExitAboveEnterIsAConfigErrorNamingTheField) {
  const std::string m = error_of(
      "filter:\n  delayed_sampling:\n    enter_heading_sigma_rad: 0.1\n    exit_heading_sigma_rad: 0.2\n");
  EXPECT_TRUE(contains(m, kOrigin)) << m;
  EXPECT_TRUE(contains(m, "delayed_sampling.exit_heading_sigma_rad")) << m;
  EXPECT_TRUE(contains(m, "enter_heading_sigma_rad")) << m;
}

TEST(SlamOptionsYaml, BadResampleModeListsAllowedValues) {
  const std::string m = error_of("filter:\n  resample:\n    mode: foo\n");
  EXPECT_TRUE(contains(m, "filter.resample.mode")) << m;
  EXPECT_TRUE(contains(m, "foo")) << m;
  EXPECT_TRUE(contains(m, "effective_sample_size")) << m;
  EXPECT_TRUE(contains(m, "every_frame")) << m;
}

TEST(SlamOptionsYaml, AssociationModeAndItsErrors) {
  const FilterOptions o =
      read("filter:\n  association:\n    mode: maximum_likelihood\n    new_landmark_probability: 0.995\n");
  EXPECT_EQ(o.association, Association::kMaximumLikelihood);
  EXPECT_DOUBLE_EQ(o.new_landmark_probability, 0.995);
  EXPECT_EQ(read("filter:\n  particles: 3\n").association, Association::kKnownId);
  const std::string m = error_of("filter:\n  association:\n    mode: nearest\n");
  EXPECT_TRUE(contains(m, "filter.association.mode")) << m;
  EXPECT_TRUE(contains(m, "maximum_likelihood")) << m;
  EXPECT_TRUE(contains(error_of("filter:\n  association:\n    new_landmark_probability: 1.5\n"),
                       "filter.association.new_landmark_probability"));
}

TEST(SlamOptionsYaml, SyntaxErrorGivesLineNumber) {
  // Line 3 opens a flow sequence that is never closed.
  try {
    read("filter:\n  particles: 10\n  seed: [1, 2\n");
    FAIL() << "expected ConfigError";
  } catch (const ConfigError& e) {
    const std::string m = e.what();
    EXPECT_TRUE(contains(m, kOrigin)) << m;
    EXPECT_TRUE(contains(m, "line")) << m;
  }
  // Line 4 is indented deeper than its sibling on line 5: the error is on line 5.
  try {
    read("filter:\n  particles: 10\n  motion:\n     v_sigma_m_per_sqrt_s: 0.1\n    w_sigma_rad_per_sqrt_s: 0.1\n");
    FAIL() << "expected ConfigError";
  } catch (const ConfigError& e) {
    const std::string m = e.what();
    EXPECT_TRUE(contains(m, kOrigin)) << m;
    EXPECT_TRUE(contains(m, "line 5")) << m;
  }
}

TEST(SlamOptionsYaml, MissingFileNamesThePath) {
  try {
    read_filter_options_file("/nonexistent/pixyslam_missing_filter.yaml");
    FAIL() << "expected ConfigError";
  } catch (const ConfigError& e) {
    EXPECT_TRUE(contains(e.what(), "pixyslam_missing_filter.yaml")) << e.what();
  }
}

// ---- The parameter table (filter_parameters()): one declaration per parameter.

// Every member of FilterOptions is in the table: the effective configuration
// printed from a changed struct reads back into the same struct.
TEST(FilterParameters, EffectiveConfigurationReadsBackIntoTheSameOptions) {
  FilterOptions o;
  o.particles = 321;
  o.seed = 987654321;
  o.motion.w_sigma_rad_per_sqrt_s = 0.0225;
  o.error_correlation_s = 0.7;
  o.gate_enabled = false;
  o.association = Association::kKnownId;
  o.resample_mode = ResampleMode::kEveryFrame;
  o.delayed_sampling.enabled = true;
  o.delayed_sampling.max_landmarks = 24;
  o.anchor_frame.min_spread_m = 0.75;
  o.landmark_uncertainty = true;
  const std::string yaml = parameters::to_yaml(o, filter_parameters(), "filter");
  const FilterOptions back = read(yaml);
  for (const auto& p : filter_parameters()) {
    EXPECT_EQ(parameters::value_text(p, back), parameters::value_text(p, o)) << p.path << "\n" << yaml;
  }
  EXPECT_EQ(back.seed, 987654321u);
  EXPECT_EQ(back.resample_mode, ResampleMode::kEveryFrame);
  EXPECT_TRUE(contains(yaml, "    w_sigma_rad_per_sqrt_s: 0.0225  # rad/sqrt(s)\n")) << yaml;
}

TEST(FilterParameters, PathsAreUniqueAndTheDefaultsInRange) {
  const auto& table = filter_parameters();
  EXPECT_GE(table.size(), 30u);
  for (std::size_t i = 0; i < table.size(); ++i) {
    EXPECT_FALSE(table[i].help.empty()) << table[i].path;
    for (std::size_t j = i + 1; j < table.size(); ++j) EXPECT_NE(table[i].path, table[j].path);
  }
  EXPECT_NO_THROW(validate(FilterOptions{}));
  const std::string help = parameters::help_text(table, "filter");
  for (const auto& p : table) EXPECT_TRUE(contains(help, "filter." + p.path + "  ")) << p.path;
}

TEST(FilterParameters, OverridesCheckNameTypeAndRange) {
  FilterOptions o;
  parameters::apply_override(o, filter_parameters(), "filter", "filter.particles=250");
  parameters::apply_override(o, filter_parameters(), "filter", "filter.gate.enabled=false");
  parameters::apply_override(o, filter_parameters(), "filter", "filter.association.mode=maximum_likelihood");
  parameters::apply_override(o, filter_parameters(), "filter", "filter.observation.range_sigma_m=0.125");
  EXPECT_EQ(o.particles, 250);
  EXPECT_FALSE(o.gate_enabled);
  EXPECT_EQ(o.association, Association::kMaximumLikelihood);
  EXPECT_DOUBLE_EQ(o.range_sigma_m, 0.125);
  const auto error = [&](const std::string& assignment) {
    try {
      parameters::apply_override(o, filter_parameters(), "filter", assignment);
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    ADD_FAILURE() << "expected an error for " << assignment;
    return std::string();
  };
  EXPECT_TRUE(contains(error("filter.particles=0"), "filter.particles = '0': out of range ([1, 1000000])"));
  EXPECT_TRUE(contains(error("filter.particles=2.5"), "not an integer"));
  EXPECT_TRUE(contains(error("filter.particles=many"), "not a number"));
  EXPECT_TRUE(contains(error("filter.gate.enabled=yes"), "not true or false"));
  EXPECT_TRUE(contains(error("filter.resample.mode=often"), "effective_sample_size | every_frame"));
  EXPECT_TRUE(contains(error("filter.particle=3"), "unknown parameter 'filter.particle'"));
  EXPECT_TRUE(contains(error("estimator.particles=3"), "not a parameter of 'filter'"));
  EXPECT_TRUE(contains(error("filter.particles"), "expected KEY=VALUE"));
  EXPECT_EQ(o.particles, 250);  // a refused override leaves the value
}

TEST(FilterParameters, ValidateNamesTheParameterWithItsRange) {
  FilterOptions o;
  o.particles = 0;
  try {
    validate(o);
    FAIL() << "expected std::invalid_argument";
  } catch (const std::invalid_argument& e) {
    EXPECT_TRUE(contains(e.what(), "filter.particles: value 0 is out of range [1, 1000000]")) << e.what();
  }
  o = FilterOptions{};
  o.motion.v_sigma_m_per_sqrt_s = std::nan("");
  EXPECT_THROW(validate(o), std::invalid_argument);
  o = FilterOptions{};
  o.error_correlation_s = 0.5;
  o.association = Association::kMaximumLikelihood;
  try {
    validate(o);
    FAIL() << "expected std::invalid_argument";
  } catch (const std::invalid_argument& e) {
    EXPECT_TRUE(contains(e.what(), "filter.observation.error_correlation_s")) << e.what();
  }
}

TEST(SlamOptions, GateMahalanobisIsTheChiSquare2Quantile) {
  FilterOptions o;
  o.gate_probability = 0.95;
  EXPECT_NEAR(gate_mahalanobis2(o), 5.991464547107979, 1e-9);
  o.gate_probability = 0.999;
  EXPECT_NEAR(gate_mahalanobis2(o), 13.815510557964274, 1e-9);
}

TEST(SlamOptions, ResampleModeNames) {
  EXPECT_EQ(to_string(ResampleMode::kEveryFrame), "every_frame");
  EXPECT_EQ(to_string(ResampleMode::kEffectiveSampleSize), "effective_sample_size");
}

}  // namespace
}  // namespace pixyslam::slam
