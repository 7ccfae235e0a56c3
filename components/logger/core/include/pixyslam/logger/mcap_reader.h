#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

namespace pixyslam::logger {

struct McapSchema {
  std::uint16_t id = 0;
  std::string name;
  std::string encoding;  // e.g. "omgidl"
  std::string data;      // the schema bytes (IDL text for omgidl)
};

struct McapChannel {
  std::uint16_t id = 0;
  std::uint16_t schema_id = 0;  // 0 = no schema
  std::string topic;
  std::string message_encoding;  // e.g. "cdr"
  std::map<std::string, std::string> metadata;
};

struct McapMessage {
  std::uint16_t channel_id = 0;
  std::uint32_t sequence = 0;
  std::uint64_t log_time_ns = 0;
  std::uint64_t publish_time_ns = 0;
  std::vector<std::uint8_t> data;
};

// The Statistics record of the summary section, as written.
struct McapStatistics {
  std::uint64_t message_count = 0;
  std::uint16_t schema_count = 0;
  std::uint32_t channel_count = 0;
  std::uint32_t attachment_count = 0;
  std::uint32_t metadata_count = 0;
  std::uint32_t chunk_count = 0;
  std::uint64_t message_start_time_ns = 0;
  std::uint64_t message_end_time_ns = 0;
  std::map<std::uint16_t, std::uint64_t> channel_message_counts;
};

// One Chunk record of the data section.
struct McapChunkInfo {
  std::uint64_t offset = 0;  // of the record's opcode byte
  std::uint64_t length = 0;  // whole record, opcode and length prefix included
  std::string compression;
  std::uint64_t compressed_size = 0;
  std::uint64_t uncompressed_size = 0;
  std::uint64_t message_start_time_ns = 0;
  std::uint64_t message_end_time_ns = 0;
  std::uint64_t message_count = 0;  // messages taken from it (0 when rejected)
  bool valid = false;               // CRC (when non-zero), decompression and inner records fine
};

// Something wrong with the file, and where: `offset` is the byte offset of the
// record (or field) concerned from the start of the file.
struct McapDiagnostic {
  std::uint64_t offset = 0;
  std::string message;
};

// How much of the file could be used. A file closed properly by McapWriter has
// footer_present, no diagnostics and bytes_ignored_at_end == 0.
struct McapRecovery {
  std::uint64_t file_size = 0;
  bool header_present = false;
  bool data_end_present = false;
  bool summary_present = false;       // at least one record between Data End and the Footer
  bool footer_present = false;        // a Footer record followed by the closing magic
  std::uint64_t complete_chunks = 0;  // chunk records present in full and valid
  std::uint64_t rejected_chunks = 0;  // chunk records present in full but failing CRC / decoding
  std::uint64_t messages_recovered = 0;
  std::uint64_t valid_bytes = 0;           // end of the last complete record (or closing magic)
  std::uint64_t bytes_ignored_at_end = 0;  // file_size - valid_bytes: a cut record, garbage, zeros
};

// Reads a whole MCAP file (https://mcap.dev/spec) into memory and parses it
// front to back, the way a file from a killed writer must be read: no use of
// the summary or index to find data.
//
// Verified: magic at both ends, every record length, chunk CRCs, the Data End
// CRC and the summary CRC (when non-zero), duplicate Schema/Channel records
// agree, Message Index and Chunk Index records point at what they claim,
// Summary Offset groups, and the Statistics counts. Decompresses "zstd" and
// "lz4" chunks when built with them.
//
// Tolerated, each reported in diagnostics() with its offset instead of
// throwing: a file cut anywhere after the leading magic (no Footer, a record or
// chunk cut short), zeros or garbage at the end, a chunk failing its CRC or
// decompression (its messages are dropped, the rest is kept), malformed
// records (skipped), unknown opcodes (skipped silently). Messages are returned
// in file order from every complete valid record.
//
// Throws std::runtime_error naming the file if it cannot be read, or if it is
// shorter than the 8-byte magic or does not begin with it (not MCAP).
// Immutable after construction; thread-safe for concurrent const use.
class McapReader {
 public:
  explicit McapReader(const std::string& path);
  // Parses bytes already in memory; `name` stands in for the path in messages.
  McapReader(std::vector<std::uint8_t> bytes, const std::string& name);

  const std::string& path() const { return path_; }
  const std::string& profile() const { return profile_; }
  const std::string& library() const { return library_; }
  // In order of first appearance, one per id.
  const std::vector<McapSchema>& schemas() const { return schemas_; }
  const std::vector<McapChannel>& channels() const { return channels_; }
  const std::vector<McapMessage>& messages() const { return messages_; }
  const std::vector<McapChunkInfo>& chunks() const { return chunks_; }
  // The summary's Statistics record, if there was one.
  const std::optional<McapStatistics>& statistics() const { return statistics_; }
  const McapRecovery& recovery() const { return recovery_; }
  const std::vector<McapDiagnostic>& diagnostics() const { return diagnostics_; }
  // True when the file is complete and nothing was wrong with it.
  bool clean() const { return diagnostics_.empty() && recovery_.footer_present; }

  const McapSchema* find_schema(std::uint16_t id) const;
  const McapChannel* find_channel(std::uint16_t id) const;
  const McapChannel* find_channel(const std::string& topic) const;
  // Diagnostics one per line, "offset N: message".
  std::string diagnostics_text() const;

 private:
  class Parser;

  std::string path_;
  std::string profile_;
  std::string library_;
  std::vector<McapSchema> schemas_;
  std::vector<McapChannel> channels_;
  std::vector<McapMessage> messages_;
  std::vector<McapChunkInfo> chunks_;
  std::optional<McapStatistics> statistics_;
  McapRecovery recovery_;
  std::vector<McapDiagnostic> diagnostics_;
};

}  // namespace pixyslam::logger
