#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <optional>
#include <vector>

namespace pixyslam::pixy {

// Byte format of the original Pixy (CMUcam5) UART block stream, as parsed and
// produced here.
//
//   Words are 16 bit, little-endian: 0xaa55 is the byte 0x55 followed by 0xaa.
//
//   Block, normal signature (7 words = 14 bytes):
//     0xaa55  checksum  signature  x  y  width  height
//   Block, colour code (8 words = 16 bytes):
//     0xaa56  checksum  signature  x  y  width  height  angle
//   checksum = 16-bit wrap-around sum of the words after it (signature..height,
//   plus angle for a colour code). x, y are the block centre in pixels from the
//   image's top-left corner (0..319, 0..199), width and height in pixels, angle
//   in degrees (signed, -180..180). A normal block has no angle word (angle 0).
//   A colour-code signature is octal-composed: tags 1 then 2 give 012 (= 10);
//   the raw value is kept.
//
//   Frame: one extra 0xaa55 before the first block, so "0xaa55 0xaa55" (or
//   "0xaa55 0xaa56" when the first block is a colour code) opens a frame; every
//   block up to the next such pair belongs to it.
//
//   0x0000 words are idle fill (the camera sends zeros when it has nothing to
//   send).
//
// Choices where the firmware or its documentation leave room:
//   * Frame-start syncs. Between blocks, a 0xaa55 followed by another sync
//     (0xaa55 or 0xaa56) or by 0x0000 is a frame-start sync; any other sync
//     starts a block. So "aa55 aa55 aa55 <checksum> ..." delivers an empty frame
//     and then opens the next one, and a lone "aa55" followed by idle zeros is a
//     frame without blocks (yet): this is how encode_frame({}) writes an empty
//     frame. The original firmware's public source writes nothing but idle zeros
//     for a frame without blocks, so on a real camera an empty frame is not visible on the
//     wire. A 0xaa56 followed by another sync starts neither a block nor a
//     frame; its two bytes are skipped.
//   * A checksum word equal to 0xaa55 or 0xaa56 cannot be told from a sync
//     (the Arduino library reads it as the start of the next frame, as we do),
//     nor can a normal block's checksum 0x0000 (it reads as a frame start
//     followed by idle fill); encode_block() refuses such blocks. Neither occurs
//     with real data: a normal block's words sum to far less than 0xaa55. A
//     colour code's checksum may be 0x0000 (a negative angle can cancel the
//     sum) and is parsed as a block.
//   * 0x0000 words are ignored only where a sync is expected (between blocks);
//     they neither end nor start a frame. Inside a block every word is data.
//   * Signature 0 is never sent by the camera: a block with signature 0 whose
//     checksum matches (e.g. a sync followed by zeros) is rejected and counted
//     in `zero_signature_blocks`.
//   * Resync: where a sync is expected and the next two bytes are neither a
//     sync nor 0x0000, one byte is skipped, so a sync at an odd offset is found
//     again. After a bad checksum only the block's sync word is skipped and
//     scanning resumes right after it, so a byte lost inside one block costs
//     that block only, not the next one too.
//   * Anything but a sync or 0x0000 right after a frame-start sync is read as
//     that sync's checksum, so garbage there costs the frame start (the
//     frame's blocks then join the previous frame) and normally counts a
//     checksum error.
//   * Blocks that arrive before the first frame start (joining a stream
//     mid-frame) belong to no frame: they are counted and dropped.
//   * The end of a frame is known only when the next frame starts. flush()
//     closes the open frame early (end of stream, or an idle line).

inline constexpr std::uint16_t kPixySyncNormal = 0xaa55;
inline constexpr std::uint16_t kPixySyncColourCode = 0xaa56;
inline constexpr std::size_t kPixyNormalBlockBytes = 14;
inline constexpr std::size_t kPixyColourCodeBlockBytes = 16;
// Most blocks one frame keeps: a stream of valid blocks without frame starts
// would otherwise grow the open frame without end. A camera frame at 50 Hz
// carries a few blocks at 19200 baud, at most ~80 at 460800.
inline constexpr std::size_t kPixyMaxBlocksPerFrame = 256;

// One detected colour block, exactly as the camera reports it (pixels, image
// frame: x right, y down, origin at the top-left corner).
struct PixyBlock {
  std::uint16_t signature = 0;  // 1..7, or an octal-composed colour code (012 = tags 1, 2)
  std::uint16_t x = 0;          // centre column, px
  std::uint16_t y = 0;          // centre row, px
  std::uint16_t width = 0;      // px
  std::uint16_t height = 0;     // px
  std::int16_t angle_deg = 0;   // colour codes only; 0 for normal blocks
  bool colour_code = false;

