#include "pixyslam/pixy/pixy_geometry.h"

#include <cmath>
#include <limits>
#include <stdexcept>

namespace pixyslam::pixy {
namespace {

constexpr int kMaxTags = 5;

}  // namespace

const parameters::Table<CameraModel>& camera_parameters() {
  using O = CameraModel;
  namespace P = parameters;
  static const P::Table<O> table = {
      P::real<O>("focal_length_mm", 0.1, 100.0, "mm", "f, the lens's focal length",
                 [](O& o) -> double& { return o.focal_length_mm; }),
      P::real<O>("sensor_height_mm", 0.1, 100.0, "mm", "S_h, the sensor's height",
                 [](O& o) -> double& { return o.sensor_height_mm; }),
      P::real<O>("sensor_width_mm", 0.1, 100.0, "mm", "S_w, the sensor's width (default: square pixels)",
                 [](O& o) -> double& { return o.sensor_width_mm; }),
      P::integer<O, int>("image_width_px", 1, 10000, "px", "I_w", [](O& o) -> int& { return o.image_width_px; }),
      P::integer<O, int>("image_height_px", 1, 10000, "px", "I_h", [](O& o) -> int& { return o.image_height_px; }),
      P::required(P::real<O>("landmark_height_m", 1e-3, 100.0, "m", "h_r, the poles' height",
                             [](O& o) -> double& { return o.landmark_height_m; })),
      P::real<O>("min_height_to_width", 0.01, 100.0, "", "smallest block height/width ratio accepted",
                 [](O& o) -> double& { return o.min_height_to_width; }),
      P::real<O>("max_height_to_width", 0.01, 100.0, "", "largest block height/width ratio accepted (>= min)",
                 [](O& o) -> double& { return o.max_height_to_width; }),
      P::integer<O, int>("aspect_tolerance_px", 0, 10, "px", "pixels of rounding the ratio check forgives",
                         [](O& o) -> int& { return o.aspect_tolerance_px; }),
      P::real<O>("range_sigma_fraction", 1e-6, 1.0, "", "range sd as a fraction of the range",
                 [](O& o) -> double& { return o.range_sigma_fraction; }),
      P::real<O>("bearing_sigma_rad", 1e-6, 1.0, "rad", "bearing sd", [](O& o) -> double& { return o.bearing_sigma_rad; }),
      P::real<O>("range_sigma_floor_m", 0.0, 10.0, "m", "range sd floor",
                 [](O& o) -> double& { return o.range_sigma_floor_m; }),
      P::real<O>("block_height_sigma_px", 0.0, 100.0, "px", "block height error, through Eq. 5 into the range sd",
                 [](O& o) -> double& { return o.block_height_sigma_px; }),
  };
  return table;
}

void validate(const CameraModel& c) {
  parameters::check_ranges(c, camera_parameters(), "pixy");
  if (!(c.max_height_to_width >= c.min_height_to_width)) {
    throw parameters::RuleError("pixy", "max_height_to_width",
                                "value " + parameters::number_text(c.max_height_to_width) +
                                    " must be >= min_height_to_width (" + parameters::number_text(c.min_height_to_width) +
                                    ")");
  }
}

double block_height_px(const CameraModel& c, double range) {
  return c.focal_length_mm * c.landmark_height_m * c.image_height_px / (c.sensor_height_mm * range);
}

double px_per_tan(const CameraModel& c) { return c.focal_length_mm * c.image_width_px / c.sensor_width_mm; }

double block_x_px(const CameraModel& c, double bearing) { return 0.5 * c.image_width_px - std::tan(bearing) * px_per_tan(c); }

double range_sigma_m(const CameraModel& c, double range, double block_height_px) {
  const double proportional = c.range_sigma_fraction * range;
  const double pixel = block_height_px > 0.0 ? range * c.block_height_sigma_px / block_height_px : 0.0;
  return std::sqrt(c.range_sigma_floor_m * c.range_sigma_floor_m + proportional * proportional + pixel * pixel);
}

double range_m(const CameraModel& c, double block_height_px) {
  if (block_height_px <= 0.0) return std::numeric_limits<double>::infinity();
  // Seed paper Eq. 5: r = f * h_r / S_h * I_h / h_s (f and S_h in mm cancel).
  return c.focal_length_mm * c.landmark_height_m / c.sensor_height_mm * c.image_height_px / block_height_px;
}

double bearing_rad(const CameraModel& c, double block_x_px) {
  // Seed paper Eq. 6: phi = atan(w_s * S_w / (f * I_w)), with the offset w_s
  // taken from the image centre towards the left so that left is positive.
  const double w_s_px = 0.5 * c.image_width_px - block_x_px;
  return std::atan(w_s_px * c.sensor_width_mm / (c.focal_length_mm * c.image_width_px));
}

bool aspect_ok(const CameraModel& c, const PixyBlock& b) {
  if (b.width == 0 || b.height == 0) return false;
  // h_s / w_s within [2.0, 2.2] in the paper. A quotient of small integers is
  // correctly rounded, so a ratio exactly on a bound compares equal to it.
  const double h = b.height, w = b.width, tol = c.aspect_tolerance_px;
  // The highest and lowest ratio the block could have with its sides tol px off.
  const double highest = (h + tol) / std::max(1.0, w - tol);
  const double lowest = std::max(0.0, h - tol) / (w + tol);
  return highest >= c.min_height_to_width && lowest <= c.max_height_to_width;
}

std::optional<std::uint16_t> parse_signature(std::string_view text) {
  if (text.size() >= 2 && text[0] == '0' && text[1] == 'o') {
    text.remove_prefix(2);
  } else if (text.size() >= 2 && text[0] == '0') {
    text.remove_prefix(1);
  }
  if (text.empty() || text.size() > kMaxTags) return std::nullopt;
  std::uint16_t value = 0;
  for (char ch : text) {
    if (ch < '1' || ch > '7') return std::nullopt;
    value = static_cast<std::uint16_t>(value * 8 + (ch - '0'));
  }
  return value;
}

std::string signature_tags(std::uint16_t signature) {
  std::string tags;
  for (std::uint16_t s = signature; s != 0; s = static_cast<std::uint16_t>(s / 8)) {
    const int tag = s % 8;
    if (tag == 0) return "";
    tags.insert(tags.begin(), static_cast<char>('0' + tag));
  }
  if (tags.size() > kMaxTags) return "";
  return tags;
}

bool valid_signature(std::uint16_t signature) { return !signature_tags(signature).empty(); }

void SignatureMap::add(std::uint16_t signature, int landmark_id) {
  if (!valid_signature(signature)) {
    throw std::invalid_argument("SignatureMap: " + std::to_string(signature) +
                                " is not a Pixy signature (1 to 5 tags, each 1..7)");
  }
  if (landmark_id < 0) throw std::invalid_argument("SignatureMap: landmark id must be >= 0");
  if (by_signature_.count(signature)) {
    throw std::invalid_argument("SignatureMap: signature " + signature_tags(signature) + " is already mapped");
  }
  if (by_landmark_.count(landmark_id)) {
    throw std::invalid_argument("SignatureMap: landmark " + std::to_string(landmark_id) +
                                " already has signature " + signature_tags(by_landmark_.at(landmark_id)));
  }
  by_signature_.emplace(signature, landmark_id);
  by_landmark_.emplace(landmark_id, signature);
}

std::optional<int> SignatureMap::landmark_of_signature(std::uint16_t signature) const {
  const auto it = by_signature_.find(signature);
  if (it == by_signature_.end()) return std::nullopt;
  return it->second;
}

std::optional<int> SignatureMap::landmark_of(const PixyBlock& block) const {
  // Single tags (1..7) are normal signatures; colour codes have at least two tags.
  const bool multi_tag = block.signature > 7;
  if (multi_tag != block.colour_code) return std::nullopt;
  return landmark_of_signature(block.signature);
}

std::vector<Detection> to_detections(const PixyFrame& frame, const SignatureMap& signatures,
                                     const CameraModel& camera, DetectionCounters& counters) {
  std::vector<Detection> out;
  out.reserve(frame.blocks.size());
  for (const PixyBlock& b : frame.blocks) {
    ++counters.blocks;
    const std::optional<int> id = signatures.landmark_of(b);
    if (!id) {
      ++counters.unknown_signature;
      continue;
    }
    if (b.height == 0) {
      ++counters.zero_height;
      continue;
    }
    if (b.x > camera.image_width_px || b.y > camera.image_height_px || b.width > camera.image_width_px ||
        b.height > camera.image_height_px) {
      ++counters.outside_image;
      continue;
    }
    if (!aspect_ok(camera, b)) {
      ++counters.bad_aspect;
      continue;
    }
    Detection d;
    d.landmark_id = *id;
    d.range_m = range_m(camera, b.height);
    d.bearing_rad = bearing_rad(camera, b.x);
    d.range_sigma_m = range_sigma_m(camera, d.range_m, b.height);
    d.bearing_sigma_rad = camera.bearing_sigma_rad;
    d.block = b;

    // One detection per landmark: keep the largest block.
    bool keep = true;
    for (Detection& other : out) {
      if (other.landmark_id != d.landmark_id) continue;
      const auto area = [](const PixyBlock& x) { return std::uint32_t{x.width} * x.height; };
      if (area(d.block) > area(other.block)) {
        other = d;  // replaces the smaller one in its place
      }
      keep = false;
      ++counters.duplicate_landmark;
      break;
    }
    if (keep) out.push_back(d);
  }
  counters.detections += out.size();
  return out;
}

}  // namespace pixyslam::pixy
