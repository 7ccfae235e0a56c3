// Fixed frame workload for instruction counting:
//   valgrind --tool=callgrind --toggle-collect='pixyslam::bench::FrameWorkload::step()'
//     build/benchmarks/frame_workload M K FRAMES
// Instructions per frame = Ir of the collected part / FRAMES.
#include <cstdio>

#include "frame_setup.h"
#include "pixyslam/app/cli.h"

int main(int argc, char** argv) {
  int m = 0, k = 0, frames = 0;
  pixyslam::app::Cli cli{"frame_workload", "A fixed filter workload for instruction counts under callgrind."};
  cli.option("particles", m, "M").required().range(1, 1000000).type("PARTICLES");
  cli.option("landmarks", k, "K (at least 4)").required().range(4, 1000000).type("LANDMARKS");
  cli.option("frames", frames, "frames to run").required().range(1, 100000000).type("FRAMES");
  if (const auto done = cli.parse(argc, argv)) return *done;
  pixyslam::bench::FrameWorkload w(m, k);
  for (int i = 0; i < frames; ++i) w.step();
  const auto e = w.filter().pose_estimate();
  std::printf("M=%d K=%d frames=%d pose %.4f %.4f %.4f\n", m, k, frames, e.mean.x(), e.mean.y(), e.mean.z());
  return 0;
}
