#include "pixyslam/logger/mcap_reader.h"

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <utility>

#include "mcap_format.h"
#include "pixyslam/logger/crc32.h"

namespace pixyslam::logger {

using namespace detail;

const char* detail::opcode_name(std::uint8_t op) {
  switch (op) {
    case kOpHeader: return "Header";
    case kOpFooter: return "Footer";
    case kOpSchema: return "Schema";
    case kOpChannel: return "Channel";
    case kOpMessage: return "Message";
    case kOpChunk: return "Chunk";
    case kOpMessageIndex: return "Message Index";
    case kOpChunkIndex: return "Chunk Index";
    case kOpAttachment: return "Attachment";
    case kOpAttachmentIndex: return "Attachment Index";
    case kOpStatistics: return "Statistics";
    case kOpMetadata: return "Metadata";
    case kOpMetadataIndex: return "Metadata Index";
    case kOpSummaryOffset: return "Summary Offset";
    case kOpDataEnd: return "Data End";
    default: return "unknown";
  }
}

namespace {

// Larger chunks are rejected rather than allocated (a corrupt size field).
constexpr std::uint64_t kMaxChunkUncompressedBytes = std::uint64_t{1} << 30;
constexpr std::size_t kMaxDiagnostics = 1000;
// Footer bytes covered by the summary CRC: opcode, length, summary_start, summary_offset_start.
constexpr std::uint64_t kFooterCrcBytes = kRecordPrefixBytes + 16;

std::uint64_t le64(const std::uint8_t* p) {
  std::uint64_t v = 0;
  for (int i = 0; i < 8; ++i) v |= static_cast<std::uint64_t>(p[i]) << (8 * i);
  return v;
}

std::string hex32(std::uint32_t v) {
  static constexpr char kHex[] = "0123456789abcdef";
  std::string s = "0x";
  for (int shift = 28; shift >= 0; shift -= 4) s += kHex[(v >> shift) & 0xFu];
  return s;
}

std::string op_text(std::uint8_t op) {
  std::string s = opcode_name(op);
  s += " (0x";
  static constexpr char kHex[] = "0123456789abcdef";
  s += kHex[op >> 4];
  s += kHex[op & 0xFu];
  s += ")";
  return s;
}

// A failure inside a record that makes the record (or chunk) unusable.
struct RecordError {
  std::string message;
};

// The content of a uint32 byte-length prefixed Map or Array field. With
// `entry_bytes` > 0 its length must be a multiple of that (else RecordError
// "<what> of N bytes").
ByteSource take_prefixed(ByteSource& s, std::size_t entry_bytes = 0, const char* what = "") {
  const std::uint32_t bytes = s.u32();
  if (entry_bytes > 0 && bytes % entry_bytes != 0) {
    throw RecordError{std::string(what) + " of " + std::to_string(bytes) + " bytes"};
  }
  return ByteSource(s.take(bytes), bytes);
}

McapSchema parse_schema(ByteSource& s) {
  McapSchema schema;
  schema.id = s.u16();
  schema.name = s.str();
  schema.encoding = s.str();
  schema.data = s.str();
  return schema;
}

std::map<std::string, std::string> parse_string_map(ByteSource& s) {
  ByteSource m = take_prefixed(s);
  std::map<std::string, std::string> out;
  while (m.remaining() > 0) {
    std::string key = m.str();
    out[std::move(key)] = m.str();
  }
  return out;
}

McapChannel parse_channel(ByteSource& s) {
  McapChannel channel;
  channel.id = s.u16();
  channel.schema_id = s.u16();
  channel.topic = s.str();
  channel.message_encoding = s.str();
  channel.metadata = parse_string_map(s);
  return channel;
}

McapMessage parse_message(ByteSource& s) {
  McapMessage m;
  m.channel_id = s.u16();
  m.sequence = s.u32();
  m.log_time_ns = s.u64();
  m.publish_time_ns = s.u64();
  const std::size_t n = s.remaining();
  const std::uint8_t* p = s.take(n);
  m.data.assign(p, p + n);
  return m;
}

std::map<std::uint16_t, std::uint64_t> parse_u16_u64_map(ByteSource& s) {
  ByteSource m = take_prefixed(s, 10, "Map<uint16, uint64>");
  std::map<std::uint16_t, std::uint64_t> out;
  while (m.remaining() > 0) {
    const std::uint16_t key = m.u16();
    out[key] = m.u64();
  }
  return out;
}

bool same(const McapSchema& a, const McapSchema& b) {
  return a.id == b.id && a.name == b.name && a.encoding == b.encoding && a.data == b.data;
}

bool same(const McapChannel& a, const McapChannel& b) {
  return a.id == b.id && a.schema_id == b.schema_id && a.topic == b.topic &&
         a.message_encoding == b.message_encoding && a.metadata == b.metadata;
}

}  // namespace

// The front-to-back parse; fills the reader's fields.
class McapReader::Parser {
 public:
  Parser(McapReader& reader, const std::vector<std::uint8_t>& bytes)
      : r_(reader), data_(bytes.data()), size_(bytes.size()) {}

