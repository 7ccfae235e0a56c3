#include "pixyslam/pixy_node/pixy_node_options.h"

#include <sstream>
#include <stdexcept>

#include "pixyslam/config/parameters_yaml.h"
#include "pixyslam/config/yaml_reader.h"

namespace pixyslam::pixy_node {

const parameters::Table<PixyNodeOptions>& node_parameters() {
  using O = PixyNodeOptions;
  namespace P = parameters;
  static const P::Table<O> table = [] {
    const auto process = [](O& o) -> bridge::BridgeProcessOptions& { return o.process; };
    P::Table<O> t = bridge::serial_link_parameters<O>(process, "the Pixy's UART");
    for (P::Parameter<O>& p : P::Table<O>{
        P::real<O>("camera_latency_s", 0.0, 1.0, "s", "subtracted from the host time a frame was read (exposure to UART)",
                   [](O& o) -> double& { return o.camera_latency_s; }),
        P::real<O>("frame_timeout_s", 0.005, 10.0, "s", "an open frame without new data this long is complete",
                   [](O& o) -> double& { return o.frame_timeout_s; }),
         }) {
      t.push_back(std::move(p));
    }
    for (P::Parameter<O>& p : bridge::process_parameters<O>(process)) t.push_back(std::move(p));
    return t;
  }();
  return table;
}

void validate_node(const PixyNodeOptions& o) {
  parameters::check_ranges(o, node_parameters(), "node");
  bridge::validate_serial_link(o.process, "node");
}

void apply_overrides(PixyNodeOptions& o, std::vector<std::string>& assignments) {
  for (const std::string& a : parameters::take_section(assignments, "pixy")) {
    parameters::apply_override_to_either(o.pixy.rate, pixy::frame_rate_parameters(), o.pixy.camera,
                                         pixy::camera_parameters(), "pixy", a);
  }
  pixy::validate(o.pixy.camera);
  pixy::validate(o.pixy.rate);
  for (const std::string& a : parameters::take_section(assignments, "node")) {
    parameters::apply_override(o, node_parameters(), "node", a);
  }
  validate_node(o);
}

std::string help_text() {
  return "Pixy parameters (pixy:; landmarks apart):\n" + parameters::help_text(pixy::camera_parameters(), "pixy") +
         parameters::help_text(pixy::frame_rate_parameters(), "pixy") + "the link and the process (node:):\n" +
         parameters::help_text(node_parameters(), "node") +
         "DDS settings (dds:; the PIXYSLAM_DDS_* environment overrides the file, --set both):\n" +
         parameters::help_text(dds::dds_parameters(), "dds");
}

PixyNodeOptions read_pixy_node_options(config::YamlReader& root, const std::string& config_dir,
                                       const CameraSectionReader& read_camera) {
  PixyNodeOptions o;
  if (root.has("node")) {
    config::YamlReader node = root.child("node");
    config::read_parameters(node, node_parameters(), o);
    config::check_rules(node, [&] { validate_node(o); });
    node.finish();
  }
  config::YamlReader pixy = root.child("pixy");
  o.pixy = pixy::read_pixy_options(pixy);
  o.dds = dds::read_dds_section(root, config_dir);
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
  std::ostringstream os;
  os << parameters::to_yaml(o, node_parameters(), "node")
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
