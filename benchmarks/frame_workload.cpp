// Fixed frame workload for instruction counting:
//   valgrind --tool=callgrind --toggle-collect='pixyslam::bench::FrameWorkload::step()'
//     build/benchmarks/frame_workload M K FRAMES
// Instructions per frame = Ir of the collected part / FRAMES.
#include <cstdio>
#include <string>
#include <cstdlib>

#include "frame_setup.h"

int main(int argc, char** argv) {
  if (argc == 2 && (std::string(argv[1]) == "--help" || std::string(argv[1]) == "-h")) {
    std::printf("usage: frame_workload PARTICLES LANDMARKS FRAMES\n");
    return 0;
  }
  if (argc != 4) {
    std::fprintf(stderr, "usage: frame_workload PARTICLES LANDMARKS FRAMES\n");
    return 2;
  }
  const int m = std::atoi(argv[1]);
  const int k = std::atoi(argv[2]);
  const int frames = std::atoi(argv[3]);
  if (m < 1 || k < 4 || frames < 1) {
    std::fprintf(stderr, "frame_workload: need PARTICLES >= 1, LANDMARKS >= 4, FRAMES >= 1\n");
    return 2;
  }
  pixyslam::bench::FrameWorkload w(m, k);
  for (int i = 0; i < frames; ++i) w.step();
  const auto e = w.filter().pose_estimate();
  std::printf("M=%d K=%d frames=%d pose %.4f %.4f %.4f\n", m, k, frames, e.mean.x(), e.mean.y(), e.mean.z());
  return 0;
}
