// robot_sim: the simulated robot's hardware. Writes Arduino encoder lines and
// Pixy UART bytes into two pseudo-terminals and publishes GroundTruth.
//   robot_sim --config config/robot_sim.yaml [--pixy-config config/pixy_bridge.yaml]
//             [--encoder-config config/encoder_bridge.yaml] [--duration S] [--rate R]
//             [--arduino-link PATH] [--pixy-link PATH] [--camera-video FIFO] [--domain N]
//             [--set world.KEY=V,hardware.KEY=V,run.KEY=V,dds.KEY=V ...]
// The bridge configs default to the files beside --config. Exits 0 when the
// run's duration is over (or on SIGINT/SIGTERM).
#include <string>
#include <vector>

#include "pixyslam/app/cli.h"
#include "pixyslam/config/yaml_reader.h"
#include "pixyslam/app/process_main.h"
#include "pixyslam/app/stop_signal.h"
#include "pixyslam/robot_sim/robot_sim_node.h"

int main(int argc, char** argv) {
  using namespace pixyslam;
  app::StopSignal::install();
  std::string config, pixy_config, encoder_config, arduino_link, pixy_link, camera_video;
  double duration_s = 0.0, rate = 1.0;
  bool verbose = false;
  std::vector<std::string> dds_overrides, overrides;
  app::Cli cli{"robot_sim",
               "The simulated robot's hardware: Arduino encoder lines and Pixy UART bytes into two pseudo-terminals "
               "(the bridges read them as the real devices), GroundTruth on DDS."};
  app::add_config(cli, config, "the simulator's YAML (world, hardware, run)").required();
  cli.option("--pixy-config", pixy_config, "the pixy bridge's YAML (camera, signatures; default: beside --config)")
      .existing_file()
      .type("FILE");
  cli.option("--encoder-config", encoder_config, "the encoder bridge's YAML (wheels; default: beside --config)")
      .existing_file()
      .type("FILE");
  cli.option("--duration", duration_s, "simulated seconds (default: run.duration_s)").non_negative().type("S");
  cli.option("--rate", rate, "hardware seconds per wall second (overrides run.rate)")
      .range(0.1, 10.0)
      .type("R");
  cli.option("--arduino-link", arduino_link, "a symlink to the Arduino's pseudo-terminal at PATH").type("PATH");
  cli.option("--pixy-link", pixy_link, "a symlink to the Pixy's pseudo-terminal at PATH").type("PATH");
  cli.option("--camera-video", camera_video, "also write the synthetic camera's frames to FIFO").type("FIFO");
  app::add_domain(cli, dds_overrides);
  app::add_set(cli, overrides, "world.speed_mps=0.3");
  app::add_verbose(cli, verbose);
  cli.footer(robot_sim::help_text());
  if (const auto done = cli.parse(argc, argv)) return *done;
  robot_sim::RobotSimProcessConfig c;
  if (const auto failed = app::configure("robot_sim", [&] {
        const std::string folder = config::folder_of(config);
        c = robot_sim::read_robot_sim_process_config(
            config, cli.given("--pixy-config") ? pixy_config : folder + "/pixy_bridge.yaml",
            cli.given("--encoder-config") ? encoder_config : folder + "/encoder_bridge.yaml");
        overrides.insert(overrides.end(), dds_overrides.begin(), dds_overrides.end());  // --domain last: it wins
        robot_sim::apply_overrides(c, overrides);
        // The dedicated flags after --set, as everywhere: the narrower statement wins.
        if (cli.given("--duration")) c.run.duration_s = duration_s;
        if (cli.given("--rate")) c.run.rate = rate;
        if (cli.given("--arduino-link")) c.run.arduino_link = arduino_link;
        if (cli.given("--pixy-link")) c.run.pixy_link = pixy_link;
        if (cli.given("--camera-video")) c.run.camera_video = camera_video;
        robot_sim::validate(c.run);
      })) {
    return *failed;
  }
  if (verbose) app::print_effective_configuration("robot_sim", robot_sim::to_yaml(c));
  return app::run_main("robot_sim", [&] {
    robot_sim::RobotSimNode node(c);
    node.run();
    return 0;
  });
}
