#include "pixyslam/encoder/encoder_options.h"

#include <sstream>
#include <stdexcept>

#include "pixyslam/config/parameters_yaml.h"

namespace pixyslam::encoder {
const parameters::Table<EncoderOptions>& encoder_parameters() {
  using O = EncoderOptions;
  namespace P = parameters;
  static const P::Table<O> table = {
      P::required(P::real<O>("wheel_radius_m", 0.001, 1.0, "m", "wheel radius",
                             [](O& o) -> double& { return o.wheel_radius_m; })),
      P::required(P::integer<O, int>("ticks_per_revolution", 1, 10000000, "", "counter steps per wheel turn",
                                     [](O& o) -> int& { return o.ticks_per_revolution; })),
      P::required(P::real<O>("wheel_base_m", 0.01, 5.0, "m", "distance between the wheels' contact points",
                             [](O& o) -> double& { return o.wheel_base_m; })),
      P::required(P::integer<O, int>("left_sign", -1, 1, "", "1 or -1: the left counter's direction forward",
                                     [](O& o) -> int& { return o.left_sign; })),
      P::required(P::integer<O, int>("right_sign", -1, 1, "", "1 or -1: the right counter's direction forward",
                                     [](O& o) -> int& { return o.right_sign; })),
      P::real<O>("publish_rate_hz", 0.1, 100.0, "Hz", "(v, w) outputs per second",
                 [](O& o) -> double& { return o.publish_rate_hz; }),
      P::real<O>("max_wheel_speed_mps", 0.01, 20.0, "m/s", "faster wheel travel between two samples is rejected",
                 [](O& o) -> double& { return o.max_wheel_speed_mps; }),
      P::real<O>("max_sample_gap_s", 0.001, 60.0, "s", "longer Arduino intervals give no velocity",
                 [](O& o) -> double& { return o.max_sample_gap_s; }),
  };
  return table;
}

void validate(const EncoderOptions& o) {
  parameters::check_ranges(o, encoder_parameters(), "encoder_bridge");
  for (const auto& [name, sign] : {std::pair{"left_sign", o.left_sign}, std::pair{"right_sign", o.right_sign}}) {
    if (sign == 0) throw parameters::RuleError("encoder_bridge", name, "value 0 is not a sign (expected 1 or -1)");
  }
}

EncoderOptions read_encoder_options(config::YamlReader& r) {
  EncoderOptions o;
  config::read_parameters(r, encoder_parameters(), o);
  r.finish();
  config::check_rules(r, [&] { validate(o); });
  return o;
}

EncoderOptions read_encoder_options_file(const std::string& path) {
  config::YamlReader root = config::YamlReader::from_file(path);
  config::YamlReader bridge = root.child("encoder_bridge");
  EncoderOptions o = read_encoder_options(bridge);
  // The process's own mappings, read by the encoder node (encoder_node_options.h).
  for (const char* process_key : {"node", "dds"}) {
    if (root.has(process_key)) root.child(process_key);
  }
  root.finish();
  return o;
}

std::string to_yaml(const EncoderOptions& o) { return parameters::to_yaml(o, encoder_parameters(), "encoder_bridge"); }

}  // namespace pixyslam::encoder