  void run() {
    r_.recovery_.file_size = size_;
    std::uint64_t pos = kMagic.size();
    std::uint64_t valid_end = pos;
    bool footer_seen = false;
    while (pos < size_) {
      const std::uint64_t remaining = size_ - pos;
      if (remaining < kRecordPrefixBytes) {
        diag(pos, std::to_string(remaining) + " bytes at the end, too few for a record: file cut short");
        break;
      }
      const std::uint8_t op = data_[pos];
      const std::uint64_t len = le64(data_ + pos + 1);
      if (op == 0) {
        diag(pos, "opcode 0x00 is not a record (zeroed or corrupt data); the rest of the file is ignored");
        break;
      }
      if (len > remaining - kRecordPrefixBytes) {
        diag(pos, op_text(op) + " record of " + std::to_string(len) + " content bytes, but only " +
                      std::to_string(remaining - kRecordPrefixBytes) + " remain: file cut short");
        break;
      }
      if (pos == kMagic.size() && op != kOpHeader)
        diag(pos, "first record is " + op_text(op) + ", not Header");
      if (op != kOpMessageIndex) finish_pending_chunk();
      handle(op, pos, data_ + pos + kRecordPrefixBytes, static_cast<std::size_t>(len));
      pos += kRecordPrefixBytes + len;
      valid_end = pos;
      if (op == kOpFooter) {
        footer_seen = true;
        if (size_ - pos >= kMagic.size() && std::equal(kMagic.begin(), kMagic.end(), data_ + pos)) {
          r_.recovery_.footer_present = true;
          valid_end = pos + kMagic.size();
          if (size_ > valid_end) {
            diag(valid_end, std::to_string(size_ - valid_end) + " bytes after the closing magic");
          }
        } else {
          diag(pos, "Footer not followed by the closing magic");
        }
        break;
      }
    }
    finish_pending_chunk();
    if (!footer_seen) {
      diag(valid_end, "no Footer: the file was cut short or its writer did not close it (" +
                          std::to_string(size_ - valid_end) +
                          " bytes after the last complete record ignored)");
    }
    r_.recovery_.valid_bytes = valid_end;
    r_.recovery_.bytes_ignored_at_end = size_ - valid_end;
    r_.recovery_.messages_recovered = r_.messages_.size();
    final_checks(footer_seen);
    if (suppressed_ > 0) {
      r_.diagnostics_.push_back({valid_end, std::to_string(suppressed_) + " further diagnostics suppressed"});
    }
  }

 private:
  // Extra per-chunk facts for checking the Message Index and Chunk Index records.
  struct ChunkCheck {
    std::uint64_t end = 0;                // file offset after the chunk record
    std::uint64_t message_index_end = 0;  // file offset after its Message Index records
    std::map<std::uint64_t, std::pair<std::uint16_t, std::uint64_t>> messages;  // offset -> channel, log time
    std::uint64_t indexed = 0;
    bool any_index = false;
  };
  struct SummaryRecord {
    std::uint8_t op;
    std::uint64_t length;
  };
  struct Footer {
    std::uint64_t offset = 0;
    std::uint64_t summary_start = 0;
    std::uint64_t summary_offset_start = 0;
    std::uint32_t summary_crc = 0;
  };
  struct SummaryOffset {
    std::uint64_t offset;
    std::uint8_t op;
    std::uint64_t start;
    std::uint64_t length;
  };

  void diag(std::uint64_t offset, std::string message) {
    if (r_.diagnostics_.size() >= kMaxDiagnostics) {
      ++suppressed_;
      return;
    }
    r_.diagnostics_.push_back({offset, std::move(message)});
  }

