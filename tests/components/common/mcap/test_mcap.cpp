// Tests of the MCAP writer and reader (components/logger/core, docs/mcap.md):
// CRC-32, exact bytes of small files against hand-computed records, round
// trips in every mode, truncation at every byte, corruption, statistics,
// error messages, and damage: resynchronising past bad records, "not closed"
// against "damaged".

#include <algorithm>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <ostream>
#include <random>
#include <stdexcept>
#include <utility>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <sys/stat.h>

#include "pixyslam/mcap/crc32.h"
#include "pixyslam/mcap/mcap_reader.h"
#include "pixyslam/mcap/mcap_writer.h"
#include "temp_dir.h"

namespace pixyslam::mcap {
namespace {

using Bytes = std::vector<std::uint8_t>;

Bytes read_bytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return Bytes(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

void write_bytes(const std::string& path, const Bytes& bytes) {
  std::ofstream out(path, std::ios::binary);
  out.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
}

void append_u64(Bytes& b, std::uint64_t v) {
  for (int i = 0; i < 8; ++i) b.push_back(static_cast<std::uint8_t>(v >> (8 * i)));
}

// Bitwise CRC-32 straight from the definition, to check the table-driven one.
std::uint32_t reference_crc32(const Bytes& data) {
  std::uint32_t c = 0xFFFFFFFFu;
  for (const std::uint8_t byte : data) {
    c ^= byte;
    for (int bit = 0; bit < 8; ++bit) c = (c & 1u) ? (c >> 1) ^ 0xEDB88320u : c >> 1;
  }
  return ~c;
}

// The top-level records of a file, found by walking opcode + length from
// offset 8 (independent of McapReader): (opcode, offset, end).
struct RecordSpan {
  std::uint8_t op;
  std::uint64_t offset;
  std::uint64_t end;
};

std::vector<RecordSpan> top_level_records(const Bytes& file) {
  std::vector<RecordSpan> out;
  std::uint64_t pos = 8;
  while (pos + 9 <= file.size()) {
    std::uint64_t len = 0;
    for (int i = 0; i < 8; ++i)
      len |= static_cast<std::uint64_t>(file[pos + 1 + static_cast<std::uint64_t>(i)]) << (8 * i);
    out.push_back({file[pos], pos, pos + 9 + len});
    pos += 9 + len;
    if (out.back().op == 0x02) break;  // Footer; the closing magic follows
  }
  return out;
}

const char* kIdl =
    "module pixyslam { module msgs { struct Odometry { unsigned long long stamp_ns; double v_m_s; }; }; };";

// A small recording: two schemas, three channels (one without schema), `count`
// messages of varied sizes (empty ones included) with log times not quite in
// order. Returns the messages as written.
std::vector<McapMessage> write_sample(const std::string& path, const McapWriterOptions& options, int count,
                                      McapWriterCounters* counters = nullptr) {
  McapWriter writer(path, options);
  const std::uint16_t odom_schema = writer.add_schema("pixyslam::msgs::Odometry", "omgidl", kIdl);
  const std::uint16_t blocks_schema =
      writer.add_schema("pixyslam::msgs::Blocks", "omgidl", "struct Blocks {};");
  const std::uint16_t odom =
      writer.add_channel("/odometry", "cdr", odom_schema, {{"qos", "reliable"}, {"a", ""}});
  const std::uint16_t blocks = writer.add_channel("/pixy/blocks", "cdr", blocks_schema);
  const std::uint16_t raw = writer.add_channel("/raw", "cdr", 0);
  std::vector<McapMessage> written;
  std::mt19937 prng(42);
  for (int i = 0; i < count; ++i) {
    McapMessage m;
    m.channel_id = i % 3 == 0 ? odom : (i % 3 == 1 ? blocks : raw);
    m.sequence = static_cast<std::uint32_t>(100 + i);
    m.log_time_ns =
        1'000'000'000ull + static_cast<std::uint64_t>(i) * 10'000'000ull - (i % 4 == 3 ? 15'000'000ull : 0);
    m.publish_time_ns = m.log_time_ns - 1234;
    m.data.resize(i % 5 == 4 ? 0 : static_cast<std::size_t>(prng() % 40));
    for (std::uint8_t& b : m.data) b = static_cast<std::uint8_t>(prng());
    writer.write_message(m.channel_id, m.sequence, m.log_time_ns, m.publish_time_ns, m.data);
    written.push_back(m);
  }
  writer.close();
  if (counters != nullptr) *counters = writer.counters();
  return written;
}

void expect_same_messages(const std::vector<McapMessage>& expected, const std::vector<McapMessage>& actual,
                          std::size_t count) {
  ASSERT_GE(expected.size(), count);
  ASSERT_EQ(actual.size(), count);
  for (std::size_t i = 0; i < count; ++i) {
    EXPECT_EQ(actual[i].channel_id, expected[i].channel_id) << i;
    EXPECT_EQ(actual[i].sequence, expected[i].sequence) << i;
    EXPECT_EQ(actual[i].log_time_ns, expected[i].log_time_ns) << i;
    EXPECT_EQ(actual[i].publish_time_ns, expected[i].publish_time_ns) << i;
    EXPECT_EQ(actual[i].data, expected[i].data) << i;
  }
}

TEST(Crc32, CheckValues) {
  EXPECT_EQ(crc32("123456789"), 0xCBF43926u);
  EXPECT_EQ(crc32("The quick brown fox jumps over the lazy dog"), 0x414FA339u);
  EXPECT_EQ(crc32(""), 0u);
}

TEST(Crc32, MatchesBitwiseDefinitionAndIsIncremental) {
  std::mt19937 prng(7);
  Bytes data(1031);
  for (std::uint8_t& b : data) b = static_cast<std::uint8_t>(prng());
  for (const std::size_t n : {std::size_t{0}, std::size_t{1}, std::size_t{3}, std::size_t{4}, std::size_t{5},
                              std::size_t{64}, std::size_t{1031}}) {
    const Bytes part(data.begin(), data.begin() + static_cast<std::ptrdiff_t>(n));
    EXPECT_EQ(crc32(part.data(), part.size()), reference_crc32(part)) << n;
  }
  for (std::size_t split = 0; split <= data.size(); split += 97) {
    const std::uint32_t first = crc32(data.data(), split);
    EXPECT_EQ(crc32(data.data() + split, data.size() - split, first), reference_crc32(data)) << split;
  }
}

// The smallest file: every byte hand-computed from the spec. CRCs were computed
// independently (zlib.crc32) over the byte ranges the spec names.
TEST(McapExactBytes, EmptyFile) {
  test::TempDir dir;
  const std::string path = dir.file("empty.mcap");
  McapWriterOptions options;
  options.library = "t";
  {
    McapWriter writer(path, options);
    writer.close();
    EXPECT_EQ(writer.counters().bytes_written, 157u);
  }
  // clang-format off
  const Bytes expected = {
      0x89, 'M', 'C', 'A', 'P', '0', '\r', '\n',                    // magic
      0x01, 9, 0, 0, 0, 0, 0, 0, 0,                                 // Header, 9 content bytes
      0, 0, 0, 0,                                                   //   profile ""
      1, 0, 0, 0, 't',                                              //   library "t"
      0x0F, 4, 0, 0, 0, 0, 0, 0, 0,                                 // Data End (offset 26)
      0x1E, 0x62, 0x4B, 0xF6,                                       //   CRC of bytes [0, 26) = 0xf64b621e
      0x0B, 46, 0, 0, 0, 0, 0, 0, 0,                                // Statistics (offset 39)
      0, 0, 0, 0, 0, 0, 0, 0,                                       //   message_count
      0, 0,                                                         //   schema_count
      0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0,               //   channel, attachment, metadata, chunk counts
      0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0,               //   message start, end time
      0, 0, 0, 0,                                                   //   channel_message_counts: empty map
      0x0E, 17, 0, 0, 0, 0, 0, 0, 0,                                // Summary Offset (offset 94)
      0x0B,                                                         //   group opcode: Statistics
      39, 0, 0, 0, 0, 0, 0, 0,                                      //   group_start
      55, 0, 0, 0, 0, 0, 0, 0,                                      //   group_length
      0x02, 20, 0, 0, 0, 0, 0, 0, 0,                                // Footer (offset 120)
      39, 0, 0, 0, 0, 0, 0, 0,                                      //   summary_start
      94, 0, 0, 0, 0, 0, 0, 0,                                      //   summary_offset_start
      0xEA, 0x8F, 0x56, 0xD1,                                       //   CRC of [39, 145) = 0xd1568fea
      0x89, 'M', 'C', 'A', 'P', '0', '\r', '\n',                    // magic
  };
  // clang-format on
  EXPECT_EQ(read_bytes(path), expected);

  const McapReader reader(path);
  EXPECT_TRUE(reader.clean()) << reader.diagnostics_text();
  EXPECT_EQ(reader.library(), "t");
  EXPECT_EQ(reader.profile(), "");
  EXPECT_TRUE(reader.messages().empty());
}

// Unchunked: Schema, Channel and Message records go straight to the file.
TEST(McapExactBytes, OneMessageUnchunked) {
  test::TempDir dir;
  const std::string path = dir.file("one.mcap");
  McapWriterOptions options;
  options.library = "t";
  options.chunk_size_bytes = 0;
  {
    McapWriter writer(path, options);
    EXPECT_EQ(writer.add_schema("S", "omgidl", "x"), 1);
    EXPECT_EQ(writer.add_channel("/a", "cdr", 1, {{"k", "v"}}), 1);
    writer.write_message(1, 7, 0x0102030405060708ull, 9, Bytes{0xAA, 0xBB});
  }
  // clang-format off
  const Bytes data_section = {
      0x89, 'M', 'C', 'A', 'P', '0', '\r', '\n',                    // magic
      0x01, 9, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 1, 0, 0, 0, 't',    // Header
      0x03, 22, 0, 0, 0, 0, 0, 0, 0,                                // Schema
      1, 0,                                                         //   id
      1, 0, 0, 0, 'S',                                              //   name
      6, 0, 0, 0, 'o', 'm', 'g', 'i', 'd', 'l',                     //   encoding
      1, 0, 0, 0, 'x',                                              //   data (uint32 length-prefixed)
      0x04, 31, 0, 0, 0, 0, 0, 0, 0,                                // Channel
      1, 0, 1, 0,                                                   //   id, schema_id
      2, 0, 0, 0, '/', 'a',                                         //   topic
      3, 0, 0, 0, 'c', 'd', 'r',                                    //   message_encoding
      10, 0, 0, 0, 1, 0, 0, 0, 'k', 1, 0, 0, 0, 'v',                //   metadata {k: v}
      0x05, 24, 0, 0, 0, 0, 0, 0, 0,                                // Message
      1, 0,                                                         //   channel_id
      7, 0, 0, 0,                                                   //   sequence
      8, 7, 6, 5, 4, 3, 2, 1,                                       //   log_time
      9, 0, 0, 0, 0, 0, 0, 0,                                       //   publish_time
      0xAA, 0xBB,                                                   //   data
      0x0F, 4, 0, 0, 0, 0, 0, 0, 0, 0x85, 0xBD, 0x61, 0xAF,         // Data End, CRC 0xaf61bd85
  };
  // clang-format on
  const Bytes file = read_bytes(path);
  ASSERT_GT(file.size(), data_section.size());
  EXPECT_EQ(Bytes(file.begin(), file.begin() + static_cast<std::ptrdiff_t>(data_section.size())),
            data_section);

  const McapReader reader(path);
  EXPECT_TRUE(reader.clean()) << reader.diagnostics_text();
  ASSERT_EQ(reader.messages().size(), 1u);
  EXPECT_EQ(reader.messages()[0].log_time_ns, 0x0102030405060708ull);
  EXPECT_TRUE(reader.chunks().empty());
  EXPECT_TRUE(reader.recovery().summary_present);
}

struct Mode {
  const char* name;
  std::size_t chunk_size_bytes;
  McapCompression compression;
};

void PrintTo(const Mode& mode, std::ostream* os) { *os << mode.name; }

std::string mode_name(const ::testing::TestParamInfo<Mode>& param_info) { return param_info.param.name; }

class McapRoundTrip : public ::testing::TestWithParam<Mode> {};

TEST_P(McapRoundTrip, SchemasChannelsMessagesAndStatistics) {
  const Mode mode = GetParam();
  if (!mcap_compression_available(mode.compression)) GTEST_SKIP() << "compression not built in";
  test::TempDir dir;
  const std::string path = dir.file("round_trip.mcap");
  McapWriterOptions options;
  options.chunk_size_bytes = mode.chunk_size_bytes;
  options.compression = mode.compression;
  options.profile = "pixyslam";
  McapWriterCounters counters;
  const std::vector<McapMessage> written = write_sample(path, options, 60, &counters);

  const McapReader reader(path);
  EXPECT_TRUE(reader.clean()) << reader.diagnostics_text();
  EXPECT_EQ(reader.profile(), "pixyslam");
  EXPECT_EQ(reader.library(), mcap_default_library());
  EXPECT_EQ(reader.library().rfind("pixyslam ", 0), 0u);

  ASSERT_EQ(reader.schemas().size(), 2u);
  EXPECT_EQ(reader.schemas()[0].id, 1);
  EXPECT_EQ(reader.schemas()[0].name, "pixyslam::msgs::Odometry");
  EXPECT_EQ(reader.schemas()[0].encoding, "omgidl");
  EXPECT_EQ(reader.schemas()[0].data, kIdl);
  EXPECT_EQ(reader.schemas()[1].data, "struct Blocks {};");

  ASSERT_EQ(reader.channels().size(), 3u);
  const McapChannel* odom = reader.find_channel("/odometry");
  ASSERT_NE(odom, nullptr);
  EXPECT_EQ(odom->schema_id, 1);
  EXPECT_EQ(odom->message_encoding, "cdr");
  EXPECT_EQ(odom->metadata, (std::map<std::string, std::string>{{"qos", "reliable"}, {"a", ""}}));
  ASSERT_NE(reader.find_channel("/raw"), nullptr);
  EXPECT_EQ(reader.find_channel("/raw")->schema_id, 0);
  EXPECT_EQ(reader.find_channel(std::uint16_t{2})->topic, "/pixy/blocks");

  expect_same_messages(written, reader.messages(), written.size());

  const std::size_t expected_chunks = mode.chunk_size_bytes == 0 ? 0 : reader.chunks().size();
  if (mode.chunk_size_bytes == 0) {
    EXPECT_TRUE(reader.chunks().empty());
  } else if (mode.chunk_size_bytes < 1000) {
    EXPECT_GT(reader.chunks().size(), 5u);
  } else {
    EXPECT_EQ(reader.chunks().size(), 1u);
  }
  for (const McapChunkInfo& c : reader.chunks()) {
    EXPECT_TRUE(c.valid);
    EXPECT_EQ(c.compression, mcap_compression_name(mode.compression));
  }
  EXPECT_EQ(counters.chunks, expected_chunks);
  EXPECT_EQ(counters.messages, 60u);
  EXPECT_EQ(counters.schemas, 2u);
  EXPECT_EQ(counters.channels, 3u);
  EXPECT_EQ(counters.bytes_written, read_bytes(path).size());

  ASSERT_TRUE(reader.statistics().has_value());
  const McapStatistics& st = *reader.statistics();
  EXPECT_EQ(st.message_count, 60u);
  EXPECT_EQ(st.schema_count, 2);
  EXPECT_EQ(st.channel_count, 3u);
  EXPECT_EQ(st.attachment_count, 0u);
  EXPECT_EQ(st.metadata_count, 0u);
  EXPECT_EQ(st.chunk_count, expected_chunks);
  std::uint64_t first = written[0].log_time_ns;
  std::uint64_t last = first;
  std::map<std::uint16_t, std::uint64_t> per_channel;
  for (const McapMessage& m : written) {
    first = std::min(first, m.log_time_ns);
    last = std::max(last, m.log_time_ns);
    ++per_channel[m.channel_id];
  }
  EXPECT_EQ(st.message_start_time_ns, first);
  EXPECT_EQ(st.message_end_time_ns, last);
  EXPECT_EQ(st.channel_message_counts, per_channel);
  EXPECT_EQ(per_channel, (std::map<std::uint16_t, std::uint64_t>{{1, 20}, {2, 20}, {3, 20}}));

  const McapRecovery& rec = reader.recovery();
  EXPECT_TRUE(rec.header_present && rec.data_end_present && rec.summary_present && rec.footer_present);
  EXPECT_EQ(rec.complete_chunks, expected_chunks);
  EXPECT_EQ(rec.rejected_chunks, 0u);
  EXPECT_EQ(rec.messages_recovered, 60u);
  EXPECT_EQ(rec.bytes_ignored_at_end, 0u);
  EXPECT_EQ(rec.valid_bytes, rec.file_size);
}

INSTANTIATE_TEST_SUITE_P(Modes, McapRoundTrip,
                         ::testing::Values(Mode{"unchunked", 0, McapCompression::kNone},
                                           Mode{"small_chunks", 300, McapCompression::kNone},
                                           Mode{"one_chunk", std::size_t{1} << 20, McapCompression::kNone},
                                           Mode{"zstd", 300, McapCompression::kZstd},
                                           Mode{"zstd_one_chunk", std::size_t{1} << 20,
                                                McapCompression::kZstd},
                                           Mode{"lz4", 300, McapCompression::kLz4}),
                         mode_name);

TEST(McapCompressionBuild, ZstdIsBuiltIn) {
  // libzstd-dev is a project dependency; without it the logger cannot compress.
  EXPECT_TRUE(mcap_compression_available(McapCompression::kZstd));
}

// Cuts a valid file at every byte: never throws past the magic, and recovers
// exactly the messages of the records (chunks, or messages when unchunked)
// that end before the cut.
class McapTruncation : public ::testing::TestWithParam<Mode> {};

TEST_P(McapTruncation, EveryByteOffset) {
  const Mode mode = GetParam();
  if (!mcap_compression_available(mode.compression)) GTEST_SKIP() << "compression not built in";
  test::TempDir dir;
  const std::string path = dir.file("full.mcap");
  McapWriterOptions options;
  options.chunk_size_bytes = mode.chunk_size_bytes;
  options.compression = mode.compression;
  const std::vector<McapMessage> written = write_sample(path, options, 14);
  const Bytes file = read_bytes(path);
  const McapReader full(path);
  ASSERT_TRUE(full.clean()) << full.diagnostics_text();
  const std::vector<RecordSpan> records = top_level_records(file);
  std::map<std::uint64_t, std::uint64_t> messages_in_chunk_at;
  for (const McapChunkInfo& c : full.chunks()) messages_in_chunk_at[c.offset] = c.message_count;
  if (mode.chunk_size_bytes > 0) {
    ASSERT_GE(full.chunks().size(), 3u);
  }

  for (std::size_t cut = 0; cut < file.size(); ++cut) {
    SCOPED_TRACE("cut at " + std::to_string(cut) + " of " + std::to_string(file.size()));
    Bytes prefix(file.begin(), file.begin() + static_cast<std::ptrdiff_t>(cut));
    if (cut < 8) {
      EXPECT_THROW(McapReader(prefix, "cut.mcap"), std::runtime_error);
      continue;
    }
    std::size_t expected_messages = 0;
    std::uint64_t expected_chunks = 0;
    std::uint64_t last_end = 8;
    bool footer_whole = false;
    for (const RecordSpan& r : records) {
      if (r.end > cut) break;
      last_end = r.end;
      if (r.op == 0x06) {
        ++expected_chunks;
        expected_messages += messages_in_chunk_at.at(r.offset);
      }
      if (r.op == 0x05) ++expected_messages;
      if (r.op == 0x02) footer_whole = true;
    }
    const McapReader reader(prefix, "cut.mcap");
    expect_same_messages(written, reader.messages(), expected_messages);
    const McapRecovery& rec = reader.recovery();
    EXPECT_EQ(rec.complete_chunks, expected_chunks);
    EXPECT_EQ(rec.rejected_chunks, 0u);
    EXPECT_EQ(rec.messages_recovered, expected_messages);
    EXPECT_FALSE(rec.footer_present);
    EXPECT_FALSE(reader.clean());
    EXPECT_FALSE(reader.diagnostics().empty());
    EXPECT_EQ(reader.state(), McapFileState::kNotClosed) << reader.diagnostics_text();
    EXPECT_EQ(reader.damage().intact_until, last_end);
    EXPECT_EQ(rec.header_present, cut >= records.front().end);
    // A Footer without its closing magic ends the parse at the Footer.
    EXPECT_EQ(rec.valid_bytes, last_end);
    EXPECT_EQ(rec.bytes_ignored_at_end, cut - last_end);
    if (!footer_whole) {
      bool names_offset = false;
      for (const McapDiagnostic& d : reader.diagnostics())
        names_offset = names_offset || d.offset == last_end;
      EXPECT_TRUE(names_offset) << reader.diagnostics_text();
    }
  }
}

INSTANTIATE_TEST_SUITE_P(Modes, McapTruncation,
                         ::testing::Values(Mode{"unchunked", 0, McapCompression::kNone},
                                           Mode{"chunked", 120, McapCompression::kNone},
                                           Mode{"zstd", 120, McapCompression::kZstd}),
                         mode_name);

// What a killed writer leaves: the chunks written so far, then maybe a block of
// zeros (a file system that had allocated but not written the tail).
TEST(McapRecovery, CopyOfOpenFileAndZeroTail) {
  test::TempDir dir;
  const std::string path = dir.file("live.mcap");
  McapWriterOptions options;
  options.chunk_size_bytes = 1 << 20;  // nothing is written until flush_chunk()
  McapWriter writer(path, options);
  const std::uint16_t schema = writer.add_schema("S", "omgidl", kIdl);
  const std::uint16_t channel = writer.add_channel("/odometry", "cdr", schema);
  for (std::uint32_t i = 0; i < 10; ++i) writer.write_message(channel, i, 100 + i, 100 + i, Bytes(8, 0x11));
  writer.flush_chunk();
  for (std::uint32_t i = 10; i < 15; ++i) writer.write_message(channel, i, 100 + i, 100 + i, Bytes(8, 0x22));
  EXPECT_EQ(writer.counters().chunks, 1u);
  EXPECT_GT(writer.chunk_bytes_buffered(), 0u);

  // The file as a crash at this moment would leave it: one chunk, the open one lost.
  Bytes snapshot = read_bytes(path);
  EXPECT_EQ(snapshot.size(), writer.counters().bytes_written);
  {
    const McapReader reader(snapshot, "snapshot");
    EXPECT_EQ(reader.messages().size(), 10u);
    EXPECT_EQ(reader.recovery().complete_chunks, 1u);
    EXPECT_FALSE(reader.recovery().footer_present);
    EXPECT_FALSE(reader.recovery().data_end_present);
    EXPECT_EQ(reader.recovery().bytes_ignored_at_end, 0u);
    ASSERT_EQ(reader.channels().size(), 1u);
    EXPECT_EQ(reader.schemas().size(), 1u);
  }
  snapshot.insert(snapshot.end(), 4096, 0);
  {
    const McapReader reader(snapshot, "zero_tail");
    EXPECT_EQ(reader.messages().size(), 10u);
    EXPECT_EQ(reader.recovery().bytes_ignored_at_end, 4096u);
    ASSERT_FALSE(reader.diagnostics().empty());
    EXPECT_EQ(reader.diagnostics()[0].offset, snapshot.size() - 4096);
    EXPECT_NE(reader.diagnostics()[0].message.find("0x00"), std::string::npos);
    EXPECT_EQ(reader.state(), McapFileState::kNotClosed) << reader.diagnostics_text();
  }
  writer.close();
  const McapReader reader(path);
  EXPECT_TRUE(reader.clean()) << reader.diagnostics_text();
  EXPECT_EQ(reader.state(), McapFileState::kComplete);
  EXPECT_TRUE(reader.damage().closed && reader.damage().summary_found && reader.damage().chunk_index_used);
  EXPECT_EQ(reader.messages().size(), 15u);
  EXPECT_EQ(reader.chunks().size(), 2u);
}

class McapCorruption : public ::testing::TestWithParam<Mode> {};

// One flipped byte inside a chunk's records: that chunk is rejected by its CRC
// (or by the decompressor), every other message survives.
TEST_P(McapCorruption, FlippedChunkByteIsDetected) {
  const Mode mode = GetParam();
  if (!mcap_compression_available(mode.compression)) GTEST_SKIP() << "compression not built in";
  test::TempDir dir;
  const std::string path = dir.file("good.mcap");
  McapWriterOptions options;
  options.chunk_size_bytes = mode.chunk_size_bytes;
  options.compression = mode.compression;
  const std::vector<McapMessage> written = write_sample(path, options, 30);
  const McapReader good(path);
  ASSERT_TRUE(good.clean()) << good.diagnostics_text();
  ASSERT_GE(good.chunks().size(), 3u);
  const McapChunkInfo victim = good.chunks()[1];
  ASSERT_GT(victim.message_count, 0u);

  Bytes file = read_bytes(path);
  // The last bytes of a chunk record are its records field; this one is in a
  // message payload (or in the compressed data).
  file[victim.offset + victim.length - 3] ^= 0x40;
  const std::string bad_path = dir.file("bad.mcap");
  write_bytes(bad_path, file);

  const McapReader reader(bad_path);
  EXPECT_FALSE(reader.clean());
  EXPECT_EQ(reader.recovery().rejected_chunks, 1u);
  EXPECT_EQ(reader.recovery().complete_chunks, good.chunks().size() - 1);
  EXPECT_TRUE(reader.recovery().footer_present);
  EXPECT_EQ(reader.messages().size(), written.size() - victim.message_count);
  bool chunk_reported = false;
  bool data_crc_reported = false;
  for (const McapDiagnostic& d : reader.diagnostics()) {
    chunk_reported = chunk_reported ||
                     (d.offset == victim.offset && d.message.find("Chunk rejected") != std::string::npos);
    data_crc_reported = data_crc_reported || d.message.find("data section CRC mismatch") != std::string::npos;
  }
  EXPECT_TRUE(chunk_reported) << reader.diagnostics_text();
  EXPECT_TRUE(data_crc_reported) << reader.diagnostics_text();
  if (mode.compression == McapCompression::kNone) {
    EXPECT_NE(reader.diagnostics_text().find("CRC mismatch: chunk says"), std::string::npos);
  }
  // Messages before and after the bad chunk are intact and in order.
  const std::size_t before = good.chunks()[0].message_count;
  expect_same_messages(
      written, {reader.messages().begin(), reader.messages().begin() + static_cast<std::ptrdiff_t>(before)},
      before);
  for (std::size_t i = before; i < reader.messages().size(); ++i) {
    EXPECT_EQ(reader.messages()[i].sequence, written[i + victim.message_count].sequence);
  }
}

INSTANTIATE_TEST_SUITE_P(Modes, McapCorruption,
                         ::testing::Values(Mode{"chunked", 200, McapCompression::kNone},
                                           Mode{"zstd", 200, McapCompression::kZstd}),
                         mode_name);

TEST(McapCorruption, SummaryByteIsDetectedBySummaryCrc) {
  test::TempDir dir;
  const std::string path = dir.file("good.mcap");
  McapWriterOptions options;
  options.chunk_size_bytes = 200;
  write_sample(path, options, 10);
  Bytes file = read_bytes(path);
  const std::vector<RecordSpan> records = top_level_records(file);
  const auto stats =
      std::find_if(records.begin(), records.end(), [](const RecordSpan& r) { return r.op == 0x0B; });
  ASSERT_NE(stats, records.end());
  file[stats->offset + 9 + 8 + 2 + 4 + 4 + 4 + 4 + 8 + 7] ^= 0x01;  // top byte of message_end_time
  const McapReader reader(file, "bad_summary");
  EXPECT_NE(reader.diagnostics_text().find("summary CRC mismatch"), std::string::npos)
      << reader.diagnostics_text();
  EXPECT_EQ(reader.messages().size(), 10u);
}

TEST(McapCrc, DisabledCrcsAreZeroAndNotChecked) {
  test::TempDir dir;
  const std::string path = dir.file("no_crc.mcap");
  McapWriterOptions options;
  options.chunk_size_bytes = 200;
  options.crc = false;
  write_sample(path, options, 10);
  const Bytes file = read_bytes(path);
  const std::vector<RecordSpan> records = top_level_records(file);
  for (const RecordSpan& r : records) {
    // Chunk: uncompressed_crc follows three u64 fields; Data End: the CRC is its only field.
    const std::uint64_t at = r.offset + 9 + (r.op == 0x06 ? 24 : 0);
    if (r.op == 0x06 || r.op == 0x0F) {
      EXPECT_EQ(Bytes(file.begin() + static_cast<std::ptrdiff_t>(at),
                      file.begin() + static_cast<std::ptrdiff_t>(at + 4)),
                Bytes(4, 0))
          << "record at " << r.offset;
    }
  }
  ASSERT_EQ(records.back().op, 0x02);
  EXPECT_EQ(Bytes(file.end() - 12, file.end() - 8), Bytes(4, 0));  // summary_crc
  const McapReader reader(path);
  EXPECT_TRUE(reader.clean()) << reader.diagnostics_text();
  EXPECT_EQ(reader.messages().size(), 10u);
}

TEST(McapIndex, ChunkIndexAndMessageIndexArePointedAtCorrectly) {
  test::TempDir dir;
  const std::string path = dir.file("indexed.mcap");
  McapWriterOptions options;
  options.chunk_size_bytes = 250;
  write_sample(path, options, 20);
  Bytes file = read_bytes(path);
  const McapReader good(file, "good");
  ASSERT_TRUE(good.clean()) << good.diagnostics_text();
  // Break the first Message Index record's first log_time: the reader notices.
  const std::vector<RecordSpan> records = top_level_records(file);
  const auto mi =
      std::find_if(records.begin(), records.end(), [](const RecordSpan& r) { return r.op == 0x07; });
  ASSERT_NE(mi, records.end());
  file[mi->offset + 9 + 2 + 4] ^= 0x01;
  const McapReader reader(file, "bad_index");
  EXPECT_NE(reader.diagnostics_text().find("matches no message"), std::string::npos)
      << reader.diagnostics_text();
  EXPECT_EQ(reader.messages().size(), 20u);
}

TEST(McapReaderErrors, NotMcapFilesThrowNamingTheFile) {
  test::TempDir dir;
  const std::string empty = dir.file("empty.mcap");
  write_bytes(empty, {});
  const std::string text = dir.file("text.mcap");
  write_bytes(text, Bytes{'h', 'e', 'l', 'l', 'o', ' ', 'w', 'o', 'r', 'l', 'd', '\n'});
  const std::string missing = dir.file("missing.mcap");
  for (const std::string& path : {empty, text, missing}) {
    try {
      McapReader reader(path);
      ADD_FAILURE() << "no exception for " << path;
    } catch (const std::runtime_error& e) {
      EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
    }
  }
  try {
    McapReader reader(text);
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("bad magic"), std::string::npos) << e.what();
  }
}

// A FIFO would block the open until a writer came (and Ctrl-C with it): it is
// refused at once, as a directory is, naming what it is.
TEST(McapReaderErrors, APipeOrADirectoryIsRefusedWithoutWaiting) {
  test::TempDir dir;
  const std::string fifo = dir.file("fifo.mcap");
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  for (const auto& [path, kind] : {std::pair<std::string, std::string>{fifo, "a pipe"}, {dir.path(), "a directory"}}) {
    try {
      McapReader reader(path);
      ADD_FAILURE() << "no exception for " << path;
    } catch (const std::runtime_error& e) {
      EXPECT_NE(std::string(e.what()).find(path + ": not a regular file (" + kind + ")"), std::string::npos)
          << e.what();
    }
  }
}

TEST(McapReaderErrors, OnlyMagicIsAnIncompleteFile) {
  Bytes magic = {0x89, 'M', 'C', 'A', 'P', '0', '\r', '\n'};
  const McapReader reader(magic, "magic_only");
  EXPECT_FALSE(reader.recovery().header_present);
  EXPECT_FALSE(reader.diagnostics().empty());
  EXPECT_TRUE(reader.messages().empty());
}

TEST(McapReaderErrors, GarbageAfterMagicDoesNotCrash) {
  std::mt19937 prng(3);
  for (int trial = 0; trial < 200; ++trial) {
    Bytes bytes = {0x89, 'M', 'C', 'A', 'P', '0', '\r', '\n'};
    const std::size_t n = prng() % 200;
    for (std::size_t i = 0; i < n; ++i) bytes.push_back(static_cast<std::uint8_t>(prng()));
    if (n > 9 && trial % 2 == 0) {
      bytes[8] = static_cast<std::uint8_t>(1 + prng() % 15);  // a real opcode with a small length
      for (int i = 0; i < 8; ++i) bytes[9 + static_cast<std::size_t>(i)] = 0;
      bytes[9] = static_cast<std::uint8_t>(prng() % 64);
    }
    const McapReader reader(bytes, "garbage");
    EXPECT_FALSE(reader.clean());
  }
}

// Random flips anywhere past the magic (lengths, sizes, compressed data):
// never throws or reads out of bounds, and a changed file is never clean.
// (The messages returned are not bounded: a Message Index opcode flipped into
// a Message one is a well-formed Message record outside any chunk.)
TEST(McapReaderErrors, RandomByteFlipsNeverCrash) {
  test::TempDir dir;
  const std::string path = dir.file("flips.mcap");
  McapWriterOptions options;
  options.chunk_size_bytes = 150;
  options.compression = mcap_compression_available(McapCompression::kZstd) ? McapCompression::kZstd
                                                                            : McapCompression::kNone;
  write_sample(path, options, 12);
  const Bytes file = read_bytes(path);
  std::mt19937 prng(11);
  for (int trial = 0; trial < 500; ++trial) {
    Bytes bytes = file;
    const int flips = 1 + static_cast<int>(prng() % 3);
    for (int f = 0; f < flips; ++f) {
      bytes[8 + prng() % (bytes.size() - 8)] ^= static_cast<std::uint8_t>(1u << (prng() % 8));
    }
    if (bytes == file) continue;  // two flips of the same bit
    const McapReader reader(bytes, "flipped");
    EXPECT_FALSE(reader.clean()) << "trial " << trial;
    EXPECT_FALSE(reader.diagnostics().empty()) << "trial " << trial;
  }
}

TEST(McapReaderErrors, HugeLengthIsACutRecordNotAnAllocation) {
  Bytes bytes = {0x89, 'M', 'C', 'A', 'P', '0', '\r', '\n', 0x06};
  append_u64(bytes, ~std::uint64_t{0});
  bytes.resize(bytes.size() + 50, 0xFF);
  const McapReader reader(bytes, "huge");
  EXPECT_EQ(reader.recovery().bytes_ignored_at_end, bytes.size() - 8);
  EXPECT_NE(reader.diagnostics_text().find("cut short"), std::string::npos) << reader.diagnostics_text();
}

TEST(McapWriterErrors, FailuresThrowNamingTheFile) {
  test::TempDir dir;
  const std::string bad = dir.file("no/such/dir/x.mcap");
  try {
    McapWriter writer(bad);
    ADD_FAILURE() << "no exception";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(bad), std::string::npos) << e.what();
  }

