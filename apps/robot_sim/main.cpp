// robot_sim: the simulated robot's hardware. Writes Arduino encoder lines and
// Pixy UART bytes into two pseudo-terminals and publishes GroundTruth.
//   robot_sim --config config/robot_sim.yaml [--pixy-config config/pixy_bridge.yaml]
//             [--encoder-config config/encoder_bridge.yaml] [--duration S]
//             [--arduino-link PATH] [--pixy-link PATH] [--camera-video FIFO]
// The bridge configs default to the files beside --config. Exits 0 when the
// run's duration is over (or on SIGINT/SIGTERM).
#include <cstdio>
#include <string>

#include "pixyslam/app/command_line.h"
#include "pixyslam/app/process_main.h"
#include "pixyslam/app/stop_signal.h"
#include "robot_sim_node.h"

int main(int argc, char** argv) {
  using namespace pixyslam;
  app::StopSignal::install();
  return app::run_main("robot_sim", [&] {
    const app::CommandLine args(argc, argv, {"config", "pixy-config", "encoder-config", "duration", "arduino-link", "pixy-link",
                                                    "camera-video"});
    if (args.help()) {
      std::puts("usage: robot_sim --config FILE [--pixy-config FILE] [--encoder-config FILE] [--duration S]\n"
                "                 [--arduino-link PATH] [--pixy-link PATH] [--camera-video FIFO]");
      return 0;
    }
    const std::string config = args.get("config");
    const std::string folder = app::folder_of(config);
    robot_sim::RobotSimProcessConfig c = robot_sim::read_robot_sim_process_config(
        config, args.get("pixy-config", folder + "/pixy_bridge.yaml"),
        args.get("encoder-config", folder + "/encoder_bridge.yaml"));
    c.run.duration_s = args.number("duration", c.run.duration_s);
    c.run.arduino_link = args.get("arduino-link", c.run.arduino_link);
    c.run.pixy_link = args.get("pixy-link", c.run.pixy_link);
    c.run.camera_video = args.get("camera-video", c.run.camera_video);
    dds::resolve_settings(c.dds);
    robot_sim::RobotSimNode node(c);
    node.run();
    return 0;
  });
}