  void handle(std::uint8_t op, std::uint64_t pos, const std::uint8_t* content, std::size_t len) {
    ByteSource s(content, len);
    if (in_summary_ && op != kOpFooter) {
      summary_records_[pos] = {op, kRecordPrefixBytes + len};
      if (op == kOpSummaryOffset) {
        if (first_summary_offset_ == 0) first_summary_offset_ = pos;
      } else if (first_summary_record_ == 0) {
        first_summary_record_ = pos;
      }
    }
    try {
      switch (op) {
        case kOpHeader:
          if (pos != kMagic.size()) {
            diag(pos, "Header record after the start of the file (ignored)");
            break;
          }
          r_.profile_ = s.str();
          r_.library_ = s.str();
          r_.recovery_.header_present = true;
          break;
        case kOpSchema: add_schema(parse_schema(s), pos); break;
        case kOpChannel: add_channel(parse_channel(s), pos); break;
        case kOpMessage: {
          if (in_summary_) {
            diag(pos, "Message record in the summary section (ignored)");
            break;
          }
          McapMessage m = parse_message(s);
          first_use_of_channel_.emplace(m.channel_id, pos);
          r_.messages_.push_back(std::move(m));
          break;
        }
        case kOpChunk: read_chunk(s, pos, len); break;
        case kOpMessageIndex: check_message_index(s, pos, len); break;
        case kOpChunkIndex: check_chunk_index(s, pos); break;
        case kOpAttachment: ++attachments_; break;
        case kOpMetadata: ++metadata_; break;
        case kOpStatistics: read_statistics(s, pos); break;
        case kOpSummaryOffset: {
          SummaryOffset so{pos, 0, 0, 0};
          so.op = s.u8();
          so.start = s.u64();
          so.length = s.u64();
          summary_offsets_.push_back(so);
          break;
        }
        case kOpDataEnd: {
          const std::uint32_t stored = s.u32();
          if (r_.recovery_.data_end_present) {
            diag(pos, "second Data End record");
            break;
          }
          r_.recovery_.data_end_present = true;
          in_summary_ = true;
          if (stored != 0) {
            const std::uint32_t computed = crc32(data_, static_cast<std::size_t>(pos));
            if (computed != stored) {
              diag(pos, "data section CRC mismatch: Data End says " + hex32(stored) + ", bytes give " +
                            hex32(computed));
            }
          }
          break;
        }
        case kOpFooter: {
          footer_.offset = pos;
          footer_.summary_start = s.u64();
          footer_.summary_offset_start = s.u64();
          footer_.summary_crc = s.u32();
          break;
        }
        default: break;  // Attachment/Metadata Index, future and application records
      }
      if (op == kOpFooter && len != kFooterContentBytes) {
        diag(pos, "Footer of " + std::to_string(len) + " content bytes, expected 20");
      }
    } catch (const FieldOverrun& e) {
      diag(pos, "malformed " + op_text(op) + " record: a field of " + std::to_string(e.wanted) +
                    " bytes at content offset " + std::to_string(e.at) + " runs past its " +
                    std::to_string(len) + " bytes (record skipped)");
    } catch (const RecordError& e) {
      diag(pos, "malformed " + op_text(op) + " record: " + e.message + " (record skipped)");
    }
  }

  void add_schema(McapSchema schema, std::uint64_t pos) {
    if (schema.id == 0) {
      diag(pos, "Schema record with id 0 (invalid, ignored)");
      return;
    }
    for (const McapSchema& s : r_.schemas_) {
      if (s.id == schema.id) {
        if (!same(s, schema)) diag(pos, "Schema id " + std::to_string(schema.id) + " redefined differently");
        return;
      }
    }
    r_.schemas_.push_back(std::move(schema));
  }

  void add_channel(McapChannel channel, std::uint64_t pos) {
    for (const McapChannel& c : r_.channels_) {
      if (c.id == channel.id) {
        if (!same(c, channel))
          diag(pos, "Channel id " + std::to_string(channel.id) + " redefined differently");
        return;
      }
    }
    r_.channels_.push_back(std::move(channel));
  }