  const std::string path = dir.file("w.mcap");
  McapWriter writer(path);
  EXPECT_TRUE(writer.is_open());
  EXPECT_THROW(writer.open(path), std::runtime_error);
  const Bytes payload = {1, 2, 3};
  try {
    writer.write_message(1, 0, 0, 0, payload);
    ADD_FAILURE() << "no exception";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("unknown channel"), std::string::npos) << e.what();
  }
  EXPECT_THROW(writer.add_channel("/t", "cdr", 5), std::runtime_error);
  const std::uint16_t channel = writer.add_channel("/t", "cdr", 0);
  writer.write_message(channel, 0, 0, 0, payload);
  writer.close();
  EXPECT_FALSE(writer.is_open());
  writer.close();  // no-op
  EXPECT_THROW(writer.write_message(channel, 1, 0, 0, payload), std::runtime_error);
  const McapReader reader(path);
  EXPECT_TRUE(reader.clean()) << reader.diagnostics_text();
  EXPECT_EQ(reader.messages().size(), 1u);
}

TEST(McapWriterErrors, UnavailableCompressionIsRefused) {
  if (mcap_compression_available(McapCompression::kLz4)) GTEST_SKIP() << "lz4 is built in";
  test::TempDir dir;
  McapWriterOptions options;
  options.compression = McapCompression::kLz4;
  EXPECT_THROW(McapWriter(dir.file("x.mcap"), options), std::runtime_error);
}

