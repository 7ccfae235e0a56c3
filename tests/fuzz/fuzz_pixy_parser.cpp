// libFuzzer target: arbitrary bytes from the Pixy's SPI/UART block stream into
// the block parser, in chunks whose sizes come from the input. It must never
// crash, buffer at most one block, deliver only blocks with a signature, and
// keep its byte accounting exact (every byte in is a block, a sync, an idle
// word, skipped or still buffered).

#include <cstddef>
#include <cstdint>

#include "fuzz_common.h"
#include "pixyslam/pixy/pixy_block_parser.h"

namespace {

void check_frame(const pixyslam::pixy::PixyFrame& frame) {
  for (const pixyslam::pixy::PixyBlock& b : frame.blocks) {
    FUZZ_CHECK(b.signature != 0);
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  pixyslam::pixy::PixyBlockParser parser;
  const std::size_t chunk = 1 + data[0] % 64;
  for (std::size_t at = 1; at < size; at += chunk) {
    const std::size_t n = at + chunk <= size ? chunk : size - at;
    parser.feed(data + at, n, [](pixyslam::pixy::PixyFrame&& frame) { check_frame(frame); });
    FUZZ_CHECK(parser.bytes_buffered() <= pixyslam::pixy::kPixyColourCodeBlockBytes);
    const pixyslam::pixy::PixyParserCounters& c = parser.counters();
    FUZZ_CHECK(c.bytes_in == 14 * (c.blocks_ok - c.colour_code_blocks_ok) + 16 * c.colour_code_blocks_ok +
                                 2 * (c.frame_syncs + c.zero_words) + c.bytes_skipped + parser.bytes_buffered());
    FUZZ_CHECK(c.bytes_skipped >= 2 * (c.checksum_errors + c.zero_signature_blocks));
  }
  if (auto last = parser.flush()) check_frame(*last);
  return 0;
}
