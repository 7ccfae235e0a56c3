#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

namespace pixyslam::mcap {

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

// What the file as a whole is, as `pixyslam_log info` reports it.
enum class McapFileState {
  kComplete,   // Footer and closing magic present, no diagnostics
  kNotClosed,  // no Footer and no closing magic, nothing else wrong: what a writer that did not close
               // the file leaves (killed, still writing, a copy of an open file). Every record before
               // McapDamage::intact_until is intact; only what follows (a cut record, or zeros) is lost
  kDamaged,    // anything else: corrupt records, bytes skipped, CRC / index / Statistics mismatches
};

// "complete", "not closed", "damaged".
const char* mcap_file_state_name(McapFileState state);

struct McapByteRange {
  std::uint64_t begin = 0;
  std::uint64_t end = 0;  // one past the last byte
};

// A record the reader could not use as it stood, or a run of bytes that is no
// record. [offset, end) is what it spans as far as the reader could tell.
struct McapDamagedRecord {
  std::uint64_t offset = 0;
  std::uint64_t end = 0;
  std::string what;
};

// Where the file is damaged and how the reader got past it. The reader
// resynchronises after a bad record (bad opcode, a length past the end of the
// file or across a record the chunk index names, a chunk failing its CRC or
// decompression, a malformed record): at the next record the chunk index names
// when the summary is intact, else at the next offset where a valid record
// starts (a chunk that decodes and matches its CRC, the Data End whose CRC
// matches, the Footer before the closing magic, or a run of well-formed
// records). A Chunk whose length field alone is wrong is read at the length
// its own header (and the chunk index) gives, checked by its CRC.
struct McapDamage {
  McapFileState state = McapFileState::kNotClosed;
  bool closed = false;            // the file ends with a Footer and the closing magic
  bool footer_found = false;      // a Footer record right before the closing magic at the end
  bool summary_found = false;     // the summary section that Footer points at parses (CRC ok when set)
  bool chunk_index_used = false;  // chunks were located by its Chunk Index records
  // Every byte before this offset belongs to intact records: the first damage
  // (kDamaged), the end of the last complete record (kNotClosed), the file size.
  std::uint64_t intact_until = 0;
  std::vector<McapDamagedRecord> records;  // in file order
  std::vector<McapByteRange> skipped;      // bytes passed over to reach the next valid record
  std::uint64_t bytes_skipped = 0;         // sum of `skipped`
};

// Reads a whole MCAP file (https://mcap.dev/spec) into memory and parses it
// front to back, the way a file from a killed writer must be read. When the
// file ends with a Footer whose summary is intact, its Chunk Index records say
// where each chunk is, so that a damaged chunk loses only itself; otherwise
// the reader scans past a bad record for the next valid one (McapDamage).
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
// records, bad opcodes and lengths (reading resumes at the next valid record),
// reserved opcodes (reported, skipped), private opcodes (skipped silently).
// Messages are returned in file order from every complete valid record.
// state() says whether the file is complete, not closed (only cut short) or
// damaged; damage() says where.
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
  // Complete, not closed, or damaged, and where the damage is.
  const McapDamage& damage() const { return damage_; }
  McapFileState state() const { return damage_.state; }
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
  McapDamage damage_;
  std::vector<McapDiagnostic> diagnostics_;
};

}  // namespace pixyslam::mcap