TEST(McapWriter, DestructorClosesTheFile) {
  test::TempDir dir;
  const std::string path = dir.file("scoped.mcap");
  {
    McapWriterOptions options;
    options.compression =
        mcap_compression_available(McapCompression::kZstd) ? McapCompression::kZstd : McapCompression::kNone;
    options.sync_after_chunk = true;
    McapWriter writer(path, options);
    const std::uint16_t channel = writer.add_channel("/t", "cdr", 0);
    for (std::uint32_t i = 0; i < 1000; ++i) writer.write_message(channel, i, i, i, Bytes(100, 7));
    writer.flush();
  }
  const McapReader reader(path);
  EXPECT_TRUE(reader.clean()) << reader.diagnostics_text();
  EXPECT_EQ(reader.messages().size(), 1000u);
  ASSERT_TRUE(reader.statistics().has_value());
  EXPECT_EQ(reader.statistics()->message_end_time_ns, 999u);
}

// ---- Damage: resynchronising past a bad record (docs/mcap.md, "Damage") ----

// A log of `count` messages in many small chunks (zstd when built in).
struct ManyChunks {
  std::vector<McapMessage> written;
  Bytes file;
  std::vector<McapChunkInfo> chunks;  // as a clean read finds them
  std::uint64_t data_end = 0;         // offset of the Data End record
};

