#pragma once

#include "pixyslam/pixy/frame_rate_limiter.h"
#include "pixyslam/pixy/pixy_geometry.h"

namespace pixyslam::config {
class YamlReader;
}

namespace pixyslam::pixy {

// Everything the Pixy core needs from configuration: the camera and landmark
// model, which colour code marks which landmark, and how fast frames may come.
// A plain value.
struct PixyOptions {
  CameraModel camera;
  SignatureMap signatures;
  FrameRateOptions rate;  // warn_period_s is not read from the file
};

// Reads a `pixy:` mapping (every key but the two required ones has the paper's
// default):
//
//   focal_length_mm: 2.8        # f
//   sensor_height_mm: 2.43      # S_h
//   sensor_width_mm: 3.888      # S_w; default sensor_height_mm * I_w / I_h
//   image_width_px: 320         # I_w
//   image_height_px: 200        # I_h
//   landmark_height_m: 0.08     # h_r, required
//   min_height_to_width: 2.0    # block height/width bounds, inclusive
//   max_height_to_width: 2.2
//   range_sigma_fraction: 0.05  # range sd = fraction * range
//   bearing_sigma_rad: 0.027
//   frame_rate_hz: 50           # the camera's frame rate: the most frames without blocks per second
//   max_frame_rate_hz: 60       # the most frames per second; default 1.2 * frame_rate_hz
//   frame_rate_tolerance_s: 0.1 # how early (bunched up) a frame may come and still pass
//   landmarks:                  # required: colour-code signature -> landmark id
//     "12": 1
//     "0o13": 2
//
// A landmarks key is a signature's tags as PixyMon shows them, never a decimal
// number: "12" is tags 1 then 2 = raw 012 octal = 10; "012" and "0o12" mean the
// same. One to five tags, each 1..7; a single tag maps normal (non colour-code)
// blocks. Ids are integers 0..1000000. Quoting the keys is advised but not needed.
//
// Throws config::ConfigError naming the file and key path for an unknown key, a
// wrong type, a value out of range, max_height_to_width < min_height_to_width,
// a signature given twice (e.g. as "12" and "012") or an id given twice.
// A key repeated verbatim in one mapping is not detected (yaml-cpp keeps one).
PixyOptions read_pixy_options(config::YamlReader& pixy);

}  // namespace pixyslam::pixy
