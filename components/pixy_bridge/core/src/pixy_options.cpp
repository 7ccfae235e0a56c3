#include "pixyslam/pixy/pixy_options.h"

#include <map>
#include <optional>
#include <string>

#include "pixyslam/config/yaml_reader.h"
#include "pixyslam/config/yaml_text.h"

namespace pixyslam::pixy {
namespace {

constexpr std::int64_t kMaxLandmarkId = 1000000;

constexpr const char* kSignatureHelp =
    "a landmarks key is a signature's tags as PixyMon shows them: 1 to 5 digits 1-7, e.g. \"12\" "
    "(or \"012\", \"0o12\"), mapped to an integer id";

SignatureMap read_landmarks(config::YamlReader& lm) {
  SignatureMap map;
  std::map<std::uint16_t, std::string> key_of_signature;
  std::map<std::int64_t, std::string> key_of_id;
  for (const std::string& key : lm.keys()) {
    const std::optional<std::uint16_t> sig = parse_signature(key);
    if (!sig) lm.fail(key, std::string("not a colour-code signature; ") + kSignatureHelp);
    const std::int64_t id = lm.integer(key, 0, kMaxLandmarkId);
    if (const auto it = key_of_signature.find(*sig); it != key_of_signature.end()) {
      lm.fail(key, "signature " + key + " is already given as key '" + it->second + "'");
    }
    if (const auto it = key_of_id.find(id); it != key_of_id.end()) {
      lm.fail(key, "landmark id " + std::to_string(id) + " is already given to key '" + it->second + "'");
    }
    key_of_signature.emplace(*sig, key);
    key_of_id.emplace(id, key);
    map.add(*sig, static_cast<int>(id));
  }
  lm.finish();
  return map;
}

}  // namespace

PixyOptions read_pixy_options(config::YamlReader& p) {
  PixyOptions o;
  CameraModel& c = o.camera;
  c.focal_length_mm = p.number("focal_length_mm", 0.1, 100.0, c.focal_length_mm);
  c.sensor_height_mm = p.number("sensor_height_mm", 0.1, 100.0, c.sensor_height_mm);
  c.image_width_px = static_cast<int>(p.integer("image_width_px", 1, 10000, c.image_width_px));
  c.image_height_px = static_cast<int>(p.integer("image_height_px", 1, 10000, c.image_height_px));
  // Square pixels unless told otherwise (the paper's Table 2 prints S_w = S_h).
  c.sensor_width_mm = p.number("sensor_width_mm", 0.1, 100.0,
                               c.sensor_height_mm * c.image_width_px / c.image_height_px);
  c.landmark_height_m = p.number("landmark_height_m", 1e-3, 100.0);
  c.min_height_to_width = p.number("min_height_to_width", 0.01, 100.0, c.min_height_to_width);
  c.max_height_to_width = p.number("max_height_to_width", 0.01, 100.0, c.max_height_to_width);
  c.aspect_tolerance_px = static_cast<int>(p.integer("aspect_tolerance_px", 0, 10, c.aspect_tolerance_px));
  if (c.max_height_to_width < c.min_height_to_width) {
    p.fail("max_height_to_width", "must be >= min_height_to_width");
  }
  c.range_sigma_fraction = p.number("range_sigma_fraction", 1e-6, 1.0, c.range_sigma_fraction);
  c.bearing_sigma_rad = p.number("bearing_sigma_rad", 1e-6, 1.0, c.bearing_sigma_rad);
  c.range_sigma_floor_m = p.number("range_sigma_floor_m", 0.0, 10.0, c.range_sigma_floor_m);
  c.block_height_sigma_px = p.number("block_height_sigma_px", 0.0, 100.0, c.block_height_sigma_px);
  FrameRateOptions& r = o.rate;
  r.frame_rate_hz = p.number("frame_rate_hz", 0.1, 1000.0, r.frame_rate_hz);
  // A little above the camera's rate unless told otherwise.
  r.max_frame_rate_hz = p.number("max_frame_rate_hz", 0.1, 10000.0, 1.2 * r.frame_rate_hz);
  if (r.max_frame_rate_hz < r.frame_rate_hz) {
    p.fail("max_frame_rate_hz", "value " + config::yaml_number(r.max_frame_rate_hz) +
                                    " is below frame_rate_hz (" + config::yaml_number(r.frame_rate_hz) +
                                    "): frames without blocks may come at the camera's rate");
  }
  r.tolerance_s = p.number("frame_rate_tolerance_s", 0.0, 10.0, r.tolerance_s);
  config::YamlReader lm = p.child("landmarks");
  o.signatures = read_landmarks(lm);
  p.finish();
  return o;
}

}  // namespace pixyslam::pixy
