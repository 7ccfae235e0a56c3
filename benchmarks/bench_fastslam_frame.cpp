#include <benchmark/benchmark.h>

#include "frame_setup.h"

namespace {

// One frame: odometry (predict), 3 observations through the FastSLAM 2.0 proposal
// and landmark EKFs, systematic resampling (every frame, so it is always paid).
void BM_Frame(benchmark::State& state) {
  pixyslam::bench::FrameWorkload w(static_cast<int>(state.range(0)), static_cast<int>(state.range(1)));
  for (int i = 0; i < 20; ++i) w.step();  // warm the node pool
  for (auto _ : state) {
    w.step();
  }
  state.counters["M"] = static_cast<double>(state.range(0));
  state.counters["K"] = static_cast<double>(state.range(1));
  state.counters["live_nodes"] = static_cast<double>(w.filter().pool().nodes_live());
}

BENCHMARK(BM_Frame)
    ->ArgsProduct({{100, 1000, 10000}, {10, 100, 1000, 10000}})
    ->Unit(benchmark::kMicrosecond);

}  // namespace

// BENCHMARK_MAIN, with an unknown flag a usage error (exit 2) as in every program here.
int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 2;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
