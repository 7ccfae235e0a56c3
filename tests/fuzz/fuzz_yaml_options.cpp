// libFuzzer target: arbitrary text as each YAML option file the programs read
// (filter, encoder bridge, pixy bridge, simulated world, bridge process). Any
// mistake must surface as config::ConfigError naming the file; nothing else may
// escape (a yaml-cpp exception, a crash, a hang).

#include <cstddef>
#include <cstdint>
#include <string>

#include "fuzz_common.h"
#include "pixyslam/bridge/process_options.h"
#include "pixyslam/config/parameters_yaml.h"
#include "pixyslam/config/yaml_reader.h"
#include "pixyslam/encoder/encoder_options.h"
#include "pixyslam/pixy/pixy_options.h"
#include "pixyslam/sim/sim_world.h"
#include "pixyslam/slam/slam_options_yaml.h"

namespace {

constexpr const char* kOrigin = "fuzz.yaml";

// Reads the document's `key` mapping with `read`; a ConfigError is the expected
// outcome for most inputs and must name the origin.
template <class Read>
void read_section(const std::string& text, const char* key, Read read) {
  using pixyslam::config::ConfigError;
  using pixyslam::config::YamlReader;
  try {
    YamlReader root = YamlReader::from_string(text, kOrigin);
    YamlReader section = root.child(key);
    read(section);
  } catch (const ConfigError& e) {
    FUZZ_CHECK(std::string(e.what()).find(kOrigin) != std::string::npos);
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  read_section(text, "filter", [](auto& r) { pixyslam::slam::read_filter_options(r); });
  read_section(text, "encoder_bridge", [](auto& r) { pixyslam::encoder::read_encoder_options(r); });
  read_section(text, "pixy", [](auto& r) { pixyslam::pixy::read_pixy_options(r); });
  read_section(text, "world", [](auto& r) { pixyslam::sim::read_world_options(r); });
  read_section(text, "node", [](auto& r) {
    using pixyslam::bridge::BridgeProcessOptions;
    BridgeProcessOptions o;
    pixyslam::config::read_parameters(
        r, pixyslam::bridge::process_parameters<BridgeProcessOptions>([](BridgeProcessOptions& x) -> BridgeProcessOptions& { return x; }), o);
  });
  return 0;
}
