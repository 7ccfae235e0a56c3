#pragma once

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <map>
#include <memory>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace pixyslam::mcap {

// Chunk compression. kZstd and kLz4 exist only when the library was built with
// libzstd / liblz4 (see mcap_compression_available); the names are MCAP's.
enum class McapCompression { kNone, kZstd, kLz4 };

// "" , "zstd" or "lz4".
const char* mcap_compression_name(McapCompression compression);
bool mcap_compression_available(McapCompression compression);

// "pixyslam <project version>", the Header's default library string.
std::string mcap_default_library();

struct McapWriterOptions {
  std::string profile;  // Header profile; "" (none) or e.g. "pixyslam"
  std::string library;  // Header library; "" = mcap_default_library()
  // Uncompressed bytes buffered before a Chunk is written. 0 = no chunks: every
  // record goes straight to the file and there is no chunk index.
  std::size_t chunk_size_bytes = std::size_t{1} << 20;
  McapCompression compression = McapCompression::kNone;
  int compression_level = 0;  // 0 = the codec's default
  // CRC32 of every chunk, of the data section (Data End) and of the summary
  // (Footer); false writes 0, which readers take as "not available".
  bool crc = true;
  // fsync(2) after every chunk (and in flush()), not only fflush.
  bool sync_after_chunk = false;
};

// Running totals since open().
struct McapWriterCounters {
  std::uint64_t messages = 0;
  std::uint64_t schemas = 0;
  std::uint64_t channels = 0;
  std::uint64_t chunks = 0;         // Chunk records written to the file
  std::uint64_t bytes_written = 0;  // file size so far (the open chunk is not in it)
  std::uint64_t message_bytes = 0;  // sum of message payload sizes
};

// Writes an MCAP file (https://mcap.dev/spec, major version 0) in one pass:
//
//   magic, Header, data section, Data End, summary (Schema, Channel,
//   Statistics, Chunk Index groups), Summary Offset records, Footer, magic.
//
// In chunked mode (chunk_size_bytes > 0) Schema, Channel and Message records
// are buffered into a Chunk; a full chunk is written with its Message Index
// records and fflush()ed (fsync()ed with sync_after_chunk), so a killed writer
// loses at most the open chunk. Schemas and channels are repeated in the
// summary. Times are nanoseconds on any epoch the caller chooses.
//
// Every failure (open, write, unknown id, use after close) throws
// std::runtime_error whose message starts with the file path; after a write
// failure the writer is closed and unusable. The destructor closes the file
// and swallows errors (call close() to see them). Thread-compatible.
class McapWriter {
 public:
  McapWriter() = default;
  // Same as open(path, options).
  explicit McapWriter(const std::string& path, const McapWriterOptions& options = {});
  ~McapWriter();
  McapWriter(const McapWriter&) = delete;
  McapWriter& operator=(const McapWriter&) = delete;

  // Creates (truncates) `path` and writes magic + Header. Throws if already
  // open, if the compression is not available, or if the file cannot be written.
  void open(const std::string& path, const McapWriterOptions& options = {});

  // Returns the new schema id (1, 2, ...). `data` is the schema text or bytes,
  // e.g. encoding "omgidl" with the IDL source.
  std::uint16_t add_schema(std::string_view name, std::string_view encoding, std::string_view data);
  // Returns the new channel id (1, 2, ...). schema_id 0 = no schema, otherwise
  // an id returned by add_schema. For DDS topics: message_encoding "cdr".
  std::uint16_t add_channel(std::string_view topic, std::string_view message_encoding,
                            std::uint16_t schema_id, const std::map<std::string, std::string>& metadata = {});
  // Appends one message (its serialized bytes, copied) on a channel from add_channel.
  void write_message(std::uint16_t channel_id, std::uint32_t sequence, std::uint64_t log_time_ns,
                     std::uint64_t publish_time_ns, const std::uint8_t* data, std::size_t size);
  void write_message(std::uint16_t channel_id, std::uint32_t sequence, std::uint64_t log_time_ns,
                     std::uint64_t publish_time_ns, const std::vector<std::uint8_t>& data) {
    write_message(channel_id, sequence, log_time_ns, publish_time_ns, data.data(), data.size());
  }

  // Writes the open chunk now even if not full (no-op when empty or unchunked).
  // Lets a caller bound the data lost in a crash by time as well as by size.
  void flush_chunk();
  // flush_chunk(), then fflush (and fsync with sync_after_chunk).
  void flush();
  // Writes the last chunk, Data End, summary, Footer and closing magic, then
  // closes the file. No-op when not open.
  void close();

  bool is_open() const { return file_ != nullptr; }
  const std::string& path() const { return path_; }
  const McapWriterCounters& counters() const { return counters_; }
  // Uncompressed bytes waiting in the open chunk.
  std::size_t chunk_bytes_buffered() const { return chunk_.size(); }

 private:
  struct ChannelInfo {
    std::uint16_t id = 0;
    std::uint16_t schema_id = 0;
    std::string topic;
    std::string message_encoding;
    std::map<std::string, std::string> metadata;
  };
  struct SchemaInfo {
    std::uint16_t id = 0;
    std::string name;
    std::string encoding;
    std::string data;
  };
  struct ChunkIndexEntry {
    std::uint64_t message_start_time = 0;
    std::uint64_t message_end_time = 0;
    std::uint64_t chunk_start_offset = 0;
    std::uint64_t chunk_length = 0;
    std::map<std::uint16_t, std::uint64_t> message_index_offsets;
    std::uint64_t message_index_length = 0;
    std::uint64_t compressed_size = 0;
    std::uint64_t uncompressed_size = 0;
  };
  struct FileCloser {
    void operator()(std::FILE* f) const;
  };

  void require_open(const char* what) const;
  [[noreturn]] void fail(const std::string& what);
  // Appends to the file, updating offset and the data-section CRC.
  void write_bytes(const std::uint8_t* data, std::size_t size);
  void write_bytes(const std::vector<std::uint8_t>& bytes) { write_bytes(bytes.data(), bytes.size()); }
  // A data-section record: into the open chunk, or straight to the file when unchunked.
  void emit_data_record(const std::vector<std::uint8_t>& record);
  void write_chunk();
  void sync_file();
  std::vector<std::uint8_t> summary_section(std::uint64_t summary_start,
                                            std::uint64_t& summary_offset_start) const;

  std::unique_ptr<std::FILE, FileCloser> file_;
  std::string path_;
  McapWriterOptions options_;
  McapWriterCounters counters_;
  std::uint64_t offset_ = 0;
  std::uint32_t data_crc_ = 0;

  std::vector<SchemaInfo> schemas_;    // id = index + 1
  std::vector<ChannelInfo> channels_;  // id = index + 1
  std::map<std::uint16_t, std::uint64_t> channel_message_counts_;
  std::uint64_t message_start_time_ = 0;
  std::uint64_t message_end_time_ = 0;

  // The open chunk: uncompressed records, their log-time range, and per channel
  // (log_time, offset in the uncompressed records) of every message.
  std::vector<std::uint8_t> chunk_;
  std::uint64_t chunk_start_time_ = 0;
  std::uint64_t chunk_end_time_ = 0;
  bool chunk_has_messages_ = false;
  std::map<std::uint16_t, std::vector<std::pair<std::uint64_t, std::uint64_t>>> chunk_message_index_;
  std::vector<ChunkIndexEntry> chunk_indexes_;
  std::vector<std::uint8_t> scratch_;
};

}  // namespace pixyslam::mcap