ManyChunks write_many_chunks(const test::TempDir& dir, int count, McapCompression compression) {
  ManyChunks out;
  const std::string path = dir.file("many.mcap");
  McapWriterOptions options;
  options.chunk_size_bytes = 1024;
  options.compression = compression;
  out.written = write_sample(path, options, count);
  out.file = read_bytes(path);
  const McapReader good(out.file, "good");
  EXPECT_TRUE(good.clean()) << good.diagnostics_text();
  out.chunks = good.chunks();
  for (const RecordSpan& r : top_level_records(out.file)) {
    if (r.op == 0x0F) out.data_end = r.offset;
  }
  return out;
}

McapCompression zstd_if_built() {
  return mcap_compression_available(McapCompression::kZstd) ? McapCompression::kZstd : McapCompression::kNone;
}

// The messages read are the written ones without those of `lost_chunk`
// (none when it is SIZE_MAX), in order.
void expect_all_but_chunk(const ManyChunks& log, const McapReader& reader, std::size_t lost_chunk) {
  std::size_t first_lost = 0;
  std::size_t lost = 0;
  for (std::size_t i = 0; i < log.chunks.size(); ++i) {
    if (i < lost_chunk) first_lost += log.chunks[i].message_count;
    if (i == lost_chunk) lost = log.chunks[i].message_count;
  }
  ASSERT_EQ(reader.messages().size(), log.written.size() - lost) << reader.diagnostics_text();
  for (std::size_t i = 0; i < reader.messages().size(); ++i) {
    const McapMessage& expected = log.written[i < first_lost ? i : i + lost];
    ASSERT_EQ(reader.messages()[i].sequence, expected.sequence) << i;
    ASSERT_EQ(reader.messages()[i].data, expected.data) << i;
  }
}

