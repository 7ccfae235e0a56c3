// Logger throughput on loopback: this process publishes Odometry at a fixed
// rate to a separate `logger` process, then checks the file it wrote.
//   bench_logger_throughput [--rate-hz 10000] [--duration 10] [--compression zstd]
//                           [--out FILE.mcap] [--domain D]
// The logger runs with config/logger.yaml's settings (1 MiB chunks, flush
// every 1 s) on a domain of its own, recording Odometry only. Reports: messages
// sent, the logger's CPU use over the publishing run (utime + stime from
// /proc/<pid>/stat, % of one core), the file size, and whether McapReader finds
// seq 1..N with none missing. Exit status 0 when nothing was lost.
#include <dirent.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "pixyslam/app/cli.h"
#include "pixyslam/app/process_main.h"
#include "pixyslam/app/stop_signal.h"
#include "pixyslam/dds/endpoints.h"
#include "pixyslam/log_tool/sequence_check.h"
#include "pixyslam/mcap/mcap_reader.h"
#include "pixyslam/launcher/process_group.h"

namespace pixyslam::bench {
namespace {

std::string own_folder() {
  return std::filesystem::read_symlink("/proc/self/exe").parent_path().string();
}

// The pid of the process whose command line contains `marker` (0 if none).
int find_process(const std::string& marker) {
  DIR* proc = ::opendir("/proc");
  if (proc == nullptr) return 0;
  int found = 0;
  while (dirent* entry = ::readdir(proc)) {
    const int pid = std::atoi(entry->d_name);
    if (pid <= 0 || pid == ::getpid()) continue;
    std::ifstream in("/proc/" + std::to_string(pid) + "/cmdline", std::ios::binary);
    const std::string cmdline((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    if (cmdline.find(marker) != std::string::npos && cmdline.find("logger") != std::string::npos) {
      found = pid;
      break;
    }
  }
  ::closedir(proc);
  return found;
}

// utime + stime of `pid` (all threads), in seconds; negative if unreadable.
double cpu_seconds(int pid) {
  std::ifstream in("/proc/" + std::to_string(pid) + "/stat");
  std::string stat((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const std::size_t close = stat.rfind(')');  // comm may contain spaces
  if (close == std::string::npos) return -1.0;
  std::istringstream fields(stat.substr(close + 2));
  std::string field;
  unsigned long long utime = 0, stime = 0;
  for (int i = 3; i <= 15 && fields >> field; ++i) {  // field 3 is the state
    if (i == 14) utime = std::stoull(field);
    if (i == 15) stime = std::stoull(field);
  }
  return static_cast<double>(utime + stime) / static_cast<double>(::sysconf(_SC_CLK_TCK));
}

}  // namespace

struct Arguments {
  double rate_hz = 10000.0;
  double duration_s = 10.0;
  std::string compression = "zstd";
  std::string out;  // "": a temporary file
  int domain = 150 + static_cast<int>(::getpid() % 80);
};

int run(const Arguments& a) {
  const double rate_hz = a.rate_hz;
  const double duration_s = a.duration_s;
  const std::string& compression = a.compression;
  const int domain = a.domain;
  const std::string profiles = std::string(PIXYSLAM_CONFIG_DIR) + "/dds/profiles.xml";

  const std::filesystem::path work =
      std::filesystem::temp_directory_path() / ("pixyslam_bench_logger_" + std::to_string(::getpid()));
  std::filesystem::create_directories(work);
  const std::string out = a.out.empty() ? (work / "bench.mcap").string() : a.out;
  const std::string config = (work / "logger.yaml").string();
  {
    std::ofstream yaml(config);
    yaml << "logger:\n  output_file: " << out << "\n  topics: [pixyslam/odometry]\n  compression: " << compression
         << "\n  chunk_size_bytes: 1048576\n  flush_period_s: 1.0\n"
         << "dds:\n  domain_id: " << domain << "\n  profiles_file: " << profiles << "\n  robot_id: bench\n";
  }

  launcher::ProcessGroup logger(own_folder(), stdout);
  logger.start({"logger", {"logger", "--config", config}, 0.0, false, {}});

  dds::DdsOptions dds_options;
  dds_options.profiles_file = profiles;
  dds_options.domain_id = domain;
  dds_options.robot_id = "bench";
  dds::resolve_settings(dds_options);  // as the logger does with its file
  dds::Participant participant(dds_options, "bench_logger_throughput");
  dds::Writer<msg::Odometry> writer(participant);
  if (!writer.wait_for_readers(1, std::chrono::seconds(20))) {
    std::fprintf(stderr, "bench_logger_throughput: the logger did not appear on DDS\n");
    return 1;
  }
  logger.poll(std::chrono::milliseconds(500));
  const int pid = find_process(config);
  if (pid == 0) std::fprintf(stderr, "bench_logger_throughput: logger pid not found, no CPU figure\n");

  using Clock = std::chrono::steady_clock;
  const auto count = static_cast<std::uint64_t>(rate_hz * duration_s);
  const std::uint64_t per_ms = std::max<std::uint64_t>(1, static_cast<std::uint64_t>(rate_hz / 1000.0));
  const double cpu_start = pid ? cpu_seconds(pid) : 0.0;
  const auto start = Clock::now();
  std::uint64_t failures = 0;
  for (std::uint64_t i = 0; i < count && !app::StopSignal::requested();) {
    // In bursts of rate/1000 every millisecond.
    std::this_thread::sleep_until(start + std::chrono::microseconds(static_cast<long long>(1e6 * static_cast<double>(i) / rate_hz)));
    for (std::uint64_t k = 0; k < per_ms && i < count; ++k, ++i) {
      msg::Odometry m;
      m.header().stamp_ns(dds::now_ns());
      m.header().frame_id("base_link");
      m.v_mps(0.3);
      m.w_radps(0.01 * static_cast<double>(i % 100));
      m.period_s(1.0 / rate_hz);
      m.encoder_samples(static_cast<std::uint32_t>(i % 7));
      if (!writer.publish(m)) ++failures;
    }
    if (i % 10000 == 0) logger.poll(std::chrono::milliseconds(0));  // forward its output
  }
  const double publish_s = std::chrono::duration<double>(Clock::now() - start).count();
  const bool acked = writer.wait_for_acknowledgments(std::chrono::seconds(30));
  const double wall_s = std::chrono::duration<double>(Clock::now() - start).count();
  const double cpu_s = pid ? cpu_seconds(pid) - cpu_start : 0.0;
  logger.stop_all(std::chrono::seconds(20));
  const bool logger_ok = logger.status(0).ok();

  const mcap::McapReader reader(out);
  std::vector<std::uint64_t> seqs;
  for (const mcap::McapMessage& m : reader.messages()) seqs.push_back(m.sequence);
  const log_tool::SequenceReport seq = log_tool::analyze_sequence(seqs);
  // A failed write (DDS history full past its blocking time) still used up its
  // seq (dds::Writer::publish): such seqs were never sent, so not lost here.
  const bool complete = seq.duplicates == 0 && seq.zeros == 0 && seq.missing == failures &&
                        seqs.size() + failures == writer.published() && reader.clean();
  const auto size = std::filesystem::file_size(out);

  std::printf("bench_logger_throughput: Odometry at %.0f Hz for %.1f s (compression %s, 1 MiB chunks)\n", rate_hz,
              duration_s, compression.c_str());
  std::printf("  sent %llu (publish failures %llu) in %.2f s (%.0f msg/s), all acknowledged: %s\n",
              static_cast<unsigned long long>(writer.published()), static_cast<unsigned long long>(failures), publish_s,
              static_cast<double>(writer.published()) / publish_s, acked ? "yes" : "NO");
  std::printf("  file %s: %llu messages, %s, %s; %.2f MB (%.1f bytes/message), %zu chunks\n", out.c_str(),
              static_cast<unsigned long long>(seqs.size()), log_tool::describe(seq).c_str(),
              reader.clean() ? "clean" : "NOT clean", static_cast<double>(size) / 1e6,
              seqs.empty() ? 0.0 : static_cast<double>(size) / static_cast<double>(seqs.size()), reader.chunks().size());
  if (pid) {
    std::printf("  logger CPU (utime+stime, pid %d): %.2f s over %.2f s (publishing + acknowledgments) = %.1f %% of one core"
                " (%.1f %% per publishing second)\n",
                pid, cpu_s, wall_s, 100.0 * cpu_s / wall_s, 100.0 * cpu_s / publish_s);
  }
  std::printf("  result: %s\n", complete && logger_ok ? "no message lost" : "MESSAGES LOST or logger failed");
  if (failures > 0) std::printf("  (%llu seq numbers missing = publish failures: never sent)\n", static_cast<unsigned long long>(failures));
  if (a.out.empty()) std::filesystem::remove_all(work);
  return complete && logger_ok ? 0 : 1;
}

}  // namespace pixyslam::bench

int main(int argc, char** argv) {
  using namespace pixyslam;
  app::StopSignal::install();
  bench::Arguments a;
  app::Cli cli{"bench_logger_throughput",
               "Odometry at RATE per second to a separate logger on loopback: its CPU use and what it lost."};
  cli.option("--rate-hz", a.rate_hz, "messages per second (default 10000)").positive().type("HZ");
  cli.option("--duration", a.duration_s, "seconds (default 10)").positive().type("S");
  cli.option("--compression", a.compression, "chunk compression (default zstd)").choices({"none", "zstd", "lz4"}).type("C");
  cli.option("--out", a.out, "the MCAP file to write (default: a temporary file)").type("FILE.mcap");
  cli.option("--domain", a.domain, "DDS domain (default 150 + pid % 80; the logger checks it)").type("N");
  if (const auto done = cli.parse(argc, argv)) return *done;
  // A bad config exits 2, any other error 1 (as every program here).
  return app::run_main("bench_logger_throughput", [&] { return bench::run(a); });
}
