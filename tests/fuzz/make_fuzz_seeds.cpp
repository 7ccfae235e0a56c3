// Writes the seed corpora of the fuzz targets into corpus/<target>/ (run once
// by hand when a format changes; the output is committed):
//   build-fuzz/bin/make_fuzz_seeds tests/fuzz/corpus config
// Seeds are small valid inputs of each format, so the fuzzers start from the
// interesting paths instead of rediscovering the syntax.

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <string>
#include <vector>

#include "pixyslam/app/cli.h"
#include "pixyslam/encoder/arduino_line_parser.h"
#include "pixyslam/mcap/mcap_reader.h"
#include "pixyslam/mcap/mcap_writer.h"
#include "pixyslam/dds/cdr_payload.h"
#include "pixyslam/pixy/pixy_block_parser.h"

namespace fs = std::filesystem;
using Bytes = std::vector<std::uint8_t>;

namespace {

void write(const fs::path& dir, const std::string& name, const Bytes& bytes) {
  fs::create_directories(dir);
  std::ofstream out(dir / name, std::ios::binary);
  out.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
}

Bytes text(std::uint8_t first, const std::string& s) {
  Bytes b{first};
  b.insert(b.end(), s.begin(), s.end());
  return b;
}

pixyslam::msg::MessageHeader header(std::uint64_t seq, std::uint64_t period_ns, const char* frame_id) {
  pixyslam::msg::MessageHeader h;
  h.stamp_ns(1'000'000'000ull + seq * period_ns);
  h.seq(seq);
  h.robot_id("robot1");
  h.frame_id(frame_id);
  return h;
}

pixyslam::msg::Odometry odometry(std::uint64_t seq) {
  pixyslam::msg::Odometry m;
  m.header(header(seq, 100'000'000ull, "base_link"));
  m.v_mps(0.2);
  m.w_radps(0.1);
  m.period_s(0.1);
  m.distance_m(0.02);
  m.rotation_rad(0.01);
  m.encoder_samples(5);
  return m;
}

pixyslam::msg::LandmarkObservation observation(std::uint64_t seq) {
  pixyslam::msg::LandmarkObservation m;
  m.header(header(seq, 200'000'000ull, "camera"));
  m.camera_frame(static_cast<std::uint32_t>(seq));
  m.blocks_in_frame(2);
  for (int id : {3, 7}) {
    pixyslam::msg::LandmarkDetection d;
    d.landmark_id(id);
    d.range_m(1.0 + 0.5 * id);
    d.bearing_rad(0.1 * (id - 5));
    m.detections().push_back(d);
  }
  return m;
}

}  // namespace

int main(int argc, char** argv) {
  std::string corpus, configs;
  pixyslam::app::Cli cli{"make_fuzz_seeds", "Writes the fuzz targets' seed inputs (built from the project's own "
                                            "encoders and the shipped configs) into CORPUS_DIR."};
  cli.option("corpus_dir", corpus, "one folder per fuzz target is made in it").required().type("CORPUS_DIR");
  cli.option("config_dir", configs, "the shipped config/ folder").required().type("CONFIG_DIR");
  if (const auto done = cli.parse(argc, argv)) return *done;
  const fs::path root = corpus;
  const fs::path config_dir = configs;
  using namespace pixyslam;

  // Arduino lines (first byte: chunk size).
  const fs::path arduino = root / "fuzz_arduino_parser";
  write(arduino, "enc", text(7, encoder::format_line(encoder::EncoderSample{1, 20000, 12, -7})));
  write(arduino, "rst_enc", text(3, encoder::format_line(encoder::EncoderReset{"1.2.0", 1440}) +
                                        encoder::format_line(encoder::EncoderSample{2, 40000, 30, 25})));
  write(arduino, "garbage_then_line", text(1, "xx$ENC,1,2*00\n$" + encoder::format_line(encoder::EncoderSample{3, 1, 2, 3})));

  // Pixy block stream (first byte: chunk size).
  const fs::path pixy = root / "fuzz_pixy_parser";
  pixy::PixyBlock normal;
  normal.signature = 1;
  normal.x = 160;
  normal.y = 100;
  normal.width = 20;
  normal.height = 60;
  pixy::PixyBlock code = normal;
  code.signature = 012;
  code.colour_code = true;
  code.angle_deg = -3;
  Bytes frames{5};
  for (int i = 0; i < 3; ++i) {
    const Bytes f = pixy::encode_frame({normal, code});
    frames.insert(frames.end(), f.begin(), f.end());
  }
  write(pixy, "three_frames", frames);

  // YAML option files: the shipped configs.
  const fs::path yaml = root / "fuzz_yaml_options";
  fs::create_directories(yaml);
  for (const char* name : {"slam_sim.yaml", "slam_mrclam.yaml", "encoder_bridge.yaml", "pixy_bridge.yaml",
                           "robot_sim.yaml"}) {
    fs::copy_file(config_dir / name, yaml / name, fs::copy_options::overwrite_existing);
  }

  // CDR payloads (first byte & 7: topic, 0 Odometry, 1 LandmarkObservation, 2 MapState, 3 GroundTruth,
  // 4 Diagnostics, 5 OptimisedMap).
  const fs::path cdr = root / "fuzz_cdr_topics";
  const auto cdr_seed = [&](const std::string& name, std::uint8_t topic, const Bytes& payload) {
    Bytes b{topic};
    b.insert(b.end(), payload.begin(), payload.end());
    write(cdr, name, b);
  };
  cdr_seed("odometry", 0, pixyslam::dds::to_cdr(odometry(1)));
  cdr_seed("odometry_delayed", 0x10, pixyslam::dds::to_cdr(odometry(2)));
  cdr_seed("observation", 1, pixyslam::dds::to_cdr(observation(1)));
  cdr_seed("observation_delayed", 0x11, pixyslam::dds::to_cdr(observation(2)));
  msg::MapState map;
  map.header().seq(1);
  cdr_seed("map_state", 2, pixyslam::dds::to_cdr(map));
  msg::GroundTruth truth;
  truth.header().seq(1);
  cdr_seed("ground_truth", 3, pixyslam::dds::to_cdr(truth));
  msg::Diagnostics diagnostics;
  diagnostics.header().seq(1);
  diagnostics.process("encoder_bridge");
  diagnostics.counters().resize(2);
  diagnostics.counters()[0].name("lines_rejected");
  diagnostics.counters()[0].value(3);
  cdr_seed("diagnostics", 4, pixyslam::dds::to_cdr(diagnostics));
  msg::OptimisedMap optimised;
  optimised.header(header(1, 1'000'000'000ull, "map"));
  optimised.keyframe_count(2);
  optimised.keyframes().resize(2);
  optimised.keyframes()[1].stamp_ns(1'100'000'000ull);
  optimised.keyframes()[1].pose().x_m(0.02);
  optimised.landmarks().resize(1);
  optimised.landmarks()[0].landmark_id(3);
  optimised.landmarks()[0].x_m(2.0);
  optimised.landmarks()[0].cov_xx_m2(0.01);
  optimised.landmarks()[0].cov_yy_m2(0.01);
  optimised.landmarks()[0].observations(4);
  optimised.converged(true);
  cdr_seed("optimised_map", 5, pixyslam::dds::to_cdr(optimised));

  // MCAP files: chunked and unchunked, with the project's schemas.
  const fs::path mcap = root / "fuzz_mcap_reader";
  fs::create_directories(mcap);
  for (const bool chunked : {true, false}) {
    mcap::McapWriterOptions options;
    options.chunk_size_bytes = chunked ? 256 : 0;
    const fs::path path = mcap / (chunked ? "chunked.mcap" : "unchunked.mcap");
    mcap::McapWriter writer(path.string(), options);
    const std::uint16_t schema = writer.add_schema("pixyslam::msg::Odometry", "omgidl", "struct Odometry {};");
    const std::uint16_t channel = writer.add_channel("pixyslam/odometry", "cdr", schema);
    for (std::uint64_t i = 1; i <= 4; ++i) {
      writer.write_message(channel, static_cast<std::uint32_t>(i), i * 1000, i * 1000, pixyslam::dds::to_cdr(odometry(i)));
    }
    writer.close();
    (void)mcap::McapReader(path.string());  // the seed must itself be clean
  }
  std::cout << "seeds written under " << root << "\n";
  return 0;
}