  void read_chunk(ByteSource& s, std::uint64_t pos, std::size_t len) {
    McapChunkInfo info;
    info.offset = pos;
    info.length = kRecordPrefixBytes + len;
    pending_ = ChunkCheck{};
    pending_.end = pos + info.length;
    pending_.message_index_end = pending_.end;
    pending_valid_ = false;
    have_pending_ = true;

    std::string problem;
    std::uint32_t stored_crc = 0;
    const std::uint8_t* records = nullptr;
    try {
      info.message_start_time_ns = s.u64();
      info.message_end_time_ns = s.u64();
      info.uncompressed_size = s.u64();
      stored_crc = s.u32();
      info.compression = s.str();
      info.compressed_size = s.u64();
      if (info.compressed_size > s.remaining()) {
        problem = "records field of " + std::to_string(info.compressed_size) + " bytes, only " +
                  std::to_string(s.remaining()) + " in the record";
      } else {
        records = s.take(static_cast<std::size_t>(info.compressed_size));
      }
    } catch (const FieldOverrun&) {
      problem = "malformed Chunk record header";
    }

    std::vector<std::uint8_t> decoded;
    const std::uint8_t* plain = records;
    if (problem.empty()) problem = decode_chunk(info, records, decoded, plain);
    const auto plain_size = static_cast<std::size_t>(info.uncompressed_size);
    if (problem.empty() && stored_crc != 0) {
      const std::uint32_t computed = crc32(plain, plain_size);
      if (computed != stored_crc) {
        problem = "CRC mismatch: chunk says " + hex32(stored_crc) + ", records give " + hex32(computed);
      }
    }
    std::vector<McapSchema> schemas;
    std::vector<McapChannel> channels;
    std::vector<McapMessage> messages;
    if (problem.empty()) problem = parse_chunk_records(plain, plain_size, schemas, channels, messages);

    if (!problem.empty()) {
      ++r_.recovery_.rejected_chunks;
      diag(pos, "Chunk rejected, its records are skipped: " + problem);
      r_.chunks_.push_back(std::move(info));
      return;
    }
    for (McapSchema& sc : schemas) add_schema(std::move(sc), pos);
    for (McapChannel& ch : channels) add_channel(std::move(ch), pos);
    bool out_of_range = false;
    for (McapMessage& m : messages) {
      first_use_of_channel_.emplace(m.channel_id, pos);
      out_of_range = out_of_range || m.log_time_ns < info.message_start_time_ns ||
                     m.log_time_ns > info.message_end_time_ns;
      r_.messages_.push_back(std::move(m));
    }
    if (out_of_range) diag(pos, "Chunk holds messages outside its message_start_time..message_end_time");
    info.message_count = messages.size();
    info.valid = true;
    pending_valid_ = true;
    ++r_.recovery_.complete_chunks;
    chunk_at_[pos] = r_.chunks_.size();
    r_.chunks_.push_back(std::move(info));
  }

  // Points `plain` at the uncompressed records (into the file or into `decoded`);
  // returns "" or what is wrong.
  static std::string decode_chunk(const McapChunkInfo& info, const std::uint8_t* records,
                                  std::vector<std::uint8_t>& decoded, const std::uint8_t*& plain) {
    if (info.uncompressed_size > kMaxChunkUncompressedBytes) {
      return "uncompressed_size " + std::to_string(info.uncompressed_size) + " is implausibly large";
    }
    if (info.compression.empty()) {
      if (info.uncompressed_size == info.compressed_size) return "";
      return "uncompressed chunk of " + std::to_string(info.compressed_size) +
             " bytes, uncompressed_size says " + std::to_string(info.uncompressed_size);
    }
    try {
      decoded = decompress_chunk(info.compression, records, static_cast<std::size_t>(info.compressed_size),
                                 info.uncompressed_size);
      plain = decoded.data();
      return "";
    } catch (const std::exception& e) {
      return std::string("cannot decompress: ") + e.what();
    }
  }