bool damage_recorded_at(const McapReader& reader, std::uint64_t offset) {
  bool in_records = false;
  for (const McapDamagedRecord& d : reader.damage().records) in_records = in_records || d.offset == offset;
  bool in_diagnostics = false;
  for (const McapDiagnostic& d : reader.diagnostics()) in_diagnostics = in_diagnostics || d.offset == offset;
  return in_records && in_diagnostics;
}

// One chunk's length field damaged (beyond the end of the file, or a little
// off): every other chunk is read, with and without the summary (which is cut
// off in the second case, so that the reader has to scan). The chunk's own
// header still gives its length and its CRC checks it, so it is read too;
// damaging its records as well loses that chunk alone.
TEST(McapDamage, CorruptChunkLengthLosesAtMostThatChunk) {
  test::TempDir dir;
  const ManyChunks log = write_many_chunks(dir, 3000, zstd_if_built());
  ASSERT_GE(log.chunks.size(), 20u);
  const std::size_t victim_index = log.chunks.size() / 2;
  const McapChunkInfo& victim = log.chunks[victim_index];
  for (const bool with_summary : {true, false}) {
    for (const int length_byte : {1, 7}) {
      for (const bool records_damaged : {false, true}) {
        SCOPED_TRACE(std::string(with_summary ? "with summary" : "summary cut off") + ", length byte " +
                     std::to_string(length_byte) + (records_damaged ? ", records damaged" : ""));
        Bytes file = log.file;
        file[victim.offset + 1 + static_cast<std::uint64_t>(length_byte)] ^= 0x40;
        if (records_damaged) file[victim.offset + victim.length - 5] ^= 0x21;
        if (!with_summary) file.resize(log.data_end);
        const McapReader reader(file, "damaged");
        expect_all_but_chunk(log, reader, records_damaged ? victim_index : SIZE_MAX);
        EXPECT_EQ(reader.state(), McapFileState::kDamaged);
        EXPECT_TRUE(damage_recorded_at(reader, victim.offset)) << reader.diagnostics_text();
        EXPECT_EQ(reader.damage().intact_until, victim.offset);
        EXPECT_EQ(reader.recovery().rejected_chunks, records_damaged ? 1u : 0u);
        EXPECT_EQ(reader.recovery().complete_chunks, log.chunks.size() - (records_damaged ? 1 : 0));
        EXPECT_EQ(reader.damage().footer_found, with_summary);
        EXPECT_EQ(reader.damage().summary_found, with_summary);
        EXPECT_EQ(reader.damage().chunk_index_used, with_summary);
        EXPECT_EQ(reader.recovery().footer_present, with_summary);
        EXPECT_FALSE(reader.damage().closed && !with_summary);
      }
    }
  }
}

