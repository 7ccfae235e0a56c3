#include "pixyslam/mcap/mcap_reader.h"

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <fstream>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <utility>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include "mcap_format.h"
#include "pixyslam/mcap/crc32.h"

namespace pixyslam::mcap {

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

const char* mcap_file_state_name(McapFileState state) {
  switch (state) {
    case McapFileState::kComplete: return "complete";
    case McapFileState::kNotClosed: return "not closed";
    case McapFileState::kDamaged: return "damaged";
  }
  return "damaged";
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

// The records of a Chunk, decoded without touching the reader: used to read a
// chunk and to check a candidate record while resynchronising.
struct ChunkContent {
  McapChunkInfo info;
  std::string problem;  // "" = CRC, decompression and inner records fine
  std::vector<McapSchema> schemas;
  std::vector<McapChannel> channels;
  std::vector<McapMessage> messages;
  std::vector<std::uint64_t> message_offsets;  // of each message, within the uncompressed records
};

// Points `plain` at the uncompressed records (into the file or into `decoded`);
// returns "" or what is wrong.
std::string decode_chunk(const McapChunkInfo& info, const std::uint8_t* records, std::vector<std::uint8_t>& decoded,
                         const std::uint8_t*& plain) {
  if (info.uncompressed_size > kMaxChunkUncompressedBytes) {
    return "uncompressed_size " + std::to_string(info.uncompressed_size) + " is implausibly large";
  }
  if (info.compression.empty()) {
    if (info.uncompressed_size == info.compressed_size) return "";
    return "uncompressed chunk of " + std::to_string(info.compressed_size) + " bytes, uncompressed_size says " +
           std::to_string(info.uncompressed_size);
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

// Parses the records inside a chunk into `out` (only checks them unless `keep`);
// returns "" or what is wrong (the chunk is then rejected whole).
std::string parse_chunk_records(const std::uint8_t* p, std::size_t n, ChunkContent& out, bool keep) {
  std::size_t pos = 0;
  while (pos < n) {
    if (n - pos < kRecordPrefixBytes) return "inner record at chunk offset " + std::to_string(pos) + " cut short";
    const std::uint8_t op = p[pos];
    const std::uint64_t len = le64(p + pos + 1);
    if (len > n - pos - kRecordPrefixBytes) {
      return "inner " + op_text(op) + " record at chunk offset " + std::to_string(pos) + " overruns the chunk";
    }
    ByteSource s(p + pos + kRecordPrefixBytes, static_cast<std::size_t>(len));
    try {
      switch (op) {
        case kOpSchema: {
          McapSchema schema = parse_schema(s);
          if (keep) out.schemas.push_back(std::move(schema));
          break;
        }
        case kOpChannel: {
          McapChannel channel = parse_channel(s);
          if (keep) out.channels.push_back(std::move(channel));
          break;
        }
        case kOpMessage: {
          if (len < 22) throw FieldOverrun{0, 22};
          if (keep) {
            out.message_offsets.push_back(pos);
            out.messages.push_back(parse_message(s));
          }
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
      return "malformed inner " + op_text(op) + " record at chunk offset " + std::to_string(pos) + ": " + e.message;
    }
    pos += kRecordPrefixBytes + static_cast<std::size_t>(len);
  }
  return "";
}

// Decodes the content (`len` bytes after the record prefix) of a Chunk record.
void decode_chunk_content(const std::uint8_t* content, std::size_t len, ChunkContent& out, bool keep) {
  ByteSource s(content, len);
  std::uint32_t stored_crc = 0;
  const std::uint8_t* records = nullptr;
  McapChunkInfo& info = out.info;
  try {
    info.message_start_time_ns = s.u64();
    info.message_end_time_ns = s.u64();
    info.uncompressed_size = s.u64();
    stored_crc = s.u32();
    info.compression = s.str();
    info.compressed_size = s.u64();
    if (info.compressed_size > s.remaining()) {
      out.problem = "records field of " + std::to_string(info.compressed_size) + " bytes, only " +
                    std::to_string(s.remaining()) + " in the record";
      return;
    }
    records = s.take(static_cast<std::size_t>(info.compressed_size));
  } catch (const FieldOverrun&) {
    out.problem = "malformed Chunk record header";
    return;
  }
  std::vector<std::uint8_t> decoded;
  const std::uint8_t* plain = records;
  out.problem = decode_chunk(info, records, decoded, plain);
  if (!out.problem.empty()) return;
  const auto plain_size = static_cast<std::size_t>(info.uncompressed_size);
  if (stored_crc != 0) {
    const std::uint32_t computed = crc32(plain, plain_size);
    if (computed != stored_crc) {
      out.problem = "CRC mismatch: chunk says " + hex32(stored_crc) + ", records give " + hex32(computed);
      return;
    }
  }
  out.problem = parse_chunk_records(plain, plain_size, out, keep);
}

void skip_string(ByteSource& s) { s.take(s.u32()); }

void skip_string_map(ByteSource& s) {
  ByteSource m = take_prefixed(s);
  while (m.remaining() > 0) {
    skip_string(m);
    skip_string(m);
  }
}

bool known_opcode(std::uint8_t op) { return op >= kOpHeader && op <= kOpDataEnd; }

}  // namespace

// The parse; fills the reader's fields. Front to back, with the chunk index
// (when the summary is intact) and a scan for the next valid record to get
// past damage.
class McapReader::Parser {
 public:
  Parser(McapReader& reader, const std::vector<std::uint8_t>& bytes)
      : r_(reader), data_(bytes.data()), size_(bytes.size()) {}

  void run() {
    r_.recovery_.file_size = size_;
    verify_budget_ = 8 * static_cast<std::uint64_t>(size_) + (std::uint64_t{64} << 20);
    locate_footer();
    std::uint64_t pos = kMagic.size();
    while (pos < size_) {
      if (summary_ok_ && !in_summary_ && pos >= summary_start_) in_summary_ = true;
      if (index_used_) {
        const auto known = anchors_.find(pos);
        if (known != anchors_.end() && known->second.op == kOpChunk) {
          pos = read_indexed_chunk(pos, known->second.length);
          continue;
        }
        if (const std::string inside = inside_indexed_chunk(pos); !inside.empty()) {
          pos = resync(pos, pos + 1, inside);
          continue;
        }
      }
      const std::uint64_t remaining = size_ - pos;
      if (remaining < kRecordPrefixBytes) {
        pos = resync(pos, pos + 1, std::to_string(remaining) + " bytes, too few for a record");
        continue;
      }
      const std::uint8_t op = data_[pos];
      const std::uint64_t len = le64(data_ + pos + 1);
      if (op == 0) {
        pos = resync(pos, pos + 1, "opcode 0x00 is not a record (zeroed or corrupt data)");
        continue;
      }
      if (closing_magic_ && footer_at_ == 0 && pos == size_ - kMagic.size()) {
        diag(pos, "the file ends with the closing magic, but no valid Footer precedes it");
        note_damage(pos, size_, "closing magic without a Footer");
        break;
      }
      if (op == kOpChunk) {
        const std::optional<std::uint64_t> pos_after = chunk_with_bad_length(pos, len);
        if (pos_after) {
          pos = *pos_after;
          if (pos == size_ + 1) break;  // a chunk cut by the end of the file
          continue;
        }
      }
      if (len > remaining - kRecordPrefixBytes) {
        pos = resync(pos, pos + 1,
                     op_text(op) + " record of " + std::to_string(len) + " content bytes, but only " +
                         std::to_string(remaining - kRecordPrefixBytes) + " remain");
        continue;
      }
      const std::uint64_t end = pos + kRecordPrefixBytes + len;
      if (const std::uint64_t anchor = next_anchor_after(pos); anchor < end) {
        pos = resync(pos, pos + 1,
                     op_text(op) + " record of " + std::to_string(len) + " content bytes runs across offset " +
                         std::to_string(anchor) + ", where " + anchor_text(anchor));
        continue;
      }
      if (op != kOpFooter && op != kOpDataEnd && op != kOpChunk) {
        if (const std::optional<std::uint64_t> next = bad_length(pos, op, end)) {
          pos = *next;
          continue;
        }
      }
      if (pos == kMagic.size() && op != kOpHeader) diag(pos, "first record is " + op_text(op) + ", not Header");
      if (op != kOpMessageIndex) finish_pending_chunk(true);
      if (op == kOpFooter) {
        const FooterEnd how = footer_end(pos);
        if (how != FooterEnd::kNotTheFooter) {
          handle(op, pos, data_ + pos + kRecordPrefixBytes, static_cast<std::size_t>(len));
          footer_seen_ = true;
          valid_end_ = end;
          if (how == FooterEnd::kClosed) {
            r_.recovery_.footer_present = true;
            valid_end_ = end + kMagic.size();
            if (size_ > valid_end_) {
              diag(valid_end_, std::to_string(size_ - valid_end_) + " bytes after the closing magic");
            }
          } else {
            tail_diag(end, "Footer not followed by the closing magic");
          }
          break;
        }
        pos = after_bad(pos, end, "Footer record that is not at the end of the file");
        continue;
      }
      if (!known_opcode(op)) {
        if (op >= 0x80) {  // private records: skipped
          if (end_ok(end)) {
            pos = valid_end_ = end;
          } else {
            pos = resync(pos, pos + 1, "record with opcode " + op_text(op) + " is followed by no valid record");
          }
          continue;
        }
        diag(pos, "record with opcode " + op_text(op) + " (reserved, not an MCAP record)");
        pos = after_bad(pos, end, "record with a reserved opcode");
        continue;
      }
      if (!handle(op, pos, data_ + pos + kRecordPrefixBytes, static_cast<std::size_t>(len))) {
        pos = after_bad(pos, end, op_text(op) + " record unusable");
        continue;
      }
      pos = valid_end_ = end;
    }
    finish_pending_chunk(closing_magic_);  // still pending: the file ends after its Message Index records
    if (!footer_seen_) {
      const std::string text =
          "no Footer: the file was cut short or its writer did not close it (" +
          std::to_string(size_ - valid_end_) + " bytes after the last complete record ignored)";
      if (closing_magic_) {
        diag(valid_end_, text);
      } else {
        tail_diag(valid_end_, text);
      }
    }
    r_.recovery_.valid_bytes = valid_end_;
    r_.recovery_.bytes_ignored_at_end = size_ - valid_end_;
    r_.recovery_.messages_recovered = r_.messages_.size();
    final_checks(footer_seen_);
    if (suppressed_ > 0) {
      r_.diagnostics_.push_back({valid_end_, std::to_string(suppressed_) + " further diagnostics suppressed"});
    }
    finish_damage();
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
  // A record whose place is certain: the Footer before the closing magic, and
  // from an intact summary the chunks, their Message Index records, the
  // summary's first record, the first Summary Offset record and Data End.
  struct Anchor {
    std::uint8_t op = 0;          // 0: any record
    std::uint64_t length = 0;     // whole record; 0: not known
    std::uint64_t indexes_end = 0;  // chunks: end of their Message Index records
  };
  enum class FooterEnd { kClosed, kCutInMagic, kNotTheFooter };
  enum class Candidate { kBad, kWeak, kStrong };

  // Records found in a row before a scan takes an offset as the next record
  // (unless one of them is a chunk that decodes and matches its CRC, a Data End
  // whose CRC matches, or the Footer: one of those is enough).
  static constexpr int kWeakChain = 3;

  void diag(std::uint64_t offset, std::string message) {
    if (offset > 0) first_problem_ = std::min(first_problem_, offset);
    if (r_.diagnostics_.size() >= kMaxDiagnostics) {
      ++suppressed_;
      return;
    }
    r_.diagnostics_.push_back({offset, std::move(message)});
  }

  // A diagnostic that a writer which did not close its file explains (a cut
  // record, a zero tail, no Footer): damage only when the file ends with the
  // closing magic.
  void tail_diag(std::uint64_t offset, std::string message) {
    if (closing_magic_) {
      diag(offset, std::move(message));
      return;
    }
    ++tail_diagnostics_;
    if (r_.diagnostics_.size() >= kMaxDiagnostics) {
      ++suppressed_;
      return;
    }
    r_.diagnostics_.push_back({offset, std::move(message)});
  }

  // One damaged record; a second problem of the same record is added to its text.
  void note_damage(std::uint64_t offset, std::uint64_t end, std::string what) {
    first_problem_ = std::min(first_problem_, offset);
    std::vector<McapDamagedRecord>& records = r_.damage_.records;
    if (!records.empty() && records.back().offset == offset && records.back().end == end) {
      records.back().what += "; " + what;
    } else if (records.size() < kMaxDiagnostics) {
      records.push_back({offset, end, std::move(what)});
    }
  }

  bool magic_at(std::uint64_t at) const {
    return at <= size_ && size_ - at >= kMagic.size() && std::equal(kMagic.begin(), kMagic.end(), data_ + at);
  }

  // ---- the summary, from the end of the file -----------------------------------------------

  // Finds the Footer before the closing magic; when the summary it points at
  // parses (and its CRC matches, when set), takes the places of the records
  // it names as anchors, and with valid Chunk Index records reads chunks by them.
  void locate_footer() {
    constexpr std::uint64_t kFooterBytes = kRecordPrefixBytes + kFooterContentBytes;
    if (size_ < 2 * kMagic.size() + kFooterBytes || !magic_at(size_ - kMagic.size())) return;
    closing_magic_ = true;
    const std::uint64_t f = size_ - kMagic.size() - kFooterBytes;
    if (data_[f] != kOpFooter || le64(data_ + f + 1) != kFooterContentBytes) return;
    footer_at_ = f;
    anchors_[f] = {kOpFooter, kFooterBytes, 0};
    const std::uint64_t summary_start = le64(data_ + f + 9);
    const std::uint64_t summary_offset_start = le64(data_ + f + 17);
    const std::uint32_t crc = static_cast<std::uint32_t>(le64(data_ + f + 25) & 0xFFFFFFFFu);
    if (summary_start == 0 || summary_start < kMagic.size() || summary_start > f) return;
    if (summary_offset_start != 0 && (summary_offset_start < summary_start || summary_offset_start > f)) return;
    const auto summary_bytes = static_cast<std::size_t>(f + kFooterCrcBytes - summary_start);
    if (crc != 0 && crc32(data_ + summary_start, summary_bytes) != crc) return;
    struct IndexedChunk {
      std::uint64_t offset, length, indexes_length;
      std::vector<std::uint64_t> index_offsets;
    };
    std::vector<IndexedChunk> chunks;
    bool summary_offset_seen = summary_offset_start == 0;
    for (std::uint64_t at = summary_start; at < f;) {
      if (f - at < kRecordPrefixBytes) return;
      const std::uint8_t op = data_[at];
      const std::uint64_t len = le64(data_ + at + 1);
      if (len > f - at - kRecordPrefixBytes) return;
      summary_offset_seen = summary_offset_seen || at == summary_offset_start;
      if (op == kOpChunkIndex) {
        ByteSource s(data_ + at + kRecordPrefixBytes, static_cast<std::size_t>(len));
        try {
          IndexedChunk c{};
          s.u64();
          s.u64();
          c.offset = s.u64();
          c.length = s.u64();
          for (const auto& [channel, offset] : parse_u16_u64_map(s)) c.index_offsets.push_back(offset);
          c.indexes_length = s.u64();
          chunks.push_back(std::move(c));
        } catch (const FieldOverrun&) {
          return;
        } catch (const RecordError&) {
          return;
        }
      }
      at += kRecordPrefixBytes + len;
    }
    if (!summary_offset_seen) return;
    summary_ok_ = true;
    summary_start_ = summary_start;
    anchors_[summary_start] = {0, 0, 0};
    if (summary_offset_start != 0) anchors_[summary_offset_start] = {kOpSummaryOffset, 0, 0};
    const std::uint64_t data_end_at = summary_start - 13;
    if (summary_start >= kMagic.size() + 13 && data_[data_end_at] == kOpDataEnd &&
        le64(data_ + data_end_at + 1) == 4) {
      anchors_[data_end_at] = {kOpDataEnd, 13, 0};
    }
    // Usable when every chunk lies in the data section, in order, without overlaps.
    std::sort(chunks.begin(), chunks.end(),
              [](const IndexedChunk& a, const IndexedChunk& b) { return a.offset < b.offset; });
    std::uint64_t previous_end = kMagic.size();
    for (const IndexedChunk& c : chunks) {
      if (c.offset < previous_end || c.length <= kRecordPrefixBytes || c.length > summary_start - c.offset ||
          c.indexes_length > summary_start - c.offset - c.length) {
        return;
      }
      const std::uint64_t chunk_end = c.offset + c.length;
      for (const std::uint64_t mi : c.index_offsets) {
        if (mi < chunk_end || mi >= chunk_end + c.indexes_length) return;
      }
      // Without a summary CRC, a Chunk opcode where each chunk should be stands in for it.
      if (crc == 0 && data_[c.offset] != kOpChunk) return;
      previous_end = chunk_end + c.indexes_length;
    }
    index_used_ = !chunks.empty();
    for (const IndexedChunk& c : chunks) {
      anchors_[c.offset] = {kOpChunk, c.length, c.offset + c.length + c.indexes_length};
      for (const std::uint64_t mi : c.index_offsets) anchors_[mi] = {kOpMessageIndex, 0, 0};
    }
  }

  // The first anchor after `pos`, or the file size.
  std::uint64_t next_anchor_after(std::uint64_t pos) const {
    const auto it = anchors_.upper_bound(pos);
    return it == anchors_.end() ? size_ : it->first;
  }

  std::string anchor_text(std::uint64_t at) const {
    const auto it = anchors_.find(at);
    if (it == anchors_.end()) return "no record is known";
    if (it->second.op == kOpFooter) return "the Footer is";
    if (it->second.op == 0) return "the summary starts";
    return std::string("the summary puts a ") + opcode_name(it->second.op) + " record";
  }

  // Non-empty when `pos` is inside a chunk the index names, or among its
  // Message Index records but not at one: no record can start there.
  std::string inside_indexed_chunk(std::uint64_t pos) const {
    auto it = anchors_.upper_bound(pos);
    while (it != anchors_.begin()) {
      --it;
      if (it->second.op != kOpChunk) continue;
      const std::uint64_t start = it->first;
      const std::uint64_t chunk_end = start + it->second.length;
      if (pos < chunk_end) {
        return "offset " + std::to_string(pos) + " is inside the Chunk at " + std::to_string(start) +
               " (chunk index)";
      }
      if (pos >= it->second.indexes_end) return "";
      // Among its Message Index records: only a Message Index that ends among them.
      if (size_ - pos >= kRecordPrefixBytes && data_[pos] == kOpMessageIndex &&
          le64(data_ + pos + 1) <= it->second.indexes_end - pos - kRecordPrefixBytes) {
        return "";
      }
      return "no Message Index record at offset " + std::to_string(pos) +
             ", among the Message Index records of the Chunk at " + std::to_string(start) + " (chunk index)";
    }
    return "";
  }

  // ---- resynchronisation ------------------------------------------------------------------

  // A record at `at` that is certainly cut by the end of the file: a known
  // opcode and a length past the end, or fewer bytes left than a record prefix.
  bool cut_looking(std::uint64_t at) const {
    if (at >= size_) return false;
    if (size_ - at < kRecordPrefixBytes) return true;
    return known_opcode(data_[at]) && le64(data_ + at + 1) > size_ - at - kRecordPrefixBytes;
  }

  // Can reading go on at `end`, the declared end of a record?
  bool end_ok(std::uint64_t end) {
    if (end == size_ || anchors_.count(end) > 0) return true;
    if (end > size_) return false;
    if (!closing_magic_ && (cut_looking(end) || zeros_from(end))) return true;
    return probe(end, true);
  }

  bool zeros_from(std::uint64_t at) const {
    return at < size_ && data_[at] == 0 &&
           std::all_of(data_ + at, data_ + size_, [](std::uint8_t b) { return b == 0; });
  }

  // Before a record at `pos` whose length fits is used: when no valid record
  // follows its declared `end` but valid records start inside it, its length
  // field is damaged (too large, e.g. swallowing the records after it):
  // returns where to go on (the record is skipped). When nothing valid starts
  // inside it, the damage is after it, and it is read.
  std::optional<std::uint64_t> bad_length(std::uint64_t pos, std::uint8_t op, std::uint64_t end) {
    cheap_chunks_ = true;
    const bool fine = end_ok(end);
    cheap_chunks_ = false;
    if (fine) return std::nullopt;
    std::uint64_t next = end;
    for (std::uint64_t q = pos + 1; q < end; ++q) {
      if (plausible_start(q) && probe(q)) {
        next = q;
        break;
      }
    }
    if (next == end) return std::nullopt;
    finish_pending_chunk(true);
    const std::string what = op_text(op) + " record of " + std::to_string(end - pos - kRecordPrefixBytes) +
                             " content bytes is followed by no valid record (length field damaged)";
    note_damage(pos, next, what);
    r_.damage_.skipped.push_back({pos, next});
    r_.damage_.bytes_skipped += next - pos;
    diag(pos, what + ": skipped " + std::to_string(next - pos) + " bytes to the next valid record at offset " +
                  std::to_string(next));
    return next;
  }

  // After a record at `pos` that could not be used although its length fits:
  // go on at its declared end when a record follows there, else resynchronise.
  std::uint64_t after_bad(std::uint64_t pos, std::uint64_t end, const std::string& what) {
    if (end_ok(end)) {
      note_damage(pos, end, what);
      valid_end_ = end;
      return end;
    }
    return resync(pos, pos + 1, what + ", and no valid record follows it");
  }

  // Finds the next valid record after the bad one at `bad`: the next anchor
  // (chunk index / Footer), or before it the first offset from `from` where
  // probe() finds valid records. Returns where to go on (the file size when
  // nothing valid follows: then the rest is a cut record, zeros or garbage).
  std::uint64_t resync(std::uint64_t bad, std::uint64_t from, const std::string& why) {
    const std::uint64_t limit = next_anchor_after(bad);
    std::uint64_t next = limit;
    const bool in_chunk = index_used_ && !inside_indexed_chunk(bad).empty();
    if (!in_chunk) {
      for (std::uint64_t q = from; q < limit; ++q) {
        if (plausible_start(q) && probe(q)) {
          next = q;
          break;
        }
      }
    }
    // A chunk's Message Index records cut short by the end of the file are not wrong.
    finish_pending_chunk(next < size_ || closing_magic_);
    if (next >= size_) {
      end_of_data(bad, why);
      return size_;
    }
    note_damage(bad, next, why);
    r_.damage_.skipped.push_back({bad, next});
    r_.damage_.bytes_skipped += next - bad;
    diag(bad, why + ": skipped " + std::to_string(next - bad) + " bytes to the next valid record at offset " +
                  std::to_string(next));
    return next;
  }

  // Nothing valid from `at` to the end of the file.
  void end_of_data(std::uint64_t at, const std::string& why) {
    const std::uint64_t remaining = size_ - at;
    if (std::all_of(data_ + at, data_ + size_, [](std::uint8_t b) { return b == 0; })) {
      tail_diag(at, "opcode 0x00 is not a record (zeroed or corrupt data); the rest of the file is ignored");
      if (closing_magic_) note_damage(at, size_, "zeros up to the end of the file");
      return;
    }
    if (cut_looking(at)) {
      if (remaining < kRecordPrefixBytes) {
        tail_diag(at, std::to_string(remaining) + " bytes at the end, too few for a record: file cut short");
      } else {
        const std::uint8_t op = data_[at];
        tail_diag(at, op_text(op) + " record of " + std::to_string(le64(data_ + at + 1)) +
                          " content bytes, but only " + std::to_string(remaining - kRecordPrefixBytes) +
                          " remain: file cut short");
      }
      if (closing_magic_) note_damage(at, size_, "record cut short before the closing magic");
      return;
    }
    note_damage(at, size_, why);
    r_.damage_.skipped.push_back({at, size_});
    r_.damage_.bytes_skipped += remaining;
    diag(at, why + "; no valid record follows: the last " + std::to_string(remaining) + " bytes are ignored");
  }

  // Cheap test before probe(): a record opcode and a length inside the file.
  bool plausible_start(std::uint64_t q) const {
    if (size_ - q < kRecordPrefixBytes) return false;
    const std::uint8_t op = data_[q];
    return known_opcode(op) && op != kOpHeader && le64(data_ + q + 1) <= size_ - q - kRecordPrefixBytes;
  }

  // Whether valid records start at `q`: a strong record (a chunk that decodes
  // and matches its CRC, a Data End whose CRC matches, the Footer before the
  // closing magic), or kWeakChain well-formed records in a row, or well-formed
  // records up to an anchor or exactly to the end of the file. No record may
  // run across an anchor.
  // `after_record`: `q` is the declared end of a record being read, not a
  // scan candidate: records with private opcodes (0x80 and up) count as well
  // formed there (a scan does not start at one: garbage has many such bytes),
  // and so does a chain that ends in a record cut by the end of the file or in
  // zeros, when the file has no closing magic (a scan would find the records
  // of a cut chunk that way).
  bool probe(std::uint64_t q, bool after_record = false) {
    std::uint64_t at = q;
    int weak = 0;
    for (;;) {
      if (at == size_) return weak > 0;
      if (at != q && anchors_.count(at) > 0) return true;
      if (after_record && at != q && !closing_magic_ && (cut_looking(at) || zeros_from(at))) return true;
      const bool private_record = (after_record || at != q) && size_ - at >= kRecordPrefixBytes &&
                                  data_[at] >= 0x80 && le64(data_ + at + 1) <= size_ - at - kRecordPrefixBytes;
      if (!private_record && !plausible_start(at)) return false;
      const std::uint8_t op = data_[at];
      const std::uint64_t len = le64(data_ + at + 1);
      const std::uint64_t end = at + kRecordPrefixBytes + len;
      if (next_anchor_after(at) < end) return false;
      switch (private_record ? Candidate::kWeak : candidate(at, op, len)) {
        case Candidate::kStrong: return true;
        case Candidate::kBad: return false;
        case Candidate::kWeak: break;
      }
      if (++weak >= kWeakChain) return true;
      at = end;
    }
  }

  // How convincing a record of opcode `op` with `len` content bytes at `at` is.
  Candidate candidate(std::uint64_t at, std::uint8_t op, std::uint64_t len) {
    ByteSource s(data_ + at + kRecordPrefixBytes, static_cast<std::size_t>(len));
    auto exact = [&s]() { return s.remaining() == 0 ? Candidate::kWeak : Candidate::kBad; };
    try {
      switch (op) {
        case kOpChunk:
          if (cheap_chunks_) {  // its header agrees with its length: enough to take it as the next record
            const std::optional<std::uint64_t> own = chunk_length_from_header(at);
            if (own && *own == kRecordPrefixBytes + len) return Candidate::kStrong;
          }
          return chunk_verifies(at, len) ? Candidate::kStrong : Candidate::kBad;
        case kOpFooter:
          return len == kFooterContentBytes && at + kRecordPrefixBytes + len + kMagic.size() == size_ &&
                         magic_at(at + kRecordPrefixBytes + len)
                     ? Candidate::kStrong
                     : Candidate::kBad;
        case kOpDataEnd: {
          if (len != 4) return Candidate::kBad;
          const std::uint32_t stored = s.u32();
          if (stored == 0) return Candidate::kWeak;
          return crc32(data_, static_cast<std::size_t>(at)) == stored ? Candidate::kStrong : Candidate::kBad;
        }
        case kOpSchema:
          if (s.u16() == 0) return Candidate::kBad;
          skip_string(s);
          skip_string(s);
          skip_string(s);
          return exact();
        case kOpChannel:
          s.u16();
          s.u16();
          skip_string(s);
          skip_string(s);
          skip_string_map(s);
          return exact();
        case kOpMessage: return len >= 22 ? Candidate::kWeak : Candidate::kBad;
        case kOpMessageIndex:
          s.u16();
          take_prefixed(s, 16, "records array");
          return exact();
        case kOpChunkIndex:
          for (int i = 0; i < 4; ++i) s.u64();
          take_prefixed(s, 10, "Map<uint16, uint64>");
          s.u64();
          skip_string(s);
          s.u64();
          s.u64();
          return exact();
        case kOpAttachment:
          s.u64();
          s.u64();
          skip_string(s);
          skip_string(s);
          s.take(static_cast<std::size_t>(std::min<std::uint64_t>(s.u64(), len)));
          s.u32();
          return exact();
        case kOpAttachmentIndex:
          for (int i = 0; i < 5; ++i) s.u64();
          skip_string(s);
          skip_string(s);
          return exact();
        case kOpStatistics:
          s.u64();
          s.u16();
          for (int i = 0; i < 4; ++i) s.u32();
          s.u64();
          s.u64();
          take_prefixed(s, 10, "Map<uint16, uint64>");
          return exact();
        case kOpMetadata:
          skip_string(s);
          skip_string_map(s);
          return exact();
        case kOpMetadataIndex:
          s.u64();
          s.u64();
          skip_string(s);
          return exact();
        case kOpSummaryOffset:
          return len == 17 && known_opcode(s.u8()) ? Candidate::kWeak : Candidate::kBad;
        default: return Candidate::kBad;
      }
    } catch (const FieldOverrun&) {
      return Candidate::kBad;
    } catch (const RecordError&) {
      return Candidate::kBad;
    }
  }

  // Whether a Chunk record with `len` content bytes at `at` decodes and
  // matches its CRC. Remembered per offset; the bytes checked this way are
  // bounded (a file made of fake chunk headers must not take quadratic time).
  bool chunk_verifies(std::uint64_t at, std::uint64_t len) {
    const auto key = std::make_pair(at, len);
    const auto known = verified_.find(key);
    if (known != verified_.end()) return known->second;
    bool ok = false;
    // The uncompressed size as the header states it (decoding fails past kMaxChunkUncompressedBytes).
    const std::uint64_t plain =
        len >= 24 ? std::min(le64(data_ + at + kRecordPrefixBytes + 16), kMaxChunkUncompressedBytes) : 0;
    if (verify_budget_ >= len + plain) {
      verify_budget_ -= len + plain;
      ChunkContent c;
      decode_chunk_content(data_ + at + kRecordPrefixBytes, static_cast<std::size_t>(len), c, false);
      ok = c.problem.empty();
    }
    verified_[key] = ok;
    return ok;
  }

  // The whole length of the Chunk record at `pos` as its own header gives it
  // (prefix, fixed fields, compression name, compressed_size), if those fields
  // are inside the file.
  std::optional<std::uint64_t> chunk_length_from_header(std::uint64_t pos) const {
    if (size_ - pos < kRecordPrefixBytes) return std::nullopt;
    ByteSource s(data_ + pos + kRecordPrefixBytes, static_cast<std::size_t>(size_ - pos - kRecordPrefixBytes));
    try {
      s.u64();
      s.u64();
      s.u64();
      s.u32();
      const std::uint32_t name = s.u32();
      if (name > 64) return std::nullopt;
      s.take(name);
      const std::uint64_t compressed = s.u64();
      const std::uint64_t fixed = kRecordPrefixBytes + s.pos();
      if (compressed > (std::uint64_t{1} << 62)) return std::nullopt;
      return fixed + compressed;
    } catch (const FieldOverrun&) {
      return std::nullopt;
    }
  }

  // Whether a record of `length` bytes at `pos` stays inside the file, runs
  // across no anchor and is followed by a valid record.
  bool extent_ok(std::uint64_t pos, std::uint64_t length) {
    if (length <= kRecordPrefixBytes || length > size_ - pos) return false;
    return next_anchor_after(pos) >= pos + length && end_ok(pos + length);
  }

  // A Chunk record (not named by the chunk index) whose length field disagrees
  // with its header or runs past the end of the file. When the length its
  // header gives is followed by a valid record, it is read with that length
  // (and rejected unless it decodes and matches its CRC). Returns where to go
  // on, size_ + 1 for a chunk cut by the end of the file, or nothing to read it
  // as an ordinary record.
  std::optional<std::uint64_t> chunk_with_bad_length(std::uint64_t pos, std::uint64_t len) {
    const std::uint64_t remaining = size_ - pos;
    const bool fits = len <= remaining - kRecordPrefixBytes;
    const std::optional<std::uint64_t> own = chunk_length_from_header(pos);
    if (!own || (fits && *own == kRecordPrefixBytes + len)) return std::nullopt;
    const bool own_ok = extent_ok(pos, *own);
    const bool declared_ok = fits && extent_ok(pos, kRecordPrefixBytes + len);
    const bool own_verifies = own_ok && chunk_verifies(pos, *own - kRecordPrefixBytes);
    if ((own_verifies && !(declared_ok && chunk_verifies(pos, len))) || (own_ok && !declared_ok)) {
      finish_pending_chunk(true);
      const std::string what = "Chunk record length field says " + std::to_string(len) +
                               " content bytes, its header " + std::to_string(*own - kRecordPrefixBytes) +
                               " (length field damaged; read with its header's length" +
                               (own_verifies ? ", CRC checked)" : ")");
      diag(pos, what);
      note_damage(pos, pos + *own, what);
      if (!read_chunk(pos, data_ + pos + kRecordPrefixBytes, static_cast<std::size_t>(*own - kRecordPrefixBytes))) {
        note_damage(pos, pos + *own, "Chunk rejected");
      }
      valid_end_ = pos + *own;
      return pos + *own;
    }
    if (!fits && !closing_magic_ && *own > remaining) {  // the header agrees: a chunk cut by the end of the file
      finish_pending_chunk(false);
      end_of_data(pos, "Chunk record cut short");
      return size_ + 1;
    }
    return std::nullopt;
  }

  // The Chunk the chunk index puts at `pos`, `length` bytes: read as the index
  // says even when its opcode or length field is damaged (the CRC checks it).
  std::uint64_t read_indexed_chunk(std::uint64_t pos, std::uint64_t length) {
    finish_pending_chunk(true);
    const std::uint8_t op = data_[pos];
    const std::uint64_t len = le64(data_ + pos + 1);
    if (op != kOpChunk || len != length - kRecordPrefixBytes) {
      const std::string what = "the chunk index says a Chunk of " + std::to_string(length - kRecordPrefixBytes) +
                               " content bytes is here, the record has opcode " + op_text(op) +
                               " and length field " + std::to_string(len) + " (read as the index says)";
      diag(pos, what);
      note_damage(pos, pos + length, what);
    }
    if (!read_chunk(pos, data_ + pos + kRecordPrefixBytes, static_cast<std::size_t>(length - kRecordPrefixBytes))) {
      note_damage(pos, pos + length, "Chunk rejected");
    }
    valid_end_ = pos + length;
    return pos + length;
  }

  // When the Footer record at `pos` is the file's own: followed by the closing
  // magic (or, cut short, by part of it).
  FooterEnd footer_end(std::uint64_t pos) const {
    const std::uint64_t end = pos + kRecordPrefixBytes + kFooterContentBytes;
    if (le64(data_ + pos + 1) != kFooterContentBytes) return FooterEnd::kNotTheFooter;
    if (magic_at(end)) return FooterEnd::kClosed;
    if (size_ - end < kMagic.size() && std::equal(data_ + end, data_ + size_, kMagic.begin())) {
      return FooterEnd::kCutInMagic;
    }
    return FooterEnd::kNotTheFooter;
  }

  void finish_damage() {
    McapDamage& d = r_.damage_;
    d.closed = r_.recovery_.footer_present && valid_end_ == size_;
    d.footer_found = footer_at_ != 0 || r_.recovery_.footer_present;
    d.summary_found = summary_ok_;
    d.chunk_index_used = index_used_;
    std::sort(d.records.begin(), d.records.end(),
              [](const McapDamagedRecord& a, const McapDamagedRecord& b) { return a.offset < b.offset; });
    if (r_.clean()) {
      d.state = McapFileState::kComplete;
      d.intact_until = size_;
    } else if (!closing_magic_ && !r_.recovery_.footer_present && d.records.empty() && suppressed_ == 0 &&
               r_.diagnostics_.size() == tail_diagnostics_) {
      d.state = McapFileState::kNotClosed;
      d.intact_until = valid_end_;
    } else {
      d.state = McapFileState::kDamaged;
      d.intact_until = std::min<std::uint64_t>(first_problem_, size_);
    }
  }

  // ---- records -------------------------------------------------------------------------------

  // Reads one record whose length fits; false when it is unusable (malformed,
  // a rejected chunk, a Header after the start).
  bool handle(std::uint8_t op, std::uint64_t pos, const std::uint8_t* content, std::size_t len) {
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
            return false;
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
        case kOpChunk: return read_chunk(pos, content, len);
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
        default: break;  // Attachment/Metadata Index
      }
      if (op == kOpFooter && len != kFooterContentBytes) {
        diag(pos, "Footer of " + std::to_string(len) + " content bytes, expected 20");
      }
    } catch (const FieldOverrun& e) {
      diag(pos, "malformed " + op_text(op) + " record: a field of " + std::to_string(e.wanted) +
                    " bytes at content offset " + std::to_string(e.at) + " runs past its " + std::to_string(len) +
                    " bytes (record skipped)");
      return false;
    } catch (const RecordError& e) {
      diag(pos, "malformed " + op_text(op) + " record: " + e.message + " (record skipped)");
      return false;
    }
    return true;
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
        if (!same(c, channel)) diag(pos, "Channel id " + std::to_string(channel.id) + " redefined differently");
        return;
      }
    }
    r_.channels_.push_back(std::move(channel));
  }

  // The Chunk record at `pos` with `len` content bytes; false when rejected.
  bool read_chunk(std::uint64_t pos, const std::uint8_t* content, std::size_t len) {
    ChunkContent c;
    c.info.offset = pos;
    c.info.length = kRecordPrefixBytes + len;
    pending_ = ChunkCheck{};
    pending_.end = pos + c.info.length;
    pending_.message_index_end = pending_.end;
    pending_valid_ = false;
    have_pending_ = true;

    decode_chunk_content(content, len, c, true);
    McapChunkInfo& info = c.info;
    if (!c.problem.empty()) {
      ++r_.recovery_.rejected_chunks;
      diag(pos, "Chunk rejected, its records are skipped: " + c.problem);
      r_.chunks_.push_back(std::move(info));
      return false;
    }
    for (McapSchema& sc : c.schemas) add_schema(std::move(sc), pos);
    for (McapChannel& ch : c.channels) add_channel(std::move(ch), pos);
    bool out_of_range = false;
    for (std::size_t i = 0; i < c.messages.size(); ++i) {
      McapMessage& m = c.messages[i];
      pending_.messages[c.message_offsets[i]] = {m.channel_id, m.log_time_ns};
      first_use_of_channel_.emplace(m.channel_id, pos);
      out_of_range = out_of_range || m.log_time_ns < info.message_start_time_ns ||
                     m.log_time_ns > info.message_end_time_ns;
      r_.messages_.push_back(std::move(m));
    }
    if (out_of_range) diag(pos, "Chunk holds messages outside its message_start_time..message_end_time");
    info.message_count = c.messages.size();
    info.valid = true;
    pending_valid_ = true;
    ++r_.recovery_.complete_chunks;
    chunk_at_[pos] = r_.chunks_.size();
    r_.chunks_.push_back(std::move(info));
    return true;
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

  // Called when the records after a chunk stop being Message Index records;
  // `check` false when they stop because the file is cut.
  void finish_pending_chunk(bool check) {
    if (!have_pending_) return;
    have_pending_ = false;
    if (pending_valid_) {
      const std::uint64_t chunk_offset = r_.chunks_.back().offset;
      if (check && pending_.any_index && pending_.indexed != pending_.messages.size()) {
        diag(chunk_offset, "Message Index records cover " + std::to_string(pending_.indexed) + " of the chunk's " +
                               std::to_string(pending_.messages.size()) + " messages");
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
    std::string differ;
    auto compare = [&differ](const char* field, bool same_value) {
      if (!same_value) differ += std::string(differ.empty() ? "" : ", ") + field;
    };
    compare("length", c.length == chunk_length);
    compare("compression", c.compression == compression);
    compare("compressed_size", c.compressed_size == compressed_size);
    compare("uncompressed_size", c.uncompressed_size == uncompressed_size);
    compare("message_start_time", c.message_start_time_ns == start_time);
    compare("message_end_time", c.message_end_time_ns == end_time);
    if (!differ.empty()) {
      if (summary_ok_) {  // the summary's CRC matched: the chunk's header is what changed
        diag(chunk_offset, "Chunk header disagrees with its Chunk Index at offset " + std::to_string(pos) + " (" +
                               differ + ")");
      } else {
        diag(pos, "Chunk Index disagrees with the Chunk at offset " + std::to_string(chunk_offset) + " (" + differ +
                      ")");
      }
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
  std::size_t tail_diagnostics_ = 0;  // diagnostics a writer that did not close the file explains
  std::uint64_t first_problem_ = ~std::uint64_t{0};
  std::uint64_t valid_end_ = kMagic.size();  // end of the last complete record
  bool footer_seen_ = false;
  bool in_summary_ = false;
  std::uint64_t attachments_ = 0;
  std::uint64_t metadata_ = 0;
  std::uint64_t chunk_indexes_ = 0;
  std::uint64_t statistics_offset_ = 0;

  // From the end of the file (locate_footer).
  bool closing_magic_ = false;   // the file ends with the magic
  std::uint64_t footer_at_ = 0;  // the Footer right before it, 0 if none
  bool summary_ok_ = false;      // the summary it points at parses (CRC ok when set)
  std::uint64_t summary_start_ = 0;
  bool index_used_ = false;  // chunks located by the Chunk Index records
  std::map<std::uint64_t, Anchor> anchors_;
  std::map<std::pair<std::uint64_t, std::uint64_t>, bool> verified_;  // (offset, length) -> chunk verifies
  std::uint64_t verify_budget_ = 0;
  bool cheap_chunks_ = false;  // probe(): a Chunk whose header agrees with its length is enough

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

// The whole file. Only a regular file: a FIFO (which would wait for a writer,
// deaf to Ctrl-C), a directory or a device is refused, naming what it is.
std::vector<std::uint8_t> read_file(const std::string& path) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC | O_NOCTTY | O_NONBLOCK);
  if (fd < 0) throw std::runtime_error(path + ": cannot open for reading: " + std::strerror(errno));
  struct Closer {
    int fd;
    ~Closer() { ::close(fd); }
  } closer{fd};
  struct stat st {};
  if (::fstat(fd, &st) != 0) throw std::runtime_error(path + ": cannot read: " + std::strerror(errno));
  if (!S_ISREG(st.st_mode)) {
    const char* kind = S_ISDIR(st.st_mode) ? "a directory" : S_ISFIFO(st.st_mode) ? "a pipe" : "a device or socket";
    throw std::runtime_error(path + ": not a regular file (" + kind + "); an MCAP file is read whole");
  }
  std::vector<std::uint8_t> bytes(static_cast<std::size_t>(st.st_size));
  std::size_t done = 0;
  while (done < bytes.size()) {
    const ssize_t n = ::read(fd, bytes.data() + done, bytes.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) throw std::runtime_error(path + ": read failed: " + std::strerror(errno));
    if (n == 0) break;  // shrank since fstat(): the bytes there are
    done += static_cast<std::size_t>(n);
  }
  bytes.resize(done);
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

}  // namespace pixyslam::mcap
