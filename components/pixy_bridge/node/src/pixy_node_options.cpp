#include "pixyslam/pixy_node/pixy_node_options.h"

#include <sstream>

#include "pixyslam/config/yaml_reader.h"
#include "pixyslam/serial/serial_port.h"

namespace pixyslam::pixy_node {
namespace {

std::string baud_list() {
  std::string s;
  for (const long b : serial::supported_bauds()) s += (s.empty() ? "" : ", ") + std::to_string(b);
  return s;
}

}  // namespace

PixyNodeOptions read_pixy_node_options(config::YamlReader& root, const std::string& config_dir,
                                       const CameraSectionReader& read_camera) {
  PixyNodeOptions o;
  if (root.has("node")) {
    config::YamlReader node = root.child("node");
    o.serial_device = node.text("serial_device", o.serial_device);
    if (o.serial_device.empty() || o.serial_device.front() != '/') {
      node.fail("serial_device",
                "value '" + o.serial_device + "' is not an absolute path (e.g. /dev/serial0)");
    }
    o.baud = static_cast<long>(node.integer("baud", 1, 4000000, o.baud));
    if (!serial::is_supported_baud(o.baud)) {
      node.fail("baud", "value " + std::to_string(o.baud) + " is not a supported serial rate (" +
                            baud_list() + ")");
    }
    o.camera_latency_s = node.number("camera_latency_s", 0.0, 1.0, o.camera_latency_s);
    o.frame_timeout_s = node.number("frame_timeout_s", 0.005, 10.0, o.frame_timeout_s);
    o.process = bridge::read_bridge_process_options(node);
    node.finish();
  }
  config::YamlReader pixy = root.child("pixy");
  o.pixy = pixy::read_pixy_options(pixy);
  if (root.has("dds")) {
    config::YamlReader dds = root.child("dds");
    o.dds = dds::read_dds_options(dds, config_dir);
  }
  if (root.has("camera")) {
    if (!read_camera) {
      root.fail("camera", "this pixy_bridge was built without the camera backend "
                          "(cmake -DPIXYSLAM_BUILD_CAMERA=ON, needs OpenCV)");
    }
    config::YamlReader camera = root.child("camera");
    read_camera(camera, o);
  }
  root.finish();
  return o;
}

PixyNodeOptions read_pixy_node_options_file(const std::string& path, const CameraSectionReader& read_camera) {
  config::YamlReader root = config::YamlReader::from_file(path);
  return read_pixy_node_options(root, config::folder_of(path), read_camera);
}

std::string to_yaml(const PixyNodeOptions& o) {
  using bridge::yaml_number;
  std::ostringstream os;
  os << "node:\n"
     << "  serial_device: " << bridge::yaml_quoted(o.serial_device) << "\n"
     << "  baud: " << o.baud << "\n"
     << "  camera_latency_s: " << yaml_number(o.camera_latency_s) << "\n"
     << "  frame_timeout_s: " << yaml_number(o.frame_timeout_s) << "\n"
     << bridge::to_yaml_lines(o.process)
     << parameters::to_yaml(o.pixy.camera, pixy::camera_parameters(), "pixy")
     << parameters::to_yaml(o.pixy.rate, pixy::frame_rate_parameters(), "pixy").substr(6)  // the same mapping
     << "  landmarks:" << (o.pixy.signatures.size() == 0 ? " {}" : "") << "\n";
  for (const auto& [signature, id] : o.pixy.signatures.entries()) {
    os << "    \"" << pixy::signature_tags(signature) << "\": " << id << "\n";
  }
  os << dds::to_yaml(o.dds);
  return os.str();
}

}  // namespace pixyslam::pixy_node