// The chunk's opcode and length both destroyed (zeros): with the chunk index
// it is still found and read; without the summary the reader scans past it
// to its Message Index records and loses only it.
TEST(McapDamage, DestroyedChunkPrefixResynchronisesAtTheNextChunk) {
  test::TempDir dir;
  const ManyChunks log = write_many_chunks(dir, 1500, zstd_if_built());
  const std::size_t victim_index = 3;
  const McapChunkInfo& victim = log.chunks[victim_index];
  for (const bool with_summary : {true, false}) {
    SCOPED_TRACE(with_summary ? "with summary" : "summary cut off");
    Bytes file = log.file;
    std::fill(file.begin() + static_cast<std::ptrdiff_t>(victim.offset),
              file.begin() + static_cast<std::ptrdiff_t>(victim.offset + 9), 0);
    if (!with_summary) file.resize(log.data_end);
    const McapReader reader(file, "damaged");
    expect_all_but_chunk(log, reader, with_summary ? SIZE_MAX : victim_index);
    EXPECT_EQ(reader.state(), McapFileState::kDamaged);
    EXPECT_TRUE(damage_recorded_at(reader, victim.offset)) << reader.diagnostics_text();
    if (!with_summary) {
      // Skipped: the chunk, up to its Message Index records.
      ASSERT_EQ(reader.damage().skipped.size(), 1u) << reader.diagnostics_text();
      EXPECT_EQ(reader.damage().skipped[0].begin, victim.offset);
      EXPECT_EQ(reader.damage().skipped[0].end, victim.offset + victim.length);
      EXPECT_EQ(reader.damage().bytes_skipped, victim.length);
    }
  }
}

