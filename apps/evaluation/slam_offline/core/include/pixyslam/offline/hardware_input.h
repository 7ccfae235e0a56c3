#pragma once

#include "pixyslam/offline/offline_run.h"
#include "pixyslam/robot_sim/robot_sim_config.h"

namespace pixyslam::offline {

// The emulated robot hardware (apps/simulation/robot_sim) decoded by the bridges' real
// parsers, offline and deterministic: Arduino lines -> ArduinoLineParser ->
// WheelOdometry -> OdometryAccumulator (10 Hz samples stamped at their period
// start), Pixy bytes -> PixyBlockParser -> to_detections (Eq. 5/6, sigmas of
// the camera model). Bytes are "received" at the emulator step they were
// emitted in (steps of step_s), as the live bridges stamp on arrival. Truth:
// the emulator's true poses and every pole with a colour code.
RunInput hardware_input(const robot_sim::RobotSimConfig& config, double duration_s, double step_s = 0.002);

}  // namespace pixyslam::offline
