// Tests of the Pixy camera geometry (seed paper Eq. 5 and 6) against numbers
// worked out by hand, the bearing sign convention, the aspect-ratio bounds, the
// block-to-detection conversion with its rejection counters, colour-code
// signature notation, and the YAML options loader's errors.

#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include <gtest/gtest.h>

#include "pixyslam/config/yaml_reader.h"
#include "pixyslam/pixy/pixy_geometry.h"
#include "pixyslam/pixy/pixy_options.h"

namespace pixyslam::pixy {
namespace {

PixyBlock block(std::uint16_t sig, bool cc, std::uint16_t x, std::uint16_t y, std::uint16_t w, std::uint16_t h) {
  PixyBlock b;
  b.signature = sig;
  b.colour_code = cc;
  b.x = x;
  b.y = y;
  b.width = w;
  b.height = h;
  return b;
}

CameraModel paper_camera(double landmark_height_m) {
  CameraModel c;  // f 2.8 mm, S_h 2.43 mm, S_w 3.888 mm, 320 x 200 px
  c.landmark_height_m = landmark_height_m;
  return c;
}

TEST(PixyGeometry, RangeFollowsEquation5) {
  // A pole h_r = 0.2 m tall seen h_s = 50 px tall: r = f h_r / S_h * I_h / h_s.
  const CameraModel c = paper_camera(0.2);
  EXPECT_NEAR(range_m(c, 50.0), 2.8 * 0.2 / 2.43 * 200.0 / 50.0, 1e-12);
  EXPECT_NEAR(range_m(c, 50.0), 0.9218106995884774, 1e-12);
  // Twice as tall in the image: half the range.
  EXPECT_NEAR(range_m(c, 100.0), 0.5 * range_m(c, 50.0), 1e-12);
  // The paper's 80 mm poles at 20 px.
  EXPECT_NEAR(range_m(paper_camera(0.08), 20.0), 2.8 * 0.08 / 2.43 * 200.0 / 20.0, 1e-12);
  EXPECT_TRUE(std::isinf(range_m(c, 0.0)));
}

TEST(PixyGeometry, BearingFollowsEquation6WithLeftPositive) {
  const CameraModel c = paper_camera(0.08);
  // Image centre: on the optical axis.
  EXPECT_EQ(bearing_rad(c, 160.0), 0.0);
  // Left of centre is counter-clockwise (positive), right is negative.
  EXPECT_GT(bearing_rad(c, 100.0), 0.0);
  EXPECT_LT(bearing_rad(c, 200.0), 0.0);
  EXPECT_NEAR(bearing_rad(c, 160.0 + 37.0), -bearing_rad(c, 160.0 - 37.0), 1e-15);
  // 80 px right of centre: w_s = -80 px, atan(-80 * 3.888 / (2.8 * 320)).
  EXPECT_NEAR(bearing_rad(c, 240.0), std::atan(-80.0 * 3.888 / (2.8 * 320.0)), 1e-15);
  EXPECT_NEAR(bearing_rad(c, 240.0), -0.334127, 1e-6);
  // Field-of-view edges: x = 0 gives +atan(S_w / 2 / f), x = I_w the negative.
  const double half_fov = std::atan(3.888 / 2.0 / 2.8);
  EXPECT_NEAR(bearing_rad(c, 0.0), half_fov, 1e-15);
  EXPECT_NEAR(bearing_rad(c, 320.0), -half_fov, 1e-15);
  EXPECT_NEAR(2.0 * half_fov * 180.0 / M_PI, 69.54, 0.01);  // degrees, horizontal
  // With the paper's Table 2 sensor width (2.43 mm) the edge is atan(1.215 / 2.8).
  CameraModel table2 = c;
  table2.sensor_width_mm = 2.43;
  EXPECT_NEAR(bearing_rad(table2, 0.0), std::atan(2.43 / 2.0 / 2.8), 1e-15);
}

// The inverse (simulator, synthetic camera, calibration) and Eq. 5/6 undo
// each other: range -> block height -> range, bearing -> column -> bearing.
TEST(PixyGeometry, InverseOfEquations5And6RoundTrips) {
  CameraModel c = paper_camera(0.08);
  c.sensor_width_mm = 4.1;  // not square pixels: S_w must be the one used for columns
  for (const double r : {0.2, 0.5, 1.0, 2.5, 7.0}) {
    EXPECT_NEAR(range_m(c, block_height_px(c, r)), r, 1e-12 * r) << r;
  }
  for (const double phi : {-0.6, -0.1, 0.0, 0.05, 0.6}) {
    EXPECT_NEAR(bearing_rad(c, block_x_px(c, phi)), phi, 1e-12) << phi;
  }
  EXPECT_DOUBLE_EQ(block_x_px(c, 0.0), 0.5 * c.image_width_px);  // straight ahead: the image centre
  EXPECT_LT(block_x_px(c, 0.3), block_x_px(c, 0.0));  // left of the axis: smaller columns
  EXPECT_NEAR(px_per_tan(c) * std::tan(0.3), 0.5 * c.image_width_px - block_x_px(c, 0.3), 1e-9);
}

TEST(PixyGeometry, AspectBoundsAreInclusive) {
  const CameraModel c = paper_camera(0.08);  // [2.0, 2.2]
  EXPECT_TRUE(aspect_ok(c, block(1, false, 160, 100, 10, 20)));   // 2.0
  EXPECT_TRUE(aspect_ok(c, block(1, false, 160, 100, 10, 22)));   // 2.2
  EXPECT_TRUE(aspect_ok(c, block(1, false, 160, 100, 10, 21)));   // 2.1
  EXPECT_FALSE(aspect_ok(c, block(1, false, 160, 100, 10, 19)));  // 1.9
  EXPECT_FALSE(aspect_ok(c, block(1, false, 160, 100, 10, 23)));  // 2.3
  EXPECT_FALSE(aspect_ok(c, block(1, false, 160, 100, 100, 199)));  // 1.99
  EXPECT_FALSE(aspect_ok(c, block(1, false, 160, 100, 90, 199)));   // 2.2111
  EXPECT_FALSE(aspect_ok(c, block(1, false, 160, 100, 0, 20)));
  EXPECT_FALSE(aspect_ok(c, block(1, false, 160, 100, 10, 0)));
  // Exactly on a bound is accepted for every width (no rounding surprise).
  for (std::uint16_t w = 1; w <= 90; ++w) {
    EXPECT_TRUE(aspect_ok(c, block(1, false, 160, 100, w, static_cast<std::uint16_t>(2 * w)))) << w;
    if (w % 5 == 0) {
      EXPECT_TRUE(aspect_ok(c, block(1, false, 160, 100, w, static_cast<std::uint16_t>(11 * w / 5)))) << w;
    }
  }
}

TEST(PixyGeometry, AspectToleranceForgivesOnePixelOfRounding) {
  CameraModel c;
  EXPECT_FALSE(aspect_ok(c, block(1, false, 160, 100, 8, 18)));  // 2.25: a 18 x 8.6 px pole rounded down
  EXPECT_FALSE(aspect_ok(c, block(1, false, 160, 100, 10, 19)));  // 1.9
  c.aspect_tolerance_px = 1;
  EXPECT_TRUE(aspect_ok(c, block(1, false, 160, 100, 8, 18)));   // 17 / 8 = 2.125 is possible
  EXPECT_TRUE(aspect_ok(c, block(1, false, 160, 100, 10, 19)));  // 20 / 10
  EXPECT_FALSE(aspect_ok(c, block(1, false, 160, 100, 10, 30)));  // 29 / 11 = 2.6: still a wrong shape
  EXPECT_FALSE(aspect_ok(c, block(1, false, 160, 100, 10, 12)));  // 13 / 9 = 1.4
}

TEST(PixyGeometry, SignatureNotation) {
  EXPECT_EQ(parse_signature("12"), std::optional<std::uint16_t>(012));
  EXPECT_EQ(parse_signature("012"), std::optional<std::uint16_t>(10));
  EXPECT_EQ(parse_signature("0o12"), std::optional<std::uint16_t>(10));
  EXPECT_EQ(parse_signature("0123"), std::optional<std::uint16_t>(83));
  EXPECT_EQ(parse_signature("1"), std::optional<std::uint16_t>(1));
  EXPECT_EQ(parse_signature("77777"), std::optional<std::uint16_t>(32767));
  for (const char* bad : {"", "0", "00", "0o", "10", "18", "8", "123456", "012x", "-12", "0x12", "0O12"}) {
    EXPECT_FALSE(parse_signature(bad).has_value()) << bad;
  }
  EXPECT_EQ(signature_tags(10), "12");
  EXPECT_EQ(signature_tags(83), "123");
  EXPECT_EQ(signature_tags(8), "");  // 010: tag 0 does not exist
  EXPECT_EQ(signature_tags(0), "");
  EXPECT_TRUE(valid_signature(7));
  EXPECT_TRUE(valid_signature(077777));
  EXPECT_FALSE(valid_signature(0100000));  // a sixth digit

  SignatureMap m;
  m.add(012, 1);
  EXPECT_THROW(m.add(012, 2), std::invalid_argument);
  EXPECT_THROW(m.add(013, 1), std::invalid_argument);
  EXPECT_THROW(m.add(010, 3), std::invalid_argument);
  EXPECT_THROW(m.add(013, -1), std::invalid_argument);
  // A colour code matches only colour-code blocks, a single tag only normal ones.
  m.add(3, 5);
  EXPECT_EQ(m.landmark_of(block(012, true, 0, 0, 1, 2)), std::optional<int>(1));
  EXPECT_FALSE(m.landmark_of(block(012, false, 0, 0, 1, 2)).has_value());
  EXPECT_EQ(m.landmark_of(block(3, false, 0, 0, 1, 2)), std::optional<int>(5));
  EXPECT_FALSE(m.landmark_of(block(3, true, 0, 0, 1, 2)).has_value());
}

TEST(PixyGeometry, FrameToDetectionsCountsEveryRejection) {
  CameraModel c = paper_camera(0.08);
  c.range_sigma_fraction = 0.1;
  c.bearing_sigma_rad = 0.03;
  SignatureMap m;
  m.add(012, 1);
  m.add(013, 2);
  m.add(3, 7);
  PixyFrame f;
  f.blocks = {
      block(012, true, 100, 90, 10, 21),   // landmark 1, small
      block(014, true, 160, 100, 10, 21),  // unknown signature
      block(3, false, 50, 100, 0, 0),      // zero height
      block(013, true, 200, 100, 20, 30),  // aspect 1.5
      block(012, false, 160, 100, 10, 21), // colour code sent as a normal block: unknown
      block(013, true, 400, 100, 10, 21),  // centre beyond the image
      block(012, true, 240, 100, 20, 44),  // landmark 1 again, larger: replaces the first
      block(3, false, 160, 100, 20, 40),   // landmark 7
      block(012, true, 10, 100, 10, 20),   // landmark 1, smaller: duplicate
  };
  DetectionCounters n;
  const std::vector<Detection> d = to_detections(f, m, c, n);
  ASSERT_EQ(d.size(), 2u);
  EXPECT_EQ(d[0].landmark_id, 1);
  EXPECT_EQ(d[0].block, f.blocks[6]);
  EXPECT_NEAR(d[0].range_m, 2.8 * 0.08 / 2.43 * 200.0 / 44.0, 1e-12);
  EXPECT_NEAR(d[0].bearing_rad, std::atan(-80.0 * 3.888 / (2.8 * 320.0)), 1e-12);
  EXPECT_NEAR(d[0].range_sigma_m, 0.1 * d[0].range_m, 1e-15);
  EXPECT_EQ(d[0].bearing_sigma_rad, 0.03);
  EXPECT_EQ(d[1].landmark_id, 7);
  EXPECT_NEAR(d[1].range_m, 2.8 * 0.08 / 2.43 * 200.0 / 40.0, 1e-12);
  EXPECT_EQ(d[1].bearing_rad, 0.0);
  EXPECT_EQ(n.blocks, 9u);
  EXPECT_EQ(n.detections, 2u);
  EXPECT_EQ(n.unknown_signature, 2u);
  EXPECT_EQ(n.zero_height, 1u);
  EXPECT_EQ(n.bad_aspect, 1u);
  EXPECT_EQ(n.outside_image, 1u);
  EXPECT_EQ(n.duplicate_landmark, 2u);
  // Counters accumulate across frames.
  to_detections(f, m, c, n);
  EXPECT_EQ(n.blocks, 18u);
  EXPECT_EQ(n.detections, 4u);
}

TEST(PixyGeometry, ValidateNamesTheBadField) {
  CameraModel c;
  EXPECT_NO_THROW(validate(c));
  c.max_height_to_width = 1.9;
  try {
    validate(c);
    ADD_FAILURE() << "expected std::invalid_argument";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("max_height_to_width"), std::string::npos) << e.what();
  }
  c = CameraModel{};
  c.focal_length_mm = 0.0;
  EXPECT_THROW(validate(c), std::invalid_argument);
}

// --- YAML options -----------------------------------------------------------

const char* const kDefaultYaml = R"(pixy:
  focal_length_mm: 2.8
  sensor_height_mm: 2.43
  image_width_px: 320
  image_height_px: 200
  landmark_height_m: 0.08
  min_height_to_width: 2.0
  max_height_to_width: 2.2
  range_sigma_fraction: 0.05
  bearing_sigma_rad: 0.027
  landmarks:
    "12": 1
    "13": 2
    0o14: 3
    0123: 4
    7: 5
)";