// A file cut in the middle of a chunk: not closed (not damaged), every chunk
// before the cut read, "intact up to" the cut chunk.
TEST(McapDamage, TruncatedMidChunkIsNotClosed) {
  test::TempDir dir;
  for (const McapCompression compression : {McapCompression::kNone, zstd_if_built()}) {
    SCOPED_TRACE(mcap_compression_name(compression));
    const ManyChunks log = write_many_chunks(dir, 1500, compression);
    const std::size_t cut_chunk = log.chunks.size() - 4;
    const McapChunkInfo& c = log.chunks[cut_chunk];
    for (const std::uint64_t into : {std::uint64_t{5}, std::uint64_t{30}, c.length / 2, c.length - 1}) {
      SCOPED_TRACE("cut " + std::to_string(into) + " bytes into the chunk");
      const Bytes file(log.file.begin(), log.file.begin() + static_cast<std::ptrdiff_t>(c.offset + into));
      const McapReader reader(file, "cut");
      std::size_t expected = 0;
      for (std::size_t i = 0; i < cut_chunk; ++i) expected += log.chunks[i].message_count;
      expect_same_messages(log.written, reader.messages(), expected);
      EXPECT_EQ(reader.state(), McapFileState::kNotClosed) << reader.diagnostics_text();
      EXPECT_FALSE(reader.damage().closed);
      EXPECT_FALSE(reader.damage().footer_found);
      EXPECT_FALSE(reader.damage().summary_found);
      EXPECT_TRUE(reader.damage().records.empty());
      EXPECT_EQ(reader.damage().bytes_skipped, 0u);
      EXPECT_EQ(reader.damage().intact_until, c.offset);
      EXPECT_EQ(reader.recovery().valid_bytes, c.offset);
      EXPECT_EQ(reader.recovery().rejected_chunks, 0u);
    }
  }
}

