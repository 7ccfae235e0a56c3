#include "pixyslam/calibration/pole_images.h"

#include <filesystem>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "pixyslam/config/yaml_reader.h"

namespace pixyslam::calibration {

std::vector<PoleImage> parse_pole_images(std::string_view text, const std::string& origin, const std::string& folder) {
  const CsvTable table = read_csv(text, origin);
  const bool two = table.header == std::vector<std::string>{"image", "distance_m"};
  const bool three = table.header == std::vector<std::string>{"image", "distance_m", "bearing_rad"};
  if (!two && !three) {
    throw config::ConfigError(origin + ":" + std::to_string(table.header_line) +
                              ": the header must be 'image,distance_m' or 'image,distance_m,bearing_rad'");
  }
  std::vector<PoleImage> out;
  for (const CsvRow& row : table.rows) {
    PoleImage p;
    const std::filesystem::path image(row.fields[0]);
    p.path = image.is_absolute() || folder.empty() ? image.string() : (std::filesystem::path(folder) / image).string();
    p.distance_m = csv_number(table, row, 1, origin);
    p.line = row.line;
    if (three) {
      p.has_bearing = true;
      p.bearing_rad = csv_number(table, row, 2, origin);
    }
    out.push_back(p);
  }
  return out;
}

std::vector<PoleSample> pole_samples_from_images(const std::vector<PoleImage>& images,
                                                 const camera::DetectorOptions& detector,
                                                 const pixy::CameraModel& camera, const std::string& origin) {
  std::vector<PoleSample> out;
  for (const PoleImage& p : images) {
    const std::string where = origin + ":" + std::to_string(p.line) + ": " + p.path + ": ";
    cv::Mat image = cv::imread(p.path, cv::IMREAD_COLOR);
    if (image.empty()) throw config::ConfigError(where + "cannot read the image");
    if (image.cols != camera.image_width_px || image.rows != camera.image_height_px) {
      cv::resize(cv::Mat(image), image, cv::Size(camera.image_width_px, camera.image_height_px), 0, 0, cv::INTER_AREA);
    }
    const std::vector<pixy::PixyBlock> blocks = camera::detect_colour_codes(image, detector);
    const pixy::PixyBlock* best = nullptr;
    for (const pixy::PixyBlock& b : blocks) {
      if (!best || b.width * b.height > best->width * best->height) best = &b;
    }
    if (!best) throw config::ConfigError(where + "no colour code found (check the signatures' HSV ranges)");
    PoleSample s;
    s.distance_m = p.distance_m;
    s.height_px = best->height;
    s.has_bearing = p.has_bearing;
    s.x_px = best->x;
    s.bearing_rad = p.bearing_rad;
    s.line = p.line;
    check_pole_sample(s, where);
    out.push_back(s);
  }
  return out;
}

}  // namespace pixyslam::calibration
