#pragma once

// Private to pixyslam_mcap: MCAP opcodes and the little-endian field
// encoders/decoders shared by the writer and the reader (https://mcap.dev/spec).

#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace pixyslam::mcap::detail {

inline constexpr std::array<std::uint8_t, 8> kMagic = {0x89, 'M', 'C', 'A', 'P', '0', '\r', '\n'};

// <opcode u8><content length u64>
inline constexpr std::size_t kRecordPrefixBytes = 9;
// Footer content: summary_start u64, summary_offset_start u64, summary_crc u32.
inline constexpr std::size_t kFooterContentBytes = 20;

enum Opcode : std::uint8_t {
  kOpHeader = 0x01,
  kOpFooter = 0x02,
  kOpSchema = 0x03,
  kOpChannel = 0x04,
  kOpMessage = 0x05,
  kOpChunk = 0x06,
  kOpMessageIndex = 0x07,
  kOpChunkIndex = 0x08,
  kOpAttachment = 0x09,
  kOpAttachmentIndex = 0x0A,
  kOpStatistics = 0x0B,
  kOpMetadata = 0x0C,
  kOpMetadataIndex = 0x0D,
  kOpSummaryOffset = 0x0E,
  kOpDataEnd = 0x0F,
};

const char* opcode_name(std::uint8_t op);

// Appends little-endian fields to a byte buffer, byte by byte.
class ByteSink {
 public:
  explicit ByteSink(std::vector<std::uint8_t>& out) : out_(out) {}

  void u8(std::uint8_t v) { out_.push_back(v); }
  void u16(std::uint16_t v) { le(v, 2); }
  void u32(std::uint32_t v) { le(v, 4); }
  void u64(std::uint64_t v) { le(v, 8); }
  void raw(const std::uint8_t* data, std::size_t size) { out_.insert(out_.end(), data, data + size); }
  void raw(std::string_view s) { raw(reinterpret_cast<const std::uint8_t*>(s.data()), s.size()); }
  // String and uint32 length-prefixed Bytes.
  void str(std::string_view s) {
    u32(static_cast<std::uint32_t>(s.size()));
    raw(s);
  }

  // Starts a record: opcode and a length placeholder; returns the handle for end_record.
  std::size_t begin_record(std::uint8_t op) {
    u8(op);
    const std::size_t at = out_.size();
    u64(0);
    return at;
  }
  void end_record(std::size_t at) { patch_u64(at, out_.size() - at - 8); }
  // Starts a uint32 byte-length prefix (Array, Map); returns the handle for end_u32_prefix.
  std::size_t begin_u32_prefix() {
    const std::size_t at = out_.size();
    u32(0);
    return at;
  }
  void end_u32_prefix(std::size_t at) {
    const std::uint64_t n = out_.size() - at - 4;
    for (int i = 0; i < 4; ++i)
      out_[at + static_cast<std::size_t>(i)] = static_cast<std::uint8_t>(n >> (8 * i));
  }
  void patch_u64(std::size_t at, std::uint64_t v) {
    for (int i = 0; i < 8; ++i)
      out_[at + static_cast<std::size_t>(i)] = static_cast<std::uint8_t>(v >> (8 * i));
  }
  std::size_t size() const { return out_.size(); }

 private:
  void le(std::uint64_t v, int bytes) {
    for (int i = 0; i < bytes; ++i) out_.push_back(static_cast<std::uint8_t>(v >> (8 * i)));
  }

  std::vector<std::uint8_t>& out_;
};

// Thrown by ByteSource when a field runs past the end of its record.
struct FieldOverrun {
  std::size_t at = 0;  // offset within the source where the read started
  std::size_t wanted = 0;
};

// Reads little-endian fields from [data, data + size), bounds-checked.
class ByteSource {
 public:
  ByteSource(const std::uint8_t* data, std::size_t size) : data_(data), size_(size) {}

  std::uint8_t u8() { return static_cast<std::uint8_t>(le(1)); }
  std::uint16_t u16() { return static_cast<std::uint16_t>(le(2)); }
  std::uint32_t u32() { return static_cast<std::uint32_t>(le(4)); }
  std::uint64_t u64() { return le(8); }
  // Returns a pointer to the next n bytes and skips them.
  const std::uint8_t* take(std::size_t n) {
    need(n);
    const std::uint8_t* p = data_ + pos_;
    pos_ += n;
    return p;
  }
  std::string str() {
    const std::uint32_t n = u32();
    const std::uint8_t* p = take(n);
    return std::string(reinterpret_cast<const char*>(p), n);
  }
  std::size_t pos() const { return pos_; }
  std::size_t remaining() const { return size_ - pos_; }

 private:
  void need(std::size_t n) const {
    if (n > size_ - pos_) throw FieldOverrun{pos_, n};
  }
  std::uint64_t le(int bytes) {
    need(static_cast<std::size_t>(bytes));
    std::uint64_t v = 0;
    for (int i = 0; i < bytes; ++i)
      v |= static_cast<std::uint64_t>(data_[pos_ + static_cast<std::size_t>(i)]) << (8 * i);
    pos_ += static_cast<std::size_t>(bytes);
    return v;
  }

  const std::uint8_t* data_;
  std::size_t size_;
  std::size_t pos_ = 0;
};

// Chunk compression codecs. Both throw std::runtime_error on codec failure or
// when the codec was not compiled in.
std::vector<std::uint8_t> compress_chunk(const std::string& compression, const std::vector<std::uint8_t>& in,
                                         int level);
// Decompresses into exactly `uncompressed_size` bytes; throws when the data does not
// decode to exactly that size.
std::vector<std::uint8_t> decompress_chunk(const std::string& compression, const std::uint8_t* data,
                                           std::size_t size, std::uint64_t uncompressed_size);

}  // namespace pixyslam::mcap::detail
