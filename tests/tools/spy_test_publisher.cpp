// Test publisher for tests/spy_echo_test.sh: publishes Odometry with values
// that follow from header.seq (so a reader joining at any point can check
// them) at `--rate-hz` until SIGINT/SIGTERM. Participant name "spy_test_publisher".
//   seq = n (from 1), stamp_ns = 1000000000000000000 + n, frame_id "base_link",
//   v_mps = n + 0.5, w_radps = -(n + 0.25), period_s = 0.1, distance_m = 2 n,
//   rotation_rad = 1e-9, encoder_samples = n + 3
#include <chrono>
#include <cstdio>
#include <exception>

#include "pixyslam/app/cli.h"
#include "pixyslam/app/process_main.h"
#include "pixyslam/app/stop_signal.h"
#include "pixyslam/config/yaml_reader.h"
#include "pixyslam/dds/endpoints.h"

namespace pixyslam {
namespace {

int run(int argc, char** argv) {
    std::string file;
    double rate_hz = 20.0;
    int map_states = 0;
    app::Cli cli{"spy_test_publisher", "Publishes Odometry whose values follow from header.seq (tests/spy_echo_test.sh)."};
    app::add_config(cli, file, "a YAML with a dds: mapping").required();
    cli.option("--rate-hz", rate_hz, "Odometry samples per second").positive().type("HZ");
    cli.option("--map-states", map_states, "first publish N MapStates (seq 1..N, transient local: kept for late readers)")
        .range(0, 100000)
        .type("N");
    if (const auto done = cli.parse(argc, argv)) return *done;
    config::YamlReader root = config::YamlReader::from_file(file);
    config::YamlReader dds_yaml = root.child("dds");
    dds::DdsOptions options = dds::read_dds_options(dds_yaml, config::folder_of(file));
    dds::resolve_settings(options);

    dds::Participant participant(options, "spy_test_publisher");
    dds::Writer<msg::Odometry> writer(participant);
    dds::Writer<msg::MapState> maps(participant);
    for (std::uint64_t n = 1; n <= static_cast<std::uint64_t>(map_states); ++n) {
      msg::MapState m;
      m.header().stamp_ns(1000000000000000000ull + n);
      m.header().frame_id("map");
      maps.publish(m);
    }
    std::fprintf(stderr, "spy_test_publisher: publishing on domain %d\n", options.domain_id);
    const auto period = std::chrono::milliseconds(static_cast<int>(1000.0 / rate_hz));
    while (!app::StopSignal::wait_for(period)) {
      const std::uint64_t n = writer.published() + 1;  // the seq publish() will give it
      msg::Odometry m;
      m.header().stamp_ns(1000000000000000000ull + n);
      m.header().frame_id("base_link");
      m.v_mps(static_cast<double>(n) + 0.5);
      m.w_radps(-(static_cast<double>(n) + 0.25));
      m.period_s(0.1);
      m.distance_m(2.0 * static_cast<double>(n));
      m.rotation_rad(1e-9);
      m.encoder_samples(static_cast<std::uint32_t>(n + 3));
      writer.publish(m);
    }
    std::fprintf(stderr, "spy_test_publisher: published %llu\n", static_cast<unsigned long long>(writer.published()));
    return 0;
}

}  // namespace
}  // namespace pixyslam

int main(int argc, char** argv) {
  pixyslam::app::StopSignal::install();
  return pixyslam::app::run_main("spy_test_publisher", [&] { return pixyslam::run(argc, argv); });
}
