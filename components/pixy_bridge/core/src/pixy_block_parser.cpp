#include "pixyslam/pixy/pixy_block_parser.h"

#include <stdexcept>
#include <string>
#include <utility>

namespace pixyslam::pixy {
namespace {

std::uint16_t word_at(const std::vector<std::uint8_t>& b, std::size_t i) {
  return static_cast<std::uint16_t>(b[i] | (b[i + 1] << 8));
}

bool is_sync(std::uint16_t w) { return w == kPixySyncNormal || w == kPixySyncColourCode; }

void put_word(std::uint16_t w, std::vector<std::uint8_t>& out) {
  out.push_back(static_cast<std::uint8_t>(w & 0xff));
  out.push_back(static_cast<std::uint8_t>(w >> 8));
}

}  // namespace

std::uint16_t pixy_block_checksum(const PixyBlock& b) {
  std::uint16_t sum = static_cast<std::uint16_t>(b.signature + b.x + b.y + b.width + b.height);
  if (b.colour_code) sum = static_cast<std::uint16_t>(sum + static_cast<std::uint16_t>(b.angle_deg));
  return sum;
}

void encode_block(const PixyBlock& b, std::vector<std::uint8_t>& out) {
  const std::uint16_t checksum = pixy_block_checksum(b);
  if (b.signature == 0) throw std::invalid_argument("encode_block: signature 0 is not a Pixy signature");
  if (is_sync(checksum) || (checksum == 0 && !b.colour_code)) {
    throw std::invalid_argument("encode_block: checksum " + std::to_string(checksum) +
                                " would read as a sync or idle word; the block cannot be sent");
  }
  put_word(b.colour_code ? kPixySyncColourCode : kPixySyncNormal, out);
  put_word(checksum, out);
  put_word(b.signature, out);
  put_word(b.x, out);
  put_word(b.y, out);
  put_word(b.width, out);
  put_word(b.height, out);
  if (b.colour_code) put_word(static_cast<std::uint16_t>(b.angle_deg), out);
}

std::vector<std::uint8_t> encode_frame(const std::vector<PixyBlock>& blocks) {
  std::vector<std::uint8_t> out;
  out.reserve(2 + blocks.size() * kPixyColourCodeBlockBytes);
  put_word(kPixySyncNormal, out);  // frame start; the first block's own sync follows
  for (const PixyBlock& b : blocks) encode_block(b, out);
  return out;
}

void PixyBlockParser::skip(std::size_t n) {
  counters_.bytes_skipped += n;
  if (!skipping_) {
    ++counters_.resyncs;
    skipping_ = true;
  }
}

void PixyBlockParser::start_frame(const FrameCallback& on_frame) {
  ++counters_.frame_syncs;
  if (frame_open_) {
    ++counters_.frames;
    on_frame(std::move(frame_));
  }
  frame_ = PixyFrame{};
  frame_.index = next_index_++;
  frame_open_ = true;
}

std::optional<PixyFrame> PixyBlockParser::flush() {
  if (!frame_open_) return std::nullopt;
  frame_open_ = false;
  ++counters_.frames;
  return std::move(frame_);
}

std::vector<PixyFrame> PixyBlockParser::feed(const std::uint8_t* data, std::size_t size) {
  std::vector<PixyFrame> frames;
  feed(data, size, [&frames](PixyFrame&& f) { frames.push_back(std::move(f)); });
  return frames;
}

void PixyBlockParser::feed(const std::uint8_t* data, std::size_t size, const FrameCallback& on_frame) {
  counters_.bytes_in += size;
  buffer_.insert(buffer_.end(), data, data + size);

  // Every decision below waits until all the bytes it depends on are here, so
  // the outcome does not depend on how the stream was split into calls.
  std::size_t pos = 0;
  while (buffer_.size() - pos >= 2) {
    const std::size_t avail = buffer_.size() - pos;
    const std::uint16_t w = word_at(buffer_, pos);
    if (w == 0) {  // idle fill between blocks
      ++counters_.zero_words;
      skipping_ = false;
      pos += 2;
      continue;
    }
    if (!is_sync(w)) {  // garbage or misaligned: move on by one byte
      skip(1);
      pos += 1;
      continue;
    }
    if (avail < 4) break;
    const std::uint16_t next = word_at(buffer_, pos + 2);
    if (is_sync(next) || (next == 0 && w == kPixySyncNormal)) {
      if (w == kPixySyncNormal) {
        start_frame(on_frame);
        skipping_ = false;
      } else {
        skip(2);  // a colour-code sync with no block after it
      }
      pos += 2;
      continue;
    }

    // A block: sync, checksum, signature, x, y, width, height[, angle].
    const bool colour_code = w == kPixySyncColourCode;
    const std::size_t len = colour_code ? kPixyColourCodeBlockBytes : kPixyNormalBlockBytes;
    if (avail < len) break;
    PixyBlock b;
    b.colour_code = colour_code;
    b.signature = word_at(buffer_, pos + 4);
    b.x = word_at(buffer_, pos + 6);
    b.y = word_at(buffer_, pos + 8);
    b.width = word_at(buffer_, pos + 10);
    b.height = word_at(buffer_, pos + 12);
    if (colour_code) b.angle_deg = static_cast<std::int16_t>(word_at(buffer_, pos + 14));
    if (pixy_block_checksum(b) != next) {
      ++counters_.checksum_errors;
      if (frame_open_) ++frame_.checksum_errors;
      skip(2);  // rescan from just after the sync: the block may be short a byte
      pos += 2;
      continue;
    }
    if (b.signature == 0) {
      ++counters_.zero_signature_blocks;
      skip(2);
      pos += 2;
      continue;
    }
    ++counters_.blocks_ok;
    if (colour_code) ++counters_.colour_code_blocks_ok;
    if (frame_open_ && frame_.blocks.size() >= kPixyMaxBlocksPerFrame) {
      ++counters_.blocks_over_frame_limit;
    } else if (frame_open_) {
      frame_.blocks.push_back(b);
    } else {
      ++counters_.blocks_outside_frame;
    }
    skipping_ = false;
    pos += len;
  }
  buffer_.erase(buffer_.begin(), buffer_.begin() + static_cast<std::ptrdiff_t>(pos));
}

}  // namespace pixyslam::pixy