  // Parses the records inside a chunk; returns "" or what is wrong (the chunk is then rejected whole).
  std::string parse_chunk_records(const std::uint8_t* p, std::size_t n, std::vector<McapSchema>& schemas,
                                  std::vector<McapChannel>& channels, std::vector<McapMessage>& messages) {
    std::size_t pos = 0;
    while (pos < n) {
      if (n - pos < kRecordPrefixBytes)
        return "inner record at chunk offset " + std::to_string(pos) + " cut short";
      const std::uint8_t op = p[pos];
      const std::uint64_t len = le64(p + pos + 1);
      if (len > n - pos - kRecordPrefixBytes) {
        return "inner " + op_text(op) + " record at chunk offset " + std::to_string(pos) +
               " overruns the chunk";
      }
      ByteSource s(p + pos + kRecordPrefixBytes, static_cast<std::size_t>(len));
      try {
        switch (op) {
          case kOpSchema: schemas.push_back(parse_schema(s)); break;
          case kOpChannel: channels.push_back(parse_channel(s)); break;
          case kOpMessage: {
            McapMessage m = parse_message(s);
            pending_.messages[pos] = {m.channel_id, m.log_time_ns};
            messages.push_back(std::move(m));
            break;
          }
          default:
            if (op == 0 || op == kOpHeader || op == kOpFooter || op == kOpChunk || op == kOpDataEnd) {
              return op_text(op) + " record inside a chunk at chunk offset " + std::to_string(pos);
            }
            break;  // other records are not expected here but harmless
        }
      } catch (const FieldOverrun&) {
        return "malformed inner " + op_text(op) + " record at chunk offset " + std::to_string(pos);
      } catch (const RecordError& e) {
        return "malformed inner " + op_text(op) + " record at chunk offset " + std::to_string(pos) + ": " +
               e.message;
      }
      pos += kRecordPrefixBytes + static_cast<std::size_t>(len);
    }
    return "";
  }

  void check_message_index(ByteSource& s, std::uint64_t pos, std::size_t len) {
    const std::uint16_t channel_id = s.u16();
    ByteSource entries = take_prefixed(s, 16, "records array");
    message_index_at_[pos] = channel_id;
    if (!have_pending_) {
      diag(pos, "Message Index record not after a Chunk");
      return;
    }
    pending_.any_index = true;
    pending_.message_index_end = pos + kRecordPrefixBytes + len;
    if (!pending_valid_) return;
    while (entries.remaining() > 0) {
      const std::uint64_t log_time = entries.u64();
      const std::uint64_t offset = entries.u64();
      const auto it = pending_.messages.find(offset);
      if (it == pending_.messages.end() || it->second.first != channel_id || it->second.second != log_time) {
        diag(pos, "Message Index entry (log_time " + std::to_string(log_time) + ", offset " +
                      std::to_string(offset) + ") of channel " + std::to_string(channel_id) +
                      " matches no message of the chunk");
      } else {
        ++pending_.indexed;
      }
    }
  }

  // Called when the records after a chunk stop being Message Index records.
  void finish_pending_chunk() {
    if (!have_pending_) return;
    have_pending_ = false;
    if (pending_valid_) {
      const std::uint64_t chunk_offset = r_.chunks_.back().offset;
      if (pending_.any_index && pending_.indexed != pending_.messages.size()) {
        diag(chunk_offset, "Message Index records cover " + std::to_string(pending_.indexed) +
                               " of the chunk's " + std::to_string(pending_.messages.size()) + " messages");
      }
      chunk_message_index_end_[chunk_offset] = pending_.message_index_end;
    }
    pending_ = ChunkCheck{};
  }

  void check_chunk_index(ByteSource& s, std::uint64_t pos) {
    if (!in_summary_) diag(pos, "Chunk Index record in the data section");
    const std::uint64_t start_time = s.u64();
    const std::uint64_t end_time = s.u64();
    const std::uint64_t chunk_offset = s.u64();
    const std::uint64_t chunk_length = s.u64();
    const std::map<std::uint16_t, std::uint64_t> index_offsets = parse_u16_u64_map(s);
    const std::uint64_t index_length = s.u64();
    const std::string compression = s.str();
    const std::uint64_t compressed_size = s.u64();
    const std::uint64_t uncompressed_size = s.u64();
    ++chunk_indexes_;
    const auto it = chunk_at_.find(chunk_offset);
    if (it == chunk_at_.end()) {
      diag(pos, "Chunk Index points at offset " + std::to_string(chunk_offset) + ", where no valid Chunk is");
      return;
    }
    const McapChunkInfo& c = r_.chunks_[it->second];
    if (c.length != chunk_length || c.compression != compression || c.compressed_size != compressed_size ||
        c.uncompressed_size != uncompressed_size || c.message_start_time_ns != start_time ||
        c.message_end_time_ns != end_time) {
      diag(pos, "Chunk Index disagrees with the Chunk at offset " + std::to_string(chunk_offset));
    }
    for (const auto& [channel_id, offset] : index_offsets) {
      const auto mi = message_index_at_.find(offset);
      if (mi == message_index_at_.end() || mi->second != channel_id) {
        diag(pos, "Chunk Index: no Message Index of channel " + std::to_string(channel_id) + " at offset " +
                      std::to_string(offset));
      }
    }
    const auto end = chunk_message_index_end_.find(chunk_offset);
    const std::uint64_t actual =
        end == chunk_message_index_end_.end() ? 0 : end->second - (c.offset + c.length);
    if (actual != index_length) {
      diag(pos, "Chunk Index: message_index_length " + std::to_string(index_length) + ", the file has " +
                    std::to_string(actual));
    }
  }

