#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "pixyslam/parameters/parameters.h"
#include "pixyslam/pixy/pixy_block_parser.h"

namespace pixyslam::pixy {

// How the Pixy camera sees a landmark pole, after the seed paper (Sec. 3.2,
// Table 2): pinhole optics, a pole of known height h_r, and the pole's
// height/width ratio in the image as a sanity check. Lengths on the sensor in
// mm, in the world in m, in the image in px. Camera frame: x forward along the
// optical axis, y to the left; the camera sits at the robot's origin facing
// forward. A plain value; validate() checks it.
struct CameraModel {
  double focal_length_mm = 2.8;   // f
  double sensor_width_mm = 3.888;  // S_w (sensor_height_mm * 320 / 200, square pixels)
  double sensor_height_mm = 2.43;  // S_h
  int image_width_px = 320;        // I_w
  int image_height_px = 200;       // I_h

  double landmark_height_m = 0.08;  // h_r (the paper's poles: 80 mm tall, 40 mm wide)
  // Accepted block height/width ratio, both bounds inclusive (paper: 2.0 to 2.2).
  double min_height_to_width = 2.0;
  double max_height_to_width = 2.2;
  // Pixels of rounding the check forgives in width and height: 0 is the
  // paper's exact check; a camera whose small blocks are whole-pixel boxes
  // needs 1 (a 18 x 9 px pole is 2.0, 18 x 8 px 2.25).
  int aspect_tolerance_px = 0;

  // Noise attached to every detection (see range_sigma_m below): a floor, a
  // fraction of the range, and the block height's pixel error through Eq. 5
  // (dr/r = -dh_s/h_s: one pixel matters more the smaller the block).
  double range_sigma_fraction = 0.05;
  double range_sigma_floor_m = 0.0;
  double block_height_sigma_px = 0.0;
  double bearing_sigma_rad = 0.027;
};

// One declaration per field: its `pixy:` key, range, unit and help.
const parameters::Table<CameraModel>& camera_parameters();

// Throws std::invalid_argument naming the first field out of its range
// (camera_parameters()) or max_height_to_width < min_height_to_width.
void validate(const CameraModel& camera);

// Range to a pole whose block is `block_height_px` tall, seed paper Eq. 5:
//   r = f * h_r / S_h * I_h / h_s.
// (Strictly the depth along the optical axis; the paper uses it as the range.)
// Infinite for a height of 0.
double range_m(const CameraModel& camera, double block_height_px);

// Range sd of a detection at `range` from a block `block_height_px` tall:
//   sqrt(floor^2 + (fraction r)^2 + (r sigma_px / h_s)^2).
double range_sigma_m(const CameraModel& camera, double range, double block_height_px);

// Bearing to a block centred on column `block_x_px`, seed paper Eq. 6:
//   phi = atan(w_s * S_w / (f * I_w)), w_s = I_w / 2 - x.
// Positive = counter-clockwise = left of the optical axis, as the filter's
// bearings: a block right of the image centre (x > I_w / 2) has a negative
// bearing, x = 0 gives +atan(S_w / (2 f)), the left edge of the field of view.
double bearing_rad(const CameraModel& camera, double block_x_px);

// The inverse of Eq. 5 and 6 (rendering a pole, simulating a camera):
// Eq. 5 solved for the block height at `range_m`, h_s = f h_r I_h / (S_h r);
double block_height_px(const CameraModel& camera, double range_m);
// Eq. 6 solved for the column of a block at `bearing_rad`, x = I_w / 2 - tan(phi) f I_w / S_w;
double block_x_px(const CameraModel& camera, double bearing_rad);
// f I_w / S_w: pixels per unit of tan(bearing); an object w m wide at range r
// spans w / r times this many columns.
double px_per_tan(const CameraModel& camera);

// Height/width ratio within [min_height_to_width, max_height_to_width]
// (inclusive). False for a zero width or height.
bool aspect_ok(const CameraModel& camera, const PixyBlock& block);

// Raw Pixy signature of a colour code or a single signature, from its tags as
// PixyMon shows them: "12" (tags 1 then 2), with an optional "0" or "0o" prefix
// ("012", "0o12"): all three give 012 octal = 10. One to five tags, each 1..7.
// The digits are never read as a decimal number. Empty if the text is not such a code.
std::optional<std::uint16_t> parse_signature(std::string_view text);
// The tags of a raw signature, e.g. 10 -> "12". Empty if it is not a valid signature.
std::string signature_tags(std::uint16_t signature);
// True if the raw value is 1..7 or an octal code of 2 to 5 tags 1..7.
bool valid_signature(std::uint16_t signature);

// Which landmark each colour-code signature marks; one landmark per signature
// and one signature per landmark. A single-tag signature (1..7) matches normal
// blocks, a multi-tag one colour-code blocks. Thread-compatible.
class SignatureMap {
 public:
  // Throws std::invalid_argument for an invalid signature, a negative id, or a
  // signature or id that is already mapped.
  void add(std::uint16_t signature, int landmark_id);
  // The landmark of a block, if its signature is mapped and of the block's kind.
  std::optional<int> landmark_of(const PixyBlock& block) const;
  std::optional<int> landmark_of_signature(std::uint16_t signature) const;
  const std::map<std::uint16_t, int>& entries() const { return by_signature_; }
  std::size_t size() const { return by_signature_.size(); }

 private:
  std::map<std::uint16_t, int> by_signature_;
  std::map<int, std::uint16_t> by_landmark_;
};

// A landmark measurement in the camera frame (see CameraModel), with the block
// it came from.
struct Detection {
  int landmark_id = 0;
  double range_m = 0.0;
  double bearing_rad = 0.0;  // counter-clockwise from the optical axis
  double range_sigma_m = 0.0;
  double bearing_sigma_rad = 0.0;
  PixyBlock block;
};

// Why blocks were turned into detections or not; running totals.
struct DetectionCounters {
  std::uint64_t blocks = 0;              // blocks examined
  std::uint64_t detections = 0;          // blocks turned into detections
  std::uint64_t unknown_signature = 0;   // signature not in the map (or wrong block kind)
  std::uint64_t zero_height = 0;         // height 0 px: no range
  std::uint64_t outside_image = 0;       // centre or size beyond the image
  std::uint64_t bad_aspect = 0;          // height/width outside the bounds (incl. width 0)
  std::uint64_t duplicate_landmark = 0;  // a larger block of the same landmark is in the frame
};

// The detections of one frame, in block order. Each block is checked in this
// order: signature mapped, height > 0, inside the image (centre and size),
// aspect ratio; the first failure is counted. When several blocks of one frame
// pass for the same landmark, one detection is kept, from the largest block
// (width * height; the earlier on a tie), at the place of the first; the others
// are counted as duplicates. Range and bearing per Eq. 5 and 6, sigmas from the
// camera model.
std::vector<Detection> to_detections(const PixyFrame& frame, const SignatureMap& signatures,
                                     const CameraModel& camera, DetectionCounters& counters);

}  // namespace pixyslam::pixy
