#pragma once

#include <optional>

#include <opencv2/core/mat.hpp>

#include "pixyslam/parameters/parameters.h"
#include "pixyslam/map_view/map_view_state.h"
#include "pixyslam/map_view/view_transform.h"

namespace pixyslam::map_view {

// Colours (BGR). The defaults follow Fig. 6b of the seed paper: mean trajectory
// blue, landmark covariance red; ground truth green; the map optimiser's
// solution orange.
struct MapColours {
  cv::Scalar background{255, 255, 255};
  cv::Scalar grid{228, 228, 228};
  cv::Scalar grid_text{150, 150, 150};
  cv::Scalar text{40, 40, 40};
  cv::Scalar particle{200, 120, 230};
  cv::Scalar trajectory{200, 90, 20};
  cv::Scalar pose{120, 30, 0};
  cv::Scalar landmark{20, 20, 210};
  cv::Scalar truth{40, 150, 40};
  cv::Scalar optimised{0, 140, 240};
  cv::Scalar fleet{30, 30, 30};  // the fleet map
};

// How render_map draws. Sizes are pixels of the whole image; the map area is
// the image minus a footer strip (legend, scale bar, caption) at the bottom.
struct RenderOptions {
  int width_px = 800;
  int height_px = 800;
  int footer_px = 56;          // 0: no footer (legend, scale bar and caption then not drawn)
  double margin_px = 30.0;     // free space around the content inside the map area
  double min_span_m = 1.0;     // the view never shows less than this
  double sigma_scale = 2.0;    // landmark ellipses: n-sigma
  std::optional<WorldBox> view;  // fixed view (e.g. for a video); unset: fit the content
  bool grid = true;
  bool legend = true;
  bool scale_bar = true;
  bool landmark_ids = true;
  bool ground_truth = true;
  MapColours colours;
};

// Smallest image render_map accepts (the map area, footer not counted).
inline constexpr int kMinMapSidePx = 64;

// The `map_view:` keys of the drawing: range, unit, default, help.
const parameters::Table<RenderOptions>& render_parameters();

// Throws std::invalid_argument naming the bad field (a range of
// render_parameters(), a footer leaving too little map, the margin).
void validate(const RenderOptions& options);

// The rectangle of the image that shows the map (the image minus the footer).
cv::Rect2d map_area(const RenderOptions& options);
// The world -> pixel transform render_map uses for `state`: the fixed view if
// set, else the content bounds (ground truth only when drawn), with the margin.
ViewTransform view_for(const MapViewState& state, const RenderOptions& options);

// Grid spacing: the smallest of 1, 2, 5 x 10^k metres at least `min_px` apart
// (1 m for a non-positive or non-finite scale).
double nice_grid_step_m(double pixels_per_metre, double min_px);

// Draws the map (CV_8UC3, options.width_px x options.height_px): metric grid
// with labels, ground truth (path, true landmarks as crosses, true pose as an
// outlined arrow), particles as dots, the mean trajectory as a line, landmarks
// as filled dots with their n-sigma ellipses and ids, the optimised trajectory
// as a line and its landmarks as outlined diamonds with n-sigma ellipses (only
// finite covariances), the current pose as a filled arrow, then the footer: a
// legend row (items present only, those that fit), then the caption with the
// scale bar on its right (a footer under 40 px has no legend row). The
// state's other_robots are drawn first, each in one colour of robot_colour()
// (its estimate, landmarks and optimised map; ground truth stays green), and
// the legend names them. The fleet map's landmarks (fleet_landmarks) go on
// top as dark squares with their n-sigma ellipses. Pure and single-threaded: same input, same pixels.
// Throws std::invalid_argument for options that fail validate().
cv::Mat render_map(const MapViewState& state, const RenderOptions& options);

// The colour of other_robots[index] (BGR), from a palette unlike the main
// robot's blue and red; it repeats after a dozen robots.
cv::Scalar robot_colour(std::size_t index);

}  // namespace pixyslam::map_view