  void read_statistics(ByteSource& s, std::uint64_t pos) {
    if (r_.statistics_) {
      diag(pos, "second Statistics record (ignored)");
      return;
    }
    McapStatistics st;
    st.message_count = s.u64();
    st.schema_count = s.u16();
    st.channel_count = s.u32();
    st.attachment_count = s.u32();
    st.metadata_count = s.u32();
    st.chunk_count = s.u32();
    st.message_start_time_ns = s.u64();
    st.message_end_time_ns = s.u64();
    st.channel_message_counts = parse_u16_u64_map(s);
    r_.statistics_ = std::move(st);
    statistics_offset_ = pos;
  }

  void final_checks(bool footer_seen) {
    for (const auto& [channel_id, pos] : first_use_of_channel_) {
      if (r_.find_channel(channel_id) == nullptr) {
        diag(pos, "messages on channel " + std::to_string(channel_id) + ", which no Channel record defines");
      }
    }
    for (const McapChannel& c : r_.channels_) {
      if (c.schema_id != 0 && r_.find_schema(c.schema_id) == nullptr) {
        diag(0, "Channel " + std::to_string(c.id) + " uses schema " + std::to_string(c.schema_id) +
                    ", which no Schema record defines");
      }
    }
    if (!footer_seen) return;
    check_footer();
    check_summary_offsets();
    if (r_.statistics_) check_statistics(*r_.statistics_);
    if (chunk_indexes_ > 0 && chunk_indexes_ != r_.chunks_.size()) {
      diag(footer_.offset, std::to_string(chunk_indexes_) + " Chunk Index records for " +
                               std::to_string(r_.chunks_.size()) + " chunks");
    }
  }

  void check_footer() {
    r_.recovery_.summary_present = first_summary_record_ != 0 || first_summary_offset_ != 0;
    if (footer_.summary_start != first_summary_record_) {
      diag(footer_.offset, "Footer summary_start " + std::to_string(footer_.summary_start) +
                               ", first summary record at " + std::to_string(first_summary_record_));
    }
    if (footer_.summary_offset_start != first_summary_offset_) {
      diag(footer_.offset, "Footer summary_offset_start " + std::to_string(footer_.summary_offset_start) +
                               ", first Summary Offset record at " + std::to_string(first_summary_offset_));
    }
    if (footer_.summary_crc == 0) return;
    std::uint64_t start = footer_.summary_start != 0          ? footer_.summary_start
                          : footer_.summary_offset_start != 0 ? footer_.summary_offset_start
                                                              : footer_.offset;
    if (start > footer_.offset) {
      diag(footer_.offset, "Footer summary_start points past the Footer");
      return;
    }
    const std::uint32_t computed =
        crc32(data_ + start, static_cast<std::size_t>(footer_.offset + kFooterCrcBytes - start));
    if (computed != footer_.summary_crc) {
      diag(footer_.offset, "summary CRC mismatch: Footer says " + hex32(footer_.summary_crc) +
                               ", bytes give " + hex32(computed));
    }
  }

  void check_summary_offsets() {
    for (const SummaryOffset& so : summary_offsets_) {
      std::uint64_t at = so.start;
      const std::uint64_t end = so.start + so.length;
      bool ok = so.length > 0;
      while (ok && at < end) {
        const auto it = summary_records_.find(at);
        ok = it != summary_records_.end() && it->second.op == so.op;
        if (ok) at += it->second.length;
      }
      if (!ok || at != end) {
        diag(so.offset, "Summary Offset group " + op_text(so.op) + " [" + std::to_string(so.start) + ", +" +
                            std::to_string(so.length) + ") does not span whole records of that opcode");
      }
    }
  }