// Random bytes over the middle of an unchunked file (Message records straight
// in the data section, no index): the reader scans to the first record after
// them and reads everything from there on.
TEST(McapDamage, GarbageInUnchunkedFileResumesAtTheNextRecord) {
  test::TempDir dir;
  const std::string path = dir.file("unchunked.mcap");
  McapWriterOptions options;
  options.chunk_size_bytes = 0;
  const std::vector<McapMessage> written = write_sample(path, options, 400);
  const Bytes good = read_bytes(path);
  const std::vector<RecordSpan> records = top_level_records(good);
  std::mt19937 prng(2024);
  for (int trial = 0; trial < 20; ++trial) {
    SCOPED_TRACE("trial " + std::to_string(trial));
    Bytes file = good;
    // From somewhere before record k's prefix to somewhere after it.
    const std::size_t k = 20 + prng() % (records.size() - 60);
    const std::uint64_t from = records[k].offset - prng() % 30;
    const std::uint64_t to = records[k].offset + 9 + prng() % 100;
    for (std::uint64_t i = from; i < to; ++i) file[i] = static_cast<std::uint8_t>(prng());
    // Records whose prefix (opcode, length) is intact and starts before the
    // garbage are read; the first record starting after the garbage is where
    // reading resumes, and every record from there on is read.
    std::size_t before = 0;
    std::size_t after = 0;
    std::uint64_t resume = 0;
    std::uint64_t bad = 0;
    for (const RecordSpan& r : records) {
      if (r.offset + 9 <= from) {
        before += r.op == 0x05 ? 1 : 0;
        bad = r.end;
      }
      if (r.offset >= to && resume == 0) resume = r.offset;
      if (r.offset >= to && r.op == 0x05) ++after;
    }
    const McapReader reader(file, "garbage");
    EXPECT_EQ(reader.state(), McapFileState::kDamaged);
    EXPECT_EQ(reader.messages().size(), before + after) << reader.diagnostics_text();
    ASSERT_EQ(reader.damage().skipped.size(), 1u) << reader.diagnostics_text();
    EXPECT_EQ(reader.damage().skipped[0].begin, bad) << reader.diagnostics_text();
    EXPECT_EQ(reader.damage().skipped[0].end, resume) << reader.diagnostics_text();
    EXPECT_LE(reader.damage().intact_until, bad);
    EXPECT_GE(reader.damage().intact_until, std::min(from, records[k - 1].offset));
    EXPECT_TRUE(reader.recovery().footer_present);
    // Everything after the garbage is exactly what was written.
    const std::size_t n = reader.messages().size();
    for (std::size_t i = 0; i < after && i < n; ++i) {
      EXPECT_EQ(reader.messages()[n - 1 - i].sequence, written[written.size() - 1 - i].sequence);
      EXPECT_EQ(reader.messages()[n - 1 - i].data, written[written.size() - 1 - i].data);
    }
  }
}

// 200 single-byte corruptions at random offsets of a chunked file (fixed
// seed): never a crash or a hang, every file is reported damaged (none as
// complete or as merely not closed), at most one chunk's messages are lost,
// and what is read is what was written, in order.
TEST(McapDamage, SingleByteCorruptionSweepIsAlwaysReportedAsDamage) {
  test::TempDir dir;
  const ManyChunks log = write_many_chunks(dir, 1200, zstd_if_built());
  std::uint64_t largest_chunk = 0;
  for (const McapChunkInfo& c : log.chunks) largest_chunk = std::max(largest_chunk, c.message_count);
  std::map<std::uint32_t, std::size_t> index_of_sequence;
  for (std::size_t i = 0; i < log.written.size(); ++i) index_of_sequence[log.written[i].sequence] = i;
  std::mt19937 prng(18);
  for (int trial = 0; trial < 200; ++trial) {
    Bytes file = log.file;
    const std::uint64_t at = 8 + prng() % (file.size() - 8);
    file[at] ^= static_cast<std::uint8_t>(1 + prng() % 255);
    SCOPED_TRACE("trial " + std::to_string(trial) + ": byte " + std::to_string(at) + " of " +
                 std::to_string(file.size()));
    const McapReader reader(file, "corrupt");
    EXPECT_EQ(reader.state(), McapFileState::kDamaged) << reader.diagnostics_text();
    EXPECT_FALSE(reader.clean());
    EXPECT_LE(reader.damage().intact_until, at + 1) << reader.diagnostics_text();
    EXPECT_GE(reader.messages().size(), log.written.size() - largest_chunk) << reader.diagnostics_text();
    std::size_t next = 0;
    for (const McapMessage& m : reader.messages()) {
      const auto it = index_of_sequence.find(m.sequence);
      ASSERT_NE(it, index_of_sequence.end()) << "a message that was never written";
      ASSERT_GE(it->second, next) << "messages out of order";
      EXPECT_EQ(m.data, log.written[it->second].data);
      next = it->second + 1;
    }
  }
}

}  // namespace
}  // namespace pixyslam::mcap
