#include "pixyslam/mcap/mcap_writer.h"

#include <unistd.h>  // fsync, fileno

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <stdexcept>

#include "mcap_format.h"
#include "pixyslam/mcap/crc32.h"

#ifndef PIXYSLAM_VERSION_STRING
#define PIXYSLAM_VERSION_STRING "unknown"
#endif

namespace pixyslam::mcap {

using detail::ByteSink;

namespace {

// The record layouts the writer emits in more than one place (https://mcap.dev/spec).
void put_schema(ByteSink& out, std::uint16_t id, std::string_view name, std::string_view encoding,
                std::string_view data) {
  const std::size_t rec = out.begin_record(detail::kOpSchema);
  out.u16(id);
  out.str(name);
  out.str(encoding);
  out.str(data);
  out.end_record(rec);
}

void put_channel(ByteSink& out, std::uint16_t id, std::uint16_t schema_id, std::string_view topic,
                 std::string_view message_encoding, const std::map<std::string, std::string>& metadata) {
  const std::size_t rec = out.begin_record(detail::kOpChannel);
  out.u16(id);
  out.u16(schema_id);
  out.str(topic);
  out.str(message_encoding);
  const std::size_t map = out.begin_u32_prefix();
  for (const auto& [key, value] : metadata) {
    out.str(key);
    out.str(value);
  }
  out.end_u32_prefix(map);
  out.end_record(rec);
}

// Map<uint16, uint64> (Statistics channel_message_counts, Chunk Index message_index_offsets).
void put_u16_u64_map(ByteSink& out, const std::map<std::uint16_t, std::uint64_t>& map) {
  const std::size_t at = out.begin_u32_prefix();
  for (const auto& [key, value] : map) {
    out.u16(key);
    out.u64(value);
  }
  out.end_u32_prefix(at);
}

}  // namespace

const char* mcap_compression_name(McapCompression compression) {
  switch (compression) {
    case McapCompression::kZstd: return "zstd";
    case McapCompression::kLz4: return "lz4";
    case McapCompression::kNone: break;
  }
  return "";
}

bool mcap_compression_available(McapCompression compression) {
  switch (compression) {
    case McapCompression::kNone: return true;
#ifdef PIXYSLAM_MCAP_HAVE_ZSTD
    case McapCompression::kZstd: return true;
#endif
#ifdef PIXYSLAM_MCAP_HAVE_LZ4
    case McapCompression::kLz4: return true;
#endif
    default: return false;
  }
}

std::string mcap_default_library() { return std::string("pixyslam ") + PIXYSLAM_VERSION_STRING; }

void McapWriter::FileCloser::operator()(std::FILE* f) const { std::fclose(f); }

McapWriter::McapWriter(const std::string& path, const McapWriterOptions& options) { open(path, options); }

McapWriter::~McapWriter() {
  try {
    close();
  } catch (...) {
    // Destructors must not throw; close() reports the error to callers who ask.
  }
}

void McapWriter::open(const std::string& path, const McapWriterOptions& options) {
  if (file_) throw std::runtime_error(path + ": McapWriter::open: writer already open on " + path_);
  if (!mcap_compression_available(options.compression)) {
    throw std::runtime_error(path + ": MCAP compression '" + mcap_compression_name(options.compression) +
                             "' is not available in this build");
  }
  std::FILE* f = std::fopen(path.c_str(), "wb");
  if (f == nullptr) throw std::runtime_error(path + ": cannot open for writing: " + std::strerror(errno));
  file_.reset(f);
  path_ = path;
  options_ = options;
  counters_ = {};
  offset_ = 0;
  data_crc_ = 0;
  schemas_.clear();
  channels_.clear();
  channel_message_counts_.clear();
  message_start_time_ = message_end_time_ = 0;
  chunk_.clear();
  chunk_message_index_.clear();
  chunk_has_messages_ = false;
  chunk_indexes_.clear();

  std::vector<std::uint8_t> head(detail::kMagic.begin(), detail::kMagic.end());
  ByteSink out(head);
  const std::size_t rec = out.begin_record(detail::kOpHeader);
  out.str(options_.profile);
  out.str(options_.library.empty() ? mcap_default_library() : options_.library);
  out.end_record(rec);
  write_bytes(head);
  // A reader of a file whose writer died early still finds magic + Header.
  if (std::fflush(file_.get()) != 0) fail("flush failed");
}

void McapWriter::require_open(const char* what) const {
  if (!file_) {
    throw std::runtime_error((path_.empty() ? std::string("<no file>") : path_) + ": McapWriter::" + what +
                             ": writer is not open");
  }
}

void McapWriter::fail(const std::string& what) {
  const std::string message =
      path_ + ": " + what + " at offset " + std::to_string(offset_) + ": " + std::strerror(errno);
  file_.reset();  // closed and unusable; the file holds what was written so far
  throw std::runtime_error(message);
}

void McapWriter::write_bytes(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return;
  if (std::fwrite(data, 1, size, file_.get()) != size) fail("write failed");
  if (options_.crc) data_crc_ = crc32(data, size, data_crc_);
  offset_ += size;
  counters_.bytes_written = offset_;
}

void McapWriter::emit_data_record(const std::vector<std::uint8_t>& record) {
  if (options_.chunk_size_bytes == 0) {
    write_bytes(record);
  } else {
    chunk_.insert(chunk_.end(), record.begin(), record.end());
  }
}

std::uint16_t McapWriter::add_schema(std::string_view name, std::string_view encoding,
                                     std::string_view data) {
  require_open("add_schema");
  if (schemas_.size() >= 0xFFFFu) throw std::runtime_error(path_ + ": too many schemas (65535)");
  SchemaInfo s;
  s.id = static_cast<std::uint16_t>(schemas_.size() + 1);
  s.name = std::string(name);
  s.encoding = std::string(encoding);
  s.data = std::string(data);

  scratch_.clear();
  ByteSink out(scratch_);
  put_schema(out, s.id, s.name, s.encoding, s.data);
  emit_data_record(scratch_);
  schemas_.push_back(std::move(s));
  ++counters_.schemas;
  return schemas_.back().id;
}

std::uint16_t McapWriter::add_channel(std::string_view topic, std::string_view message_encoding,
                                      std::uint16_t schema_id,
                                      const std::map<std::string, std::string>& metadata) {
  require_open("add_channel");
  if (schema_id > schemas_.size()) {
    throw std::runtime_error(path_ + ": add_channel('" + std::string(topic) + "'): unknown schema id " +
                             std::to_string(schema_id));
  }
  if (channels_.size() >= 0xFFFFu) throw std::runtime_error(path_ + ": too many channels (65535)");
  ChannelInfo c;
  c.id = static_cast<std::uint16_t>(channels_.size() + 1);
  c.schema_id = schema_id;
  c.topic = std::string(topic);
  c.message_encoding = std::string(message_encoding);
  c.metadata = metadata;

  scratch_.clear();
  ByteSink out(scratch_);
  put_channel(out, c.id, c.schema_id, c.topic, c.message_encoding, c.metadata);
  emit_data_record(scratch_);
  channels_.push_back(std::move(c));
  ++counters_.channels;
  return channels_.back().id;
}

void McapWriter::write_message(std::uint16_t channel_id, std::uint32_t sequence, std::uint64_t log_time_ns,
                               std::uint64_t publish_time_ns, const std::uint8_t* data, std::size_t size) {
  require_open("write_message");
  if (channel_id == 0 || channel_id > channels_.size()) {
    throw std::runtime_error(path_ + ": write_message: unknown channel id " + std::to_string(channel_id));
  }
  const bool chunked = options_.chunk_size_bytes > 0;
  std::vector<std::uint8_t>& buf = chunked ? chunk_ : scratch_;
  if (!chunked) buf.clear();
  const std::uint64_t record_offset = buf.size();
  ByteSink out(buf);
  out.u8(detail::kOpMessage);
  out.u64(2 + 4 + 8 + 8 + static_cast<std::uint64_t>(size));
  out.u16(channel_id);
  out.u32(sequence);
  out.u64(log_time_ns);
  out.u64(publish_time_ns);
  if (size > 0) out.raw(data, size);

  if (counters_.messages == 0) {
    message_start_time_ = message_end_time_ = log_time_ns;
  } else {
    message_start_time_ = std::min(message_start_time_, log_time_ns);
    message_end_time_ = std::max(message_end_time_, log_time_ns);
  }
  ++counters_.messages;
  counters_.message_bytes += size;
  ++channel_message_counts_[channel_id];

  if (!chunked) {
    write_bytes(buf);
    return;
  }
  if (!chunk_has_messages_) {
    chunk_start_time_ = chunk_end_time_ = log_time_ns;
    chunk_has_messages_ = true;
  } else {
    chunk_start_time_ = std::min(chunk_start_time_, log_time_ns);
    chunk_end_time_ = std::max(chunk_end_time_, log_time_ns);
  }
  chunk_message_index_[channel_id].emplace_back(log_time_ns, record_offset);
  if (chunk_.size() >= options_.chunk_size_bytes) write_chunk();
}

void McapWriter::write_chunk() {
  if (chunk_.empty()) return;
  const std::string compression = mcap_compression_name(options_.compression);
  const std::uint32_t uncompressed_crc = options_.crc ? crc32(chunk_.data(), chunk_.size()) : 0;
  std::vector<std::uint8_t> compressed;
  if (options_.compression != McapCompression::kNone) {
    compressed = detail::compress_chunk(compression, chunk_, options_.compression_level);
  }
  const std::vector<std::uint8_t>& records =
      options_.compression == McapCompression::kNone ? chunk_ : compressed;

  ChunkIndexEntry index;
  index.message_start_time = chunk_has_messages_ ? chunk_start_time_ : 0;
  index.message_end_time = chunk_has_messages_ ? chunk_end_time_ : 0;
  index.chunk_start_offset = offset_;
  index.compressed_size = records.size();
  index.uncompressed_size = chunk_.size();

  scratch_.clear();
  ByteSink out(scratch_);
  out.u8(detail::kOpChunk);
  out.u64(8 + 8 + 8 + 4 + 4 + compression.size() + 8 + records.size());
  out.u64(index.message_start_time);
  out.u64(index.message_end_time);
  out.u64(chunk_.size());
  out.u32(uncompressed_crc);
  out.str(compression);
  out.u64(records.size());
  write_bytes(scratch_);
  write_bytes(records);
  index.chunk_length = offset_ - index.chunk_start_offset;

  const std::uint64_t indexes_start = offset_;
  for (const auto& [channel_id, entries] : chunk_message_index_) {
    index.message_index_offsets[channel_id] = offset_;
    scratch_.clear();
    ByteSink mi(scratch_);
    mi.u8(detail::kOpMessageIndex);
    mi.u64(2 + 4 + 16 * static_cast<std::uint64_t>(entries.size()));
    mi.u16(channel_id);
    mi.u32(static_cast<std::uint32_t>(16 * entries.size()));
    for (const auto& [log_time, record_offset] : entries) {
      mi.u64(log_time);
      mi.u64(record_offset);
    }
    write_bytes(scratch_);
  }
  index.message_index_length = offset_ - indexes_start;
  chunk_indexes_.push_back(std::move(index));
  ++counters_.chunks;

  chunk_.clear();
  chunk_message_index_.clear();
  chunk_has_messages_ = false;
  if (std::fflush(file_.get()) != 0) fail("flush failed");
  if (options_.sync_after_chunk) sync_file();
}

void McapWriter::sync_file() {
  if (::fsync(::fileno(file_.get())) != 0) fail("fsync failed");
}

void McapWriter::flush_chunk() {
  require_open("flush_chunk");
  write_chunk();
}

void McapWriter::flush() {
  require_open("flush");
  write_chunk();
  if (std::fflush(file_.get()) != 0) fail("flush failed");
  if (options_.sync_after_chunk) sync_file();
}

std::vector<std::uint8_t> McapWriter::summary_section(std::uint64_t summary_start,
                                                      std::uint64_t& summary_offset_start) const {
  std::vector<std::uint8_t> bytes;
  ByteSink out(bytes);
  struct Group {
    std::uint8_t opcode;
    std::uint64_t start;
    std::uint64_t length;
  };
  std::vector<Group> groups;
  auto close_group = [&](std::uint8_t opcode, std::size_t begin) {
    if (bytes.size() > begin) groups.push_back({opcode, summary_start + begin, bytes.size() - begin});
  };

  std::size_t begin = bytes.size();
  for (const SchemaInfo& s : schemas_) put_schema(out, s.id, s.name, s.encoding, s.data);
  close_group(detail::kOpSchema, begin);

  begin = bytes.size();
  for (const ChannelInfo& c : channels_) put_channel(out, c.id, c.schema_id, c.topic, c.message_encoding, c.metadata);
  close_group(detail::kOpChannel, begin);

  begin = bytes.size();
  {
    const std::size_t rec = out.begin_record(detail::kOpStatistics);
    out.u64(counters_.messages);
    out.u16(static_cast<std::uint16_t>(schemas_.size()));
    out.u32(static_cast<std::uint32_t>(channels_.size()));
    out.u32(0);  // attachments
    out.u32(0);  // metadata
    out.u32(static_cast<std::uint32_t>(chunk_indexes_.size()));
    out.u64(message_start_time_);
    out.u64(message_end_time_);
    put_u16_u64_map(out, channel_message_counts_);
    out.end_record(rec);
  }
  close_group(detail::kOpStatistics, begin);

  begin = bytes.size();
  const std::string compression = mcap_compression_name(options_.compression);
  for (const ChunkIndexEntry& ci : chunk_indexes_) {
    const std::size_t rec = out.begin_record(detail::kOpChunkIndex);
    out.u64(ci.message_start_time);
    out.u64(ci.message_end_time);
    out.u64(ci.chunk_start_offset);
    out.u64(ci.chunk_length);
    put_u16_u64_map(out, ci.message_index_offsets);
    out.u64(ci.message_index_length);
    out.str(compression);
    out.u64(ci.compressed_size);
    out.u64(ci.uncompressed_size);
    out.end_record(rec);
  }
  close_group(detail::kOpChunkIndex, begin);

  summary_offset_start = summary_start + bytes.size();
  for (const Group& g : groups) {
    const std::size_t rec = out.begin_record(detail::kOpSummaryOffset);
    out.u8(g.opcode);
    out.u64(g.start);
    out.u64(g.length);
    out.end_record(rec);
  }
  return bytes;
}

void McapWriter::close() {
  if (!file_) return;
  write_chunk();

  // Data End carries the CRC of every byte before it, leading magic included.
  std::vector<std::uint8_t> bytes;
  ByteSink out(bytes);
  const std::size_t rec = out.begin_record(detail::kOpDataEnd);
  out.u32(options_.crc ? data_crc_ : 0);
  out.end_record(rec);
  write_bytes(bytes);

  const std::uint64_t summary_start = offset_;
  std::uint64_t summary_offset_start = 0;
  std::vector<std::uint8_t> tail = summary_section(summary_start, summary_offset_start);
  ByteSink t(tail);
  t.u8(detail::kOpFooter);
  t.u64(detail::kFooterContentBytes);
  t.u64(summary_start);
  t.u64(summary_offset_start);
  // The summary CRC covers the summary, the summary offsets and the Footer up to here.
  t.u32(options_.crc ? crc32(tail.data(), tail.size()) : 0);
  t.raw(detail::kMagic.data(), detail::kMagic.size());
  write_bytes(tail);

  std::FILE* f = file_.release();
  const bool flushed = std::fflush(f) == 0 && (!options_.sync_after_chunk || ::fsync(::fileno(f)) == 0);
  const int flush_errno = errno;
  const bool closed = std::fclose(f) == 0;
  if (!flushed || !closed) {
    errno = flushed ? errno : flush_errno;
    throw std::runtime_error(path_ + ": closing failed: " + std::strerror(errno));
  }
}

}  // namespace pixyslam::mcap