  friend bool operator==(const PixyBlock& a, const PixyBlock& b) {
    return a.signature == b.signature && a.x == b.x && a.y == b.y && a.width == b.width &&
           a.height == b.height && a.angle_deg == b.angle_deg && a.colour_code == b.colour_code;
  }
  friend bool operator!=(const PixyBlock& a, const PixyBlock& b) { return !(a == b); }
};

// The blocks of one camera frame, in the order sent. `index` counts the frames
// this parser has delivered, from 0.
struct PixyFrame {
  std::vector<PixyBlock> blocks;
  std::uint64_t index = 0;
  std::uint32_t checksum_errors = 0;  // blocks of this frame dropped for a bad checksum
};

// Running totals since construction. At any time
//   bytes_in == 14 * (blocks_ok - colour_code_blocks_ok) + 16 * colour_code_blocks_ok
//             + 2 * (frame_syncs + zero_words) + bytes_skipped + bytes_buffered()
// and bytes_skipped >= 2 * (checksum_errors + zero_signature_blocks).
struct PixyParserCounters {
  std::uint64_t bytes_in = 0;
  std::uint64_t frames = 0;                 // frames delivered (feed or flush)
  std::uint64_t frame_syncs = 0;            // frame-start sync words
  std::uint64_t blocks_ok = 0;              // blocks with a matching checksum
  std::uint64_t colour_code_blocks_ok = 0;  // of which colour codes
  std::uint64_t blocks_outside_frame = 0;   // of which dropped: before any frame start
  std::uint64_t blocks_over_frame_limit = 0;  // of which dropped: past kPixyMaxBlocksPerFrame in one frame
  std::uint64_t checksum_errors = 0;        // blocks dropped for a bad checksum
  std::uint64_t zero_signature_blocks = 0;  // blocks dropped for signature 0
  std::uint64_t zero_words = 0;             // idle 0x0000 words between blocks
  std::uint64_t resyncs = 0;                // times the parser lost sync and scanned bytes
  std::uint64_t bytes_skipped = 0;          // bytes that were part of no block, sync or zero word
};

// Incremental parser of the Pixy UART block stream (format above). Bytes may be
// fed in chunks of any size split anywhere, including inside a word: the frames,
// blocks and counters depend only on the concatenated bytes. At most one block
// (16 bytes) is buffered between calls. Frames are delivered when the next
// frame starts, or by flush(). Thread-compatible.
class PixyBlockParser {
 public:
  using FrameCallback = std::function<void(PixyFrame&&)>;

  // Parses `size` bytes; calls `on_frame` for every frame completed by them.
  // `on_frame` must not call back into this parser.
  void feed(const std::uint8_t* data, std::size_t size, const FrameCallback& on_frame);
  // Same, returning the completed frames.
  std::vector<PixyFrame> feed(const std::uint8_t* data, std::size_t size);
  std::vector<PixyFrame> feed(const std::vector<std::uint8_t>& bytes) {
    return feed(bytes.data(), bytes.size());
  }

  // Closes and returns the open frame, if any. Bytes of an unfinished block stay
  // buffered; blocks that follow before the next frame start are outside any frame.
  std::optional<PixyFrame> flush();

  const PixyParserCounters& counters() const { return counters_; }
  // Bytes received but not yet classified (an unfinished sync, word or block).
  std::size_t bytes_buffered() const { return buffer_.size(); }
  bool frame_open() const { return frame_open_; }

 private:
  void skip(std::size_t n);
  void start_frame(const FrameCallback& on_frame);

  std::vector<std::uint8_t> buffer_;
  PixyFrame frame_;
  bool frame_open_ = false;
  bool skipping_ = false;
  std::uint64_t next_index_ = 0;
  PixyParserCounters counters_;
};

// 16-bit wrap-around sum of the words after the checksum (signature..height,
// and angle for a colour code).
std::uint16_t pixy_block_checksum(const PixyBlock& block);

// Appends one block (sync, checksum, data words) to `out`. Throws
// std::invalid_argument for a block the stream cannot carry unambiguously:
// signature 0, a checksum equal to a sync word, or a normal block with checksum
// 0x0000. The angle of a normal block is not sent.
void encode_block(const PixyBlock& block, std::vector<std::uint8_t>& out);

// One frame as the camera sends it: a frame-start sync, then every block.
// Concatenated frames form a valid stream; no blocks gives the lone frame-start
// sync (see the format notes).
std::vector<std::uint8_t> encode_frame(const std::vector<PixyBlock>& blocks);

}  // namespace pixyslam::pixy