PixyOptions load(const std::string& text) {
  config::YamlReader root = config::YamlReader::from_string(text, "pixy_test.yaml");
  config::YamlReader pixy = root.child("pixy");
  PixyOptions o = read_pixy_options(pixy);
  root.finish();
  return o;
}

// The ConfigError message of loading `text` ("" and a failure if none).
std::string error_of(const std::string& text) {
  try {
    load(text);
  } catch (const config::ConfigError& e) {
    return e.what();
  }
  ADD_FAILURE() << "expected ConfigError for:\n" << text;
  return "";
}

// kDefaultYaml with `from` replaced by `to`.
std::string edited(const std::string& from, const std::string& to) {
  std::string s = kDefaultYaml;
  const std::size_t at = s.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  return s.replace(at, from.size(), to);
}

TEST(PixyOptions, ReadsTheDefaultConfig) {
  const PixyOptions o = load(kDefaultYaml);
  EXPECT_EQ(o.camera.focal_length_mm, 2.8);
  EXPECT_EQ(o.camera.sensor_height_mm, 2.43);
  EXPECT_NEAR(o.camera.sensor_width_mm, 2.43 * 320.0 / 200.0, 1e-12);  // derived: square pixels
  EXPECT_EQ(o.camera.image_width_px, 320);
  EXPECT_EQ(o.camera.image_height_px, 200);
  EXPECT_EQ(o.camera.landmark_height_m, 0.08);
  EXPECT_EQ(o.camera.min_height_to_width, 2.0);
  EXPECT_EQ(o.camera.max_height_to_width, 2.2);
  EXPECT_EQ(o.camera.range_sigma_fraction, 0.05);
  EXPECT_EQ(o.camera.bearing_sigma_rad, 0.027);
  EXPECT_NO_THROW(validate(o.camera));
  const std::map<std::uint16_t, int> want = {{012, 1}, {013, 2}, {014, 3}, {0123, 4}, {7, 5}};
  EXPECT_EQ(o.signatures.entries(), want);
}

