// End-to-end latency on loopback: Odometry published by this process -> the
// MapState that includes it, from a separate slam_estimator process.
//   bench_latency [--config config/slam_estimator.yaml] [--duration S] [--out FILE.csv] [--domain N]
// Streams the simulated world in real time at the paper's rates (odometry 10 Hz,
// stamped at the start of its period and sent at its end, as the encoder bridge
// does; camera frames 10 Hz) and prints p50/p90/p99/max of the latency.
// --out writes every sample's latency (one column latency_ms) for
// scripts/plot_results.py. This process joins DDS as the estimator does: the
// dds: section of --config, PIXYSLAM_DDS_*, then --domain (passed on to it).
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <mutex>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "pixyslam/sim/sim_world.h"
#include "pixyslam/app/cli.h"
#include "pixyslam/app/process_main.h"
#include "pixyslam/app/stop_signal.h"
#include "pixyslam/dds/dds_options.h"
#include "pixyslam/dds/endpoints.h"
#include "pixyslam/launcher/process_group.h"
#include "../tests/support/sim_sensor_messages.h"

namespace pixyslam::bench {
namespace {

double percentile(std::vector<double> values, double p) {
  if (values.empty()) return 0.0;
  std::sort(values.begin(), values.end());
  const std::size_t i = std::min(values.size() - 1, static_cast<std::size_t>(p * static_cast<double>(values.size())));
  return values[i];
}

std::string own_folder() {
  return std::filesystem::read_symlink("/proc/self/exe").parent_path().string();
}

}  // namespace

int run(const std::string& config, double duration_s, const std::string& out,
        const std::vector<std::string>& dds_overrides) {
  // The estimator's DDS settings, as it resolves them (a bad dds: key exits 2 here, before it starts).
  dds::DdsOptions dds_options = dds::read_dds_options_file(config, dds::default_profiles_file());
  dds::resolve_settings(dds_options, dds_overrides);

  // The estimator as its own process, its output forwarded with a prefix.
  launcher::ProcessGroup estimator(own_folder(), stdout);
  std::vector<std::string> command{"slam_estimator", "--config", config};
  command.insert(command.end(), {"--domain", std::to_string(dds_options.domain_id)});  // the domain resolved here
  estimator.start({"slam_estimator", command, 0.0, false, {}});

  dds::Participant participant(dds_options, "bench_latency");
  dds::Writer<msg::Odometry> odometry_writer(participant);
  dds::Writer<msg::LandmarkObservation> observation_writer(participant);

  std::mutex mutex;
  std::map<std::uint64_t, std::uint64_t> published_ns;  // odometry seq -> publish time
  std::vector<double> latencies_ms;
  std::vector<double> update_ms;
  std::uint64_t last_seen = 0;
  dds::Reader<msg::MapState> map_reader(participant, [&](const msg::MapState& m) {
    const std::uint64_t now = dds::now_ns();
    std::lock_guard<std::mutex> lock(mutex);
    update_ms.push_back(m.update_time_s() * 1e3);
    const std::uint64_t seq = m.odometry_sequence();
    if (seq == 0 || seq == last_seen) return;
    last_seen = seq;
    auto it = published_ns.find(seq);
    if (it != published_ns.end()) latencies_ms.push_back(static_cast<double>(now - it->second) * 1e-6);
  });
  // Its output is forwarded while waiting; one that exits (a config error) ends the wait with its status.
  const auto appear_by = std::chrono::steady_clock::now() + std::chrono::seconds(20);
  while (odometry_writer.matched_readers() < 1 || observation_writer.matched_readers() < 1) {
    estimator.poll(std::chrono::milliseconds(100));
    if (!estimator.running(0)) {
      const launcher::ExitStatus& status = estimator.status(0);
      std::fprintf(stderr, "bench_latency: slam_estimator %s before it appeared on DDS\n", status.describe().c_str());
      return status.exited && status.code == 2 ? 2 : 1;
    }
    if (app::StopSignal::requested()) return 1;
    if (std::chrono::steady_clock::now() > appear_by) {
      std::fprintf(stderr, "bench_latency: the estimator did not appear on DDS within 20 s (domain %d)\n",
                   dds_options.domain_id);
      return 1;
    }
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(500));

  sim::WorldOptions world;
  world.duration_s = duration_s;
  world.camera_rate_hz = 10.0;
  world.max_range_m = 4.0;
  const sim::WorldRun run = sim::simulate(world);
  const double period = 1.0 / world.odometry_rate_hz;

  // Events in wall-time order: a frame is sent at its stamp, odometry at its period's end.
  struct Event {
    double send_s;
    bool odometry;
    std::size_t index;
  };
  std::vector<Event> events;
  for (std::size_t i = 0; i < run.odometry.size(); ++i) events.push_back({run.odometry[i].t_s + period, true, i});
  for (std::size_t i = 0; i < run.frames.size(); ++i) events.push_back({run.frames[i].t_s, false, i});
  std::stable_sort(events.begin(), events.end(), [](const Event& a, const Event& b) { return a.send_s < b.send_s; });

  const auto start = std::chrono::steady_clock::now();
  const std::uint64_t base_ns = dds::now_ns();
  auto to_ns = [&](double t_s) { return base_ns + static_cast<std::uint64_t>(t_s * 1e9); };
  for (const Event& e : events) {
    if (app::StopSignal::requested()) break;
    std::this_thread::sleep_until(start + std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                                              std::chrono::duration<double>(e.send_s)));
    if (e.odometry) {
      const slam::OdometrySample& s = run.odometry[e.index];
      msg::Odometry m = test_support::odometry_msg(s, period, to_ns(s.t_s));
      {
        std::lock_guard<std::mutex> lock(mutex);
        published_ns[odometry_writer.published() + 1] = dds::now_ns();
      }
      odometry_writer.publish(m);
    } else {
      const slam::ObservationFrame& f = run.frames[e.index];
      msg::LandmarkObservation m = test_support::observation_msg(f, to_ns(f.t_s));
      observation_writer.publish(m);
    }
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(500));
  estimator.stop_all(std::chrono::seconds(5));

