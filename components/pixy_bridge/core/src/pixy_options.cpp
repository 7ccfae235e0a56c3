#include "pixyslam/pixy/pixy_options.h"

#include <map>
#include <optional>
#include <string>

#include "pixyslam/config/parameters_yaml.h"
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
  // Keys whose default follows from others: read with the others' values.
  const bool sensor_width_given = p.has("sensor_width_mm");
  const bool max_rate_given = p.has("max_frame_rate_hz");
  config::read_parameters(p, camera_parameters(), o.camera);
  config::read_parameters(p, frame_rate_parameters(), o.rate);
  CameraModel& c = o.camera;
  // Square pixels unless told otherwise (the paper's Table 2 prints S_w = S_h).
  if (!sensor_width_given) c.sensor_width_mm = c.sensor_height_mm * c.image_width_px / c.image_height_px;
  // A little above the camera's rate unless told otherwise.
  if (!max_rate_given) o.rate.max_frame_rate_hz = 1.2 * o.rate.frame_rate_hz;
  config::check_rules(p, [&] { validate(c); });
  config::check_rules(p, [&] { validate(o.rate); });
  config::YamlReader lm = p.child("landmarks");
  o.signatures = read_landmarks(lm);
  p.finish();
  return o;
}

}  // namespace pixyslam::pixy