  void check_statistics(const McapStatistics& st) {
    const std::uint64_t at = statistics_offset_;
    auto expect = [&](const char* what, std::uint64_t stated, std::uint64_t found) {
      if (stated != found) {
        diag(at, std::string("Statistics ") + what + " " + std::to_string(stated) + ", the file has " +
                     std::to_string(found));
      }
    };
    expect("message_count", st.message_count, r_.messages_.size());
    expect("schema_count", st.schema_count, r_.schemas_.size());
    expect("channel_count", st.channel_count, r_.channels_.size());
    expect("attachment_count", st.attachment_count, attachments_);
    expect("metadata_count", st.metadata_count, metadata_);
    expect("chunk_count", st.chunk_count, r_.chunks_.size());
    std::map<std::uint16_t, std::uint64_t> counts;
    std::uint64_t first = 0;
    std::uint64_t last = 0;
    for (const McapMessage& m : r_.messages_) {
      if (counts.empty()) first = last = m.log_time_ns;
      first = std::min(first, m.log_time_ns);
      last = std::max(last, m.log_time_ns);
      ++counts[m.channel_id];
    }
    if (!st.channel_message_counts.empty() && st.channel_message_counts != counts) {
      diag(at, "Statistics channel_message_counts disagree with the messages read");
    }
    expect("message_start_time", st.message_start_time_ns, first);
    expect("message_end_time", st.message_end_time_ns, last);
  }

  McapReader& r_;
  const std::uint8_t* data_;
  std::size_t size_;
  std::size_t suppressed_ = 0;
  bool in_summary_ = false;
  std::uint64_t attachments_ = 0;
  std::uint64_t metadata_ = 0;
  std::uint64_t chunk_indexes_ = 0;
  std::uint64_t statistics_offset_ = 0;

  ChunkCheck pending_;
  bool have_pending_ = false;
  bool pending_valid_ = false;
  std::map<std::uint64_t, std::size_t> chunk_at_;                   // chunk offset -> index in chunks_
  std::map<std::uint64_t, std::uint64_t> chunk_message_index_end_;  // chunk offset -> end of its indexes
  std::map<std::uint64_t, std::uint16_t> message_index_at_;         // record offset -> channel
  std::map<std::uint16_t, std::uint64_t> first_use_of_channel_;     // channel -> offset of first use

  std::map<std::uint64_t, SummaryRecord> summary_records_;
  std::uint64_t first_summary_record_ = 0;
  std::uint64_t first_summary_offset_ = 0;
  std::vector<SummaryOffset> summary_offsets_;
  Footer footer_;
};

namespace {

std::vector<std::uint8_t> read_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary | std::ios::ate);
  if (!in) throw std::runtime_error(path + ": cannot open for reading: " + std::strerror(errno));
  const std::streamoff size = in.tellg();
  if (size < 0) throw std::runtime_error(path + ": cannot determine the file size");
  std::vector<std::uint8_t> bytes(static_cast<std::size_t>(size));
  in.seekg(0);
  if (size > 0 && !in.read(reinterpret_cast<char*>(bytes.data()), size)) {
    throw std::runtime_error(path + ": read failed");
  }
  return bytes;
}

}  // namespace

McapReader::McapReader(const std::string& path) : McapReader(read_file(path), path) {}

McapReader::McapReader(std::vector<std::uint8_t> bytes, const std::string& name) : path_(name) {
  if (bytes.empty()) throw std::runtime_error(name + ": empty file, not an MCAP file");
  if (bytes.size() < kMagic.size()) {
    throw std::runtime_error(name + ": " + std::to_string(bytes.size()) +
                             " bytes, shorter than the MCAP magic: not an MCAP file");
  }
  if (!std::equal(kMagic.begin(), kMagic.end(), bytes.begin())) {
    throw std::runtime_error(name + ": not an MCAP file (bad magic)");
  }
  Parser(*this, bytes).run();
}

const McapSchema* McapReader::find_schema(std::uint16_t id) const {
  for (const McapSchema& s : schemas_) {
    if (s.id == id) return &s;
  }
  return nullptr;
}

const McapChannel* McapReader::find_channel(std::uint16_t id) const {
  for (const McapChannel& c : channels_) {
    if (c.id == id) return &c;
  }
  return nullptr;
}

const McapChannel* McapReader::find_channel(const std::string& topic) const {
  for (const McapChannel& c : channels_) {
    if (c.topic == topic) return &c;
  }
  return nullptr;
}

std::string McapReader::diagnostics_text() const {
  std::ostringstream out;
  for (const McapDiagnostic& d : diagnostics_) out << "offset " << d.offset << ": " << d.message << "\n";
  return out.str();
}

}  // namespace pixyslam::logger