TEST(PixyOptions, OptionalKeysTakeThePaperDefaultsAndSensorWidthCanBeSet) {
  const PixyOptions o = load("pixy:\n  landmark_height_m: 0.2\n  sensor_width_mm: 2.43\n  landmarks: {}\n");
  EXPECT_EQ(o.camera.focal_length_mm, 2.8);
  EXPECT_EQ(o.camera.sensor_width_mm, 2.43);
  EXPECT_EQ(o.camera.landmark_height_m, 0.2);
  EXPECT_EQ(o.camera.min_height_to_width, 2.0);
  EXPECT_EQ(o.camera.max_height_to_width, 2.2);
  EXPECT_EQ(o.signatures.size(), 0u);
}

TEST(PixyOptions, ErrorsNameTheFileAndKeyPath) {
  struct Case {
    std::string yaml;
    std::string key;
    std::string what;
  };
  const Case cases[] = {
      {edited("focal_length_mm: 2.8", "focal_lenght_mm: 2.8"), "'pixy.focal_lenght_mm'", "unknown key"},
      {edited("focal_length_mm: 2.8", "focal_length_mm: wide"), "'pixy.focal_length_mm'", "finite number"},
      {edited("image_width_px: 320", "image_width_px: 0"), "'pixy.image_width_px'", "out of range"},
      {edited("image_width_px: 320", "image_width_px: 320.5"), "'pixy.image_width_px'", "integer"},
      {edited("range_sigma_fraction: 0.05", "range_sigma_fraction: 0"), "'pixy.range_sigma_fraction'",
       "out of range"},
      {edited("  landmark_height_m: 0.08\n", ""), "'pixy.landmark_height_m'", "missing"},
      {edited("max_height_to_width: 2.2", "max_height_to_width: 1.9"), "'pixy.max_height_to_width'",
       ">= min_height_to_width"},
      {edited("\"13\": 2", "\"012\": 2"), "'pixy.landmarks.012'", "already given as key '12'"},
      {edited("\"13\": 2", "\"13\": 1"), "'pixy.landmarks.13'", "landmark id 1 is already given to key '12'"},
      {edited("\"13\": 2", "\"18\": 2"), "'pixy.landmarks.18'", "not a colour-code signature"},
      {edited("\"13\": 2", "\"123456\": 2"), "'pixy.landmarks.123456'", "1 to 5"},
      {edited("\"13\": 2", "\"13\": two"), "'pixy.landmarks.13'", "integer"},
      {edited("\"13\": 2", "\"13\": -2"), "'pixy.landmarks.13'", "out of range"},
      {edited("\"13\": 2", "\"13\": [2]"), "'pixy.landmarks.13'", "single value"},
      {"pixy:\n  landmark_height_m: 0.08\n  landmarks:\n    - {signature: 12, id: 1}\n", "'pixy.landmarks'",
       "expected a mapping"},
      {"pixy:\n  landmark_height_m: 0.08\n", "'pixy.landmarks'", "missing"},
  };
  for (const Case& c : cases) {
    const std::string msg = error_of(c.yaml);
    EXPECT_NE(msg.find("pixy_test.yaml"), std::string::npos) << msg;
    EXPECT_NE(msg.find(c.key), std::string::npos) << msg;
    EXPECT_NE(msg.find(c.what), std::string::npos) << msg;
  }
}

