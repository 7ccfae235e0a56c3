// Writes MCAP files like the logger's (Odometry on pixyslam/odometry, CDR,
// zstd chunks of 4 KiB, seq 1..N) and damaged copies of them, for the
// log_tool_damage_cli test (tests/log_tool_damage_cli_test.cmake) and for
// measuring recovery by hand:
//   mcap_damage_fixture DIR [MESSAGES]      (default 4436)
// DIR/closed.mcap          complete
// DIR/not_closed.mcap      cut in the middle of a chunk, as a killed writer leaves it
// DIR/damaged_length.mcap  the length field of the chunk at a tenth of the file damaged
// DIR/damaged_chunk.mcap   that chunk's length field and records damaged
// DIR/unchunked.mcap       complete, no chunks
// DIR/no_summary.mcap      complete, no chunks and no summary section (Footer summary_start 0)
// DIR/expected.cmake       the offsets and counts the test checks against
// Exit 0, or 1 with a message on stderr.
#include <cstdint>
#include <cstdio>
#include <exception>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "pixyslam/app/cli.h"
#include "pixyslam/app/process_main.h"
#include "pixyslam/dds/topics.h"
#include "pixyslam/mcap/mcap_reader.h"
#include "pixyslam/mcap/mcap_writer.h"
#include "pixyslam/dds/cdr_payload.h"

namespace pixyslam {
namespace {

using Bytes = std::vector<std::uint8_t>;

void write_log(const std::string& path, int count, std::size_t chunk_size) {
  mcap::McapWriterOptions options;
  options.chunk_size_bytes = chunk_size;
  options.compression = mcap::mcap_compression_available(mcap::McapCompression::kZstd)
                            ? mcap::McapCompression::kZstd
                            : mcap::McapCompression::kNone;
  mcap::McapWriter writer(path, options);
  const std::uint16_t schema = writer.add_schema("pixyslam::msg::Odometry", "omgidl", msg::idl_text("odometry"));
  const std::uint16_t channel = writer.add_channel(std::string(dds::kOdometryTopic), "cdr", schema);
  for (int i = 1; i <= count; ++i) {
    msg::Odometry odometry;
    const std::uint64_t stamp = 1'700'000'000'000'000'000ULL + static_cast<std::uint64_t>(i) * 10'000'000ULL;
    odometry.header().stamp_ns(stamp);
    odometry.header().seq(static_cast<std::uint64_t>(i));
    odometry.header().robot_id("robot1");
    odometry.header().frame_id("base_link");
    odometry.v_mps(0.1 + 0.001 * (i % 50));
    odometry.w_radps(0.01 * (i % 7));
    odometry.period_s(0.01);
    odometry.distance_m(odometry.v_mps() * 0.01);
    odometry.rotation_rad(odometry.w_radps() * 0.01);
    odometry.encoder_samples(2);
    writer.write_message(channel, static_cast<std::uint32_t>(i), stamp, stamp, dds::to_cdr(odometry));
  }
  writer.close();
}

Bytes read_bytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return Bytes(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

void write_bytes(const std::string& path, const Bytes& bytes) {
  std::ofstream out(path, std::ios::binary);
  out.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
  if (!out) throw std::runtime_error(path + ": cannot write");
}

int run(const std::string& dir, int count) {
  const std::string closed = dir + "/closed.mcap";
  write_log(closed, count, 4096);
  write_log(dir + "/unchunked.mcap", 50, 0);
  {
    // The unchunked file up to its Data End record, then a Footer pointing at no summary.
    const Bytes unchunked = read_bytes(dir + "/unchunked.mcap");
    const mcap::McapReader full(unchunked, "unchunked");
    Bytes bare(unchunked.begin(), unchunked.begin() + static_cast<std::ptrdiff_t>(full.recovery().valid_bytes));
    std::uint64_t pos = 8;
    while (pos < bare.size()) {
      std::uint64_t len = 0;
      for (std::uint64_t i = 0; i < 8; ++i) len |= static_cast<std::uint64_t>(bare[pos + 1 + i]) << (8 * i);
      if (bare[pos] == 0x0F) {  // Data End
        bare.resize(pos + 9 + len);
        break;
      }
      pos += 9 + len;
    }
    const Bytes footer = {0x02, 20, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0};
    const Bytes magic = {0x89, 'M', 'C', 'A', 'P', '0', '\r', '\n'};
    bare.insert(bare.end(), footer.begin(), footer.end());
    bare.insert(bare.end(), magic.begin(), magic.end());
    write_bytes(dir + "/no_summary.mcap", bare);
  }
  const Bytes file = read_bytes(closed);
  const mcap::McapReader reader(file, closed);
  if (!reader.clean() || reader.chunks().size() < 20) {
    std::fprintf(stderr, "mcap_damage_fixture: %s is not a clean file of 20+ chunks\n%s", closed.c_str(),
                 reader.diagnostics_text().c_str());
    return 1;
  }
  const std::vector<mcap::McapChunkInfo>& chunks = reader.chunks();
  const mcap::McapChunkInfo& victim = chunks[chunks.size() / 10];
  const mcap::McapChunkInfo& cut = chunks[chunks.size() - 3];
  std::uint64_t before_cut = 0;
  for (const mcap::McapChunkInfo& c : chunks) {
    if (c.offset < cut.offset) before_cut += c.message_count;
  }

  Bytes damaged = file;
  damaged[victim.offset + 8] ^= 0x40;  // top byte of the record length: far past the end of the file
  write_bytes(dir + "/damaged_length.mcap", damaged);
  damaged[victim.offset + victim.length - 5] ^= 0x21;  // and its compressed records
  write_bytes(dir + "/damaged_chunk.mcap", damaged);
  const auto cut_at = static_cast<std::ptrdiff_t>(cut.offset + cut.length / 2);
  write_bytes(dir + "/not_closed.mcap", Bytes(file.begin(), file.begin() + cut_at));

  std::ofstream expected(dir + "/expected.cmake");
  expected << "set(MESSAGES " << count << ")\n"
           << "set(CHUNKS " << chunks.size() << ")\n"
           << "set(DAMAGED_OFFSET " << victim.offset << ")\n"
           << "set(DAMAGED_CHUNK_MESSAGES " << victim.message_count << ")\n"
           << "set(CUT_CHUNK_OFFSET " << cut.offset << ")\n"
           << "set(MESSAGES_BEFORE_CUT " << before_cut << ")\n";
  std::printf("%s: %d messages in %zu chunks; damaged chunk %zu at offset %llu (%llu messages); cut in chunk at %llu\n",
              closed.c_str(), count, chunks.size(), chunks.size() / 10,
              static_cast<unsigned long long>(victim.offset), static_cast<unsigned long long>(victim.message_count),
              static_cast<unsigned long long>(cut.offset));
  return expected ? 0 : 1;
}

}  // namespace
}  // namespace pixyslam

int main(int argc, char** argv) {
  std::string dir;
  int messages = 4436;
  pixyslam::app::Cli cli{"mcap_damage_fixture", "Writes closed, not closed and damaged MCAP files of MESSAGES odometry "
                                                "samples into DIR, and DIR/expected.cmake with their offsets and counts."};
  cli.option("dir", dir, "the output folder").required().type("DIR");
  cli.option("messages", messages, "odometry samples per file (default 4436)").range(1, 10000000).type("MESSAGES");
  if (const auto done = cli.parse(argc, argv)) return *done;
  return pixyslam::app::run_main("mcap_damage_fixture", [&] { return pixyslam::run(dir, messages); });
}