  std::lock_guard<std::mutex> lock(mutex);
  std::printf("bench_latency: %zu odometry samples, %zu with a MapState (%.1f s, 100 particles unless configured)\n",
              run.odometry.size(), latencies_ms.size(), duration_s);
  std::printf("  Odometry publish -> MapState received [ms]: p50 %.3f  p90 %.3f  p99 %.3f  max %.3f\n",
              percentile(latencies_ms, 0.5), percentile(latencies_ms, 0.9), percentile(latencies_ms, 0.99),
              percentile(latencies_ms, 1.0));
  std::printf("  filter step time in the estimator [ms]:   p50 %.3f  p99 %.3f\n", percentile(update_ms, 0.5),
              percentile(update_ms, 0.99));
  if (!out.empty()) {
    std::ofstream csv(out);
    csv << "latency_ms\n";
    for (double l : latencies_ms) csv << l << '\n';
    if (!csv) throw std::runtime_error("cannot write " + out);
  }
  return latencies_ms.size() + 5 >= run.odometry.size() ? 0 : 1;
}

}  // namespace pixyslam::bench

int main(int argc, char** argv) {
  using namespace pixyslam;
  app::StopSignal::install();
  std::string config = std::string(PIXYSLAM_CONFIG_DIR) + "/slam_estimator.yaml";
  double duration_s = 60.0;
  std::string out;
  std::vector<std::string> dds_overrides;
  app::Cli cli{"bench_latency",
               "End-to-end latency Odometry -> MapState through a separate slam_estimator on loopback."};
  cli.option("--config", config, "the estimator's YAML (default config/slam_estimator.yaml)").existing_file().type("FILE");
  cli.option("--duration", duration_s, "seconds of odometry (default 60)").positive().type("S");
  cli.option("--out", out, "every sample's latency as CSV (for scripts/plot_results.py)").type("FILE.csv");
  app::add_domain(cli, dds_overrides);
  if (const auto done = cli.parse(argc, argv)) return *done;
  // A bad config exits 2, any other error 1 (as every program here).
  return app::run_main("bench_latency", [&] { return bench::run(config, duration_s, out, dds_overrides); });
}