TEST(PixyOptions, ReadsAFullSizedLandmarkTable) {
  // Every spelling of every signature is looked up (YamlReader cannot list
  // keys): a table of two- to five-tag codes in all three spellings comes back whole.
  std::string yaml = "pixy:\n  landmark_height_m: 0.08\n  landmarks:\n";
  const char* const keys[] = {"12", "013", "0o14", "15", "16", "17", "21", "23", "24", "25", "26", "27", "31",
                              "32", "34", "35", "36", "37", "41", "42", "43", "45", "46", "47", "0123", "1234",
                              "0o12345"};
  int id = 100;
  for (const char* key : keys) yaml += "    " + std::string(key) + ": " + std::to_string(id++) + "\n";
  const PixyOptions o = load(yaml);
  ASSERT_EQ(o.signatures.size(), 27u);
  id = 100;
  for (const char* key : keys) {
    EXPECT_EQ(o.signatures.landmark_of_signature(*parse_signature(key)), std::optional<int>(id++)) << key;
  }
  EXPECT_EQ(o.signatures.landmark_of_signature(012345), std::optional<int>(126));
}

}  // namespace
}  // namespace pixyslam::pixy

// config/pixy_bridge.yaml as shipped.
TEST(PixyOptions, ShippedConfigLoads) {
  pixyslam::config::YamlReader root =
      pixyslam::config::YamlReader::from_file(std::string(PIXYSLAM_CONFIG_DIR) + "/pixy_bridge.yaml");
  pixyslam::config::YamlReader pixy = root.child("pixy");
  const pixyslam::pixy::PixyOptions o = pixyslam::pixy::read_pixy_options(pixy);
  root.child("node");  // the process's own mappings, read by the pixy node
  root.child("dds");
  root.finish();
  EXPECT_EQ(o.signatures.entries().size(), 20u);
  EXPECT_DOUBLE_EQ(o.camera.focal_length_mm, 2.8);
}

TEST(RangeSigma, CombinesFloorFractionAndPixelError) {
  pixyslam::pixy::CameraModel c;
  c.range_sigma_floor_m = 0.07;
  c.range_sigma_fraction = 0.01;
  c.block_height_sigma_px = 0.5;
  // At 2 m from a 9.2 px block: sqrt(0.07^2 + 0.02^2 + (2 * 0.5 / 9.2)^2).
  EXPECT_NEAR(pixyslam::pixy::range_sigma_m(c, 2.0, 9.2), std::sqrt(0.0049 + 0.0004 + std::pow(1.0 / 9.2, 2)), 1e-12);
  // The pixel term grows with the square of the range at fixed pole size.
  const double near = pixyslam::pixy::range_sigma_m(c, 0.5, 36.8);
  const double far = pixyslam::pixy::range_sigma_m(c, 3.0, 6.13);
  EXPECT_LT(near, 0.075);
  EXPECT_GT(far, 0.25);
}
