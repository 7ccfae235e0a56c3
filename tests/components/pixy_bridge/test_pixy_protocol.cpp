// Tests of the Pixy (CMUcam5) UART block-stream parser and encoder: the exact
// byte format against hand-written bytes, chunking at every split point and at
// random, garbage and misalignment recovery, checksum errors, idle zero words,
// empty frames, and a fuzz run checking that the counters always add up.

#include <algorithm>
#include <cstdint>
#include <optional>
#include <random>
#include <stdexcept>
#include <vector>

#include <gtest/gtest.h>

#include "pixyslam/pixy/pixy_block_parser.h"

namespace pixyslam::pixy {
namespace {

using Bytes = std::vector<std::uint8_t>;

PixyBlock normal(std::uint16_t sig, std::uint16_t x, std::uint16_t y, std::uint16_t w, std::uint16_t h) {
  PixyBlock b;
  b.signature = sig;
  b.x = x;
  b.y = y;
  b.width = w;
  b.height = h;
  return b;
}

PixyBlock colour_code(std::uint16_t sig, std::uint16_t x, std::uint16_t y, std::uint16_t w, std::uint16_t h,
                      std::int16_t angle) {
  PixyBlock b = normal(sig, x, y, w, h);
  b.colour_code = true;
  b.angle_deg = angle;
  return b;
}

// Frames of a realistic stream: normal and colour-code blocks, one empty frame.
std::vector<std::vector<PixyBlock>> sample_frames() {
  return {
      {normal(1, 100, 80, 10, 21), colour_code(012, 200, 60, 20, 44, -30)},
      {},
      {colour_code(0123, 40, 100, 12, 25, 175), normal(3, 310, 190, 9, 19), normal(7, 5, 3, 2, 4)},
      {normal(2, 160, 100, 30, 62)},
      {colour_code(0765, 0, 0, 1, 2, 0), colour_code(0117, 319, 199, 50, 100, -180)},
  };
}

// The stream of `frames`, closed by the start of one more frame so that the
// last one is delivered by feed() alone.
Bytes stream_of(const std::vector<std::vector<PixyBlock>>& frames) {
  Bytes out;
  for (const auto& f : frames) {
    const Bytes b = encode_frame(f);
    out.insert(out.end(), b.begin(), b.end());
  }
  const Bytes next = encode_frame({normal(5, 1, 1, 1, 1)});
  out.insert(out.end(), next.begin(), next.end());
  return out;
}

struct ParseResult {
  std::vector<PixyFrame> frames;
  PixyParserCounters counters;
};

// Feeds `bytes` split at the given cut positions (ascending, may repeat).
ParseResult parse_split(const Bytes& bytes, const std::vector<std::size_t>& cuts) {
  PixyBlockParser p;
  ParseResult r;
  std::size_t start = 0;
  auto take = [&](std::size_t end) {
    for (PixyFrame& f : p.feed(bytes.data() + start, end - start)) r.frames.push_back(std::move(f));
    start = end;
  };
  for (std::size_t c : cuts) take(c);
  take(bytes.size());
  r.counters = p.counters();
  return r;
}

ParseResult parse_whole(const Bytes& bytes) { return parse_split(bytes, {}); }

void expect_same_frames(const std::vector<PixyFrame>& got, const std::vector<PixyFrame>& want) {
  ASSERT_EQ(got.size(), want.size());
  for (std::size_t i = 0; i < got.size(); ++i) {
    EXPECT_EQ(got[i].index, want[i].index);
    EXPECT_EQ(got[i].blocks, want[i].blocks) << "frame " << i;
    EXPECT_EQ(got[i].checksum_errors, want[i].checksum_errors) << "frame " << i;
  }
}

void expect_same_counters(const PixyParserCounters& a, const PixyParserCounters& b) {
  EXPECT_EQ(a.bytes_in, b.bytes_in);
  EXPECT_EQ(a.frames, b.frames);
  EXPECT_EQ(a.frame_syncs, b.frame_syncs);
  EXPECT_EQ(a.blocks_ok, b.blocks_ok);
  EXPECT_EQ(a.colour_code_blocks_ok, b.colour_code_blocks_ok);
  EXPECT_EQ(a.blocks_outside_frame, b.blocks_outside_frame);
  EXPECT_EQ(a.blocks_over_frame_limit, b.blocks_over_frame_limit);
  EXPECT_EQ(a.checksum_errors, b.checksum_errors);
  EXPECT_EQ(a.zero_signature_blocks, b.zero_signature_blocks);
  EXPECT_EQ(a.zero_words, b.zero_words);
  EXPECT_EQ(a.resyncs, b.resyncs);
  EXPECT_EQ(a.bytes_skipped, b.bytes_skipped);
}

void expect_frames_are(const std::vector<PixyFrame>& got, const std::vector<std::vector<PixyBlock>>& want) {
  ASSERT_EQ(got.size(), want.size());
  for (std::size_t i = 0; i < got.size(); ++i) {
    EXPECT_EQ(got[i].index, i);
    EXPECT_EQ(got[i].blocks, want[i]) << "frame " << i;
  }
}

// bytes_in == bytes of good blocks + syncs + zero words + skipped + buffered.
void expect_bytes_add_up(const PixyBlockParser& p) {
  const PixyParserCounters& c = p.counters();
  const std::uint64_t accounted = kPixyNormalBlockBytes * (c.blocks_ok - c.colour_code_blocks_ok) +
                                  kPixyColourCodeBlockBytes * c.colour_code_blocks_ok +
                                  2 * (c.frame_syncs + c.zero_words) + c.bytes_skipped + p.bytes_buffered();
  EXPECT_EQ(c.bytes_in, accounted);
  EXPECT_GE(c.bytes_skipped, 2 * (c.checksum_errors + c.zero_signature_blocks));
  EXPECT_LT(p.bytes_buffered(), kPixyColourCodeBlockBytes);
}

Bytes concat(std::initializer_list<Bytes> parts) {
  Bytes out;
  for (const Bytes& p : parts) out.insert(out.end(), p.begin(), p.end());
  return out;
}

Bytes block_bytes(const PixyBlock& b) {
  Bytes out;
  encode_block(b, out);
  return out;
}

TEST(PixyProtocol, EncodesTheDocumentedBytes) {
  // Normal block, signature 1, x 160, y 100, w 10, h 21: checksum 292 = 0x0124.
  const Bytes normal_bytes = encode_frame({normal(1, 160, 100, 10, 21)});
  const Bytes want_normal = {0x55, 0xaa,                                      // frame start
                             0x55, 0xaa, 0x24, 0x01,                          // sync, checksum
                             0x01, 0x00, 0xa0, 0x00, 0x64, 0x00, 0x0a, 0x00,  // sig, x, y, w
                             0x15, 0x00};                                     // h
  EXPECT_EQ(normal_bytes, want_normal);

  // Colour code 012 (= 10), x 200, y 50, w 20, h 44, angle -90 (0xffa6):
  // checksum 10 + 200 + 50 + 20 + 44 - 90 = 234.
  const Bytes cc_bytes = block_bytes(colour_code(012, 200, 50, 20, 44, -90));
  const Bytes want_cc = {0x56, 0xaa, 0xea, 0x00, 0x0a, 0x00, 0xc8, 0x00,
                         0x32, 0x00, 0x14, 0x00, 0x2c, 0x00, 0xa6, 0xff};
  EXPECT_EQ(cc_bytes, want_cc);
}

TEST(PixyProtocol, ParsesHandWrittenBytes) {
  // Given a frame written by hand (frame start, one colour code whose first
  // block sync is 0xaa56, one normal block) and the next frame start,
  const Bytes bytes = {0x55, 0xaa,  // frame start
                       0x56, 0xaa, 0xea, 0x00, 0x0a, 0x00, 0xc8, 0x00, 0x32, 0x00, 0x14, 0x00, 0x2c, 0x00, 0xa6, 0xff,
                       0x55, 0xaa, 0x24, 0x01, 0x01, 0x00, 0xa0, 0x00, 0x64, 0x00, 0x0a, 0x00, 0x15, 0x00,
                       0x55, 0xaa, 0x55, 0xaa};  // next frame start and the next block's sync
  PixyBlockParser p;
  const std::vector<PixyFrame> frames = p.feed(bytes);
  // then one frame with both blocks comes out, the angle sign-extended.
  ASSERT_EQ(frames.size(), 1u);
  expect_frames_are(frames, {{colour_code(012, 200, 50, 20, 44, -90), normal(1, 160, 100, 10, 21)}});
  EXPECT_EQ(p.counters().blocks_ok, 2u);
  EXPECT_EQ(p.counters().colour_code_blocks_ok, 1u);
  EXPECT_EQ(p.counters().bytes_skipped, 0u);
  EXPECT_EQ(p.bytes_buffered(), 2u);  // the last sync waits for its checksum
  expect_bytes_add_up(p);
}

TEST(PixyProtocol, RoundTripsNormalAndColourCodeBlocks) {
  const auto frames = sample_frames();
  PixyBlockParser p;
  const std::vector<PixyFrame> got = p.feed(stream_of(frames));
  expect_frames_are(got, frames);
  const PixyParserCounters& c = p.counters();
  EXPECT_EQ(c.frames, frames.size());
  EXPECT_EQ(c.frame_syncs, frames.size() + 1);
  EXPECT_EQ(c.blocks_ok, 9u);
  EXPECT_EQ(c.colour_code_blocks_ok, 4u);
  EXPECT_EQ(c.checksum_errors, 0u);
  EXPECT_EQ(c.bytes_skipped, 0u);
  EXPECT_EQ(c.resyncs, 0u);
  EXPECT_TRUE(p.frame_open());
  expect_bytes_add_up(p);
}

TEST(PixyProtocol, RoundTripsRandomBlocks) {
  std::mt19937 prng(42);
  std::uniform_int_distribution<int> tag(1, 7), ntags(1, 5), nblocks(0, 6), angle(-180, 180);
  std::uniform_int_distribution<int> px(0, 320), py(0, 200);
  std::vector<std::vector<PixyBlock>> frames(200);
  for (auto& f : frames) {
    const int n = nblocks(prng);
    for (int i = 0; i < n; ++i) {
      int sig = 0;
      const int k = ntags(prng);
      for (int t = 0; t < k; ++t) sig = sig * 8 + tag(prng);
      const auto u = [](int v) { return static_cast<std::uint16_t>(v); };
      f.push_back(k == 1 ? normal(u(sig), u(px(prng)), u(py(prng)), u(px(prng)), u(py(prng)))
                         : colour_code(u(sig), u(px(prng)), u(py(prng)), u(px(prng)), u(py(prng)),
                                       static_cast<std::int16_t>(angle(prng))));
    }
  }
  PixyBlockParser p;
  expect_frames_are(p.feed(stream_of(frames)), frames);
  EXPECT_EQ(p.counters().checksum_errors, 0u);
  EXPECT_EQ(p.counters().bytes_skipped, 0u);
}

TEST(PixyProtocol, EverySplitPointAndByteByByteGiveTheSameFrames) {
  const Bytes bytes = stream_of(sample_frames());
  const ParseResult whole = parse_whole(bytes);
  expect_frames_are(whole.frames, sample_frames());
  for (std::size_t k = 0; k <= bytes.size(); ++k) {
    const ParseResult split = parse_split(bytes, {k});
    SCOPED_TRACE("split at " + std::to_string(k));
    expect_same_frames(split.frames, whole.frames);
    expect_same_counters(split.counters, whole.counters);
  }
  std::vector<std::size_t> every;
  for (std::size_t k = 1; k < bytes.size(); ++k) every.push_back(k);
  const ParseResult bytewise = parse_split(bytes, every);
  expect_same_frames(bytewise.frames, whole.frames);
  expect_same_counters(bytewise.counters, whole.counters);
}

TEST(PixyProtocol, RandomChunkingGivesTheSameFrames) {
  // A stream with garbage, zeros and a bad checksum, so that the resync paths
  // are chunked too.
  Bytes bytes = stream_of(sample_frames());
  bytes.insert(bytes.begin() + 40, {0x13, 0xaa, 0x00, 0x55});
  bytes.insert(bytes.begin() + 20, {0x00, 0x00, 0x00, 0x00});
  bytes[70] ^= 0x01;
  bytes.insert(bytes.begin(), {0xaa, 0x56, 0x11});
  const ParseResult whole = parse_whole(bytes);
  EXPECT_GT(whole.counters.bytes_skipped, 0u);
  std::mt19937 prng(7);
  std::uniform_int_distribution<std::size_t> step(0, 24);
  for (int trial = 0; trial < 500; ++trial) {
    std::vector<std::size_t> cuts;
    for (std::size_t c = step(prng); c < bytes.size(); c += step(prng)) cuts.push_back(c);
    const ParseResult r = parse_split(bytes, cuts);
    expect_same_frames(r.frames, whole.frames);
    expect_same_counters(r.counters, whole.counters);
  }
}

TEST(PixyProtocol, SkipsGarbageBeforeAndBetweenBlocks) {
  // Garbage without a sync or zero word in it (but with lone 0x55/0xaa bytes and
  // the byte-swapped sync 0xaa 0x55).
  const Bytes garbage = {0x01, 0xaa, 0x55, 0x13, 0x55, 0x77, 0xaa, 0xff, 0x56};
  const PixyBlock a = normal(1, 100, 80, 10, 21), b = colour_code(012, 200, 60, 20, 44, 15);
  const PixyBlock c = normal(4, 30, 40, 5, 10);
  const Bytes start = {0x55, 0xaa};
  const Bytes bytes = concat({garbage, start, block_bytes(a), garbage, block_bytes(b), garbage, block_bytes(c),
                              garbage, start, block_bytes(a), start, start});
  PixyBlockParser p;
  const std::vector<PixyFrame> frames = p.feed(bytes);
  expect_frames_are(frames, {{a, b, c}, {a}});
  EXPECT_EQ(p.counters().bytes_skipped, 4 * garbage.size());
  EXPECT_EQ(p.counters().resyncs, 4u);
  EXPECT_EQ(p.counters().checksum_errors, 0u);
  expect_bytes_add_up(p);
}

TEST(PixyProtocol, CorruptedChecksumDropsExactlyThatBlock) {
  const auto frames = sample_frames();
  const Bytes clean = stream_of(frames);
  // Locate every block's checksum word in the stream.
  std::vector<std::pair<std::size_t, std::size_t>> where;  // (frame, block)
  std::vector<std::size_t> checksum_at;
  std::size_t pos = 0;
  for (std::size_t f = 0; f < frames.size(); ++f) {
    pos += 2;  // frame start
    for (std::size_t i = 0; i < frames[f].size(); ++i) {
      where.emplace_back(f, i);
      checksum_at.push_back(pos + 2);
      pos += frames[f][i].colour_code ? kPixyColourCodeBlockBytes : kPixyNormalBlockBytes;
    }
  }
  for (std::size_t k = 0; k < where.size(); ++k) {
    for (std::size_t which : {std::size_t{0}, std::size_t{1}, std::size_t{4}}) {  // checksum lo, hi, x lo
      Bytes bytes = clean;
      bytes[checksum_at[k] + which] ^= 0x01;
      PixyBlockParser p;
      const std::vector<PixyFrame> got = p.feed(bytes);
      auto want = frames;
      want[where[k].first].erase(want[where[k].first].begin() + static_cast<std::ptrdiff_t>(where[k].second));
      SCOPED_TRACE("block " + std::to_string(k) + " byte " + std::to_string(which));
      ASSERT_EQ(got.size(), want.size());
      expect_frames_are(got, want);
      EXPECT_EQ(p.counters().checksum_errors, 1u);
      EXPECT_EQ(got[where[k].first].checksum_errors, 1u);
      EXPECT_EQ(p.counters().blocks_ok, 8u);
      expect_bytes_add_up(p);
    }
  }
}

TEST(PixyProtocol, RecoversFromOddByteOffsets) {
  const auto frames = sample_frames();
  const Bytes clean = stream_of(frames);
  for (const Bytes& prefix : {Bytes{0xaa}, Bytes{0x55}, Bytes{0x56}, Bytes{0x00}, Bytes{0x12, 0x34, 0xaa}}) {
    PixyBlockParser p;
    expect_frames_are(p.feed(concat({prefix, clean})), frames);
    EXPECT_EQ(p.counters().bytes_skipped, prefix.size());
    EXPECT_EQ(p.counters().resyncs, 1u);
  }
  // Stream joined one byte late: the first frame start is cut, so the first
  // frame's blocks are outside any frame; the rest are whole.
  PixyBlockParser late;
  const std::vector<PixyFrame> got = late.feed(clean.data() + 1, clean.size() - 1);
  expect_frames_are(got, {frames.begin() + 1, frames.end()});
  EXPECT_EQ(late.counters().blocks_outside_frame, frames[0].size());
  EXPECT_EQ(late.counters().bytes_skipped, 1u);
}

TEST(PixyProtocol, ALostByteCostsOnlyItsBlock) {
  // Given frame 2's middle block (a normal block) losing any one of its bytes,
  const auto frames = sample_frames();
  const Bytes clean = stream_of(frames);
  const std::size_t block_start = 2 + 14 + 16 + 2 + 2 + 16;  // frames 0, 1, frame start, first block
  ASSERT_EQ(clean[block_start], 0x55);
  ASSERT_EQ(clean[block_start + 1], 0xaa);
  for (std::size_t i = 0; i < kPixyNormalBlockBytes; ++i) {
    Bytes bytes = clean;
    bytes.erase(bytes.begin() + static_cast<std::ptrdiff_t>(block_start + i));
    PixyBlockParser p;
    const std::vector<PixyFrame> got = p.feed(bytes);
    // then only that block is missing.
    auto want = frames;
    want[2].erase(want[2].begin() + 1);
    SCOPED_TRACE("lost byte " + std::to_string(i));
    expect_frames_are(got, want);
    EXPECT_GT(p.counters().bytes_skipped, 0u);
    expect_bytes_add_up(p);
  }
}

TEST(PixyProtocol, IgnoresZeroWords) {
  const auto frames = sample_frames();
  const Bytes zeros = {0x00, 0x00, 0x00, 0x00, 0x00, 0x00};  // three idle words
  Bytes bytes = zeros;
  std::size_t inserted = 3;
  for (const auto& f : frames) {
    bytes.insert(bytes.end(), {0x55, 0xaa});  // frame start
    bytes.insert(bytes.end(), zeros.begin(), zeros.end());
    inserted += 3;
    for (const PixyBlock& b : f) {
      const Bytes bb = block_bytes(b);
      bytes.insert(bytes.end(), bb.begin(), bb.end());
      bytes.insert(bytes.end(), zeros.begin(), zeros.begin() + 2);
      inserted += 1;
    }
  }
  bytes.insert(bytes.end(), {0x55, 0xaa, 0x55, 0xaa});  // next frame start
  PixyBlockParser p;
  expect_frames_are(p.feed(bytes), frames);
  EXPECT_EQ(p.counters().zero_words, inserted);
  EXPECT_EQ(p.counters().bytes_skipped, 0u);
  EXPECT_EQ(p.counters().checksum_errors, 0u);
  expect_bytes_add_up(p);
}

TEST(PixyProtocol, DeliversEmptyFramesAndFlushesTheOpenOne) {
  const PixyBlock a = normal(1, 100, 80, 10, 21);
  const Bytes bytes = concat({encode_frame({}), encode_frame({}), encode_frame({a}), encode_frame({})});
  PixyBlockParser p;
  std::vector<PixyFrame> got;
  p.feed(bytes.data(), bytes.size(), [&got](PixyFrame&& f) { got.push_back(std::move(f)); });
  // The trailing lone frame start waits for the word after it.
  expect_frames_are(got, {{}, {}});
  const Bytes idle = {0x00, 0x00};
  got = p.feed(idle);
  ASSERT_EQ(got.size(), 1u);
  EXPECT_EQ(got[0].index, 2u);
  EXPECT_EQ(got[0].blocks, std::vector<PixyBlock>{a});
  // The empty frame opened by the last frame start comes out on flush().
  const std::optional<PixyFrame> last = p.flush();
  ASSERT_TRUE(last.has_value());
  EXPECT_EQ(last->index, 3u);
  EXPECT_TRUE(last->blocks.empty());
  EXPECT_FALSE(p.flush().has_value());
  EXPECT_EQ(p.counters().frames, 4u);
  // A block after flush() and before the next frame start is outside any frame.
  p.feed(block_bytes(a));
  EXPECT_EQ(p.counters().blocks_outside_frame, 1u);
  expect_bytes_add_up(p);
}

// Valid blocks that never meet a frame start (a broken or hostile sender) do
// not grow the open frame without end: past the limit they are counted and dropped.
TEST(PixyProtocol, AFrameKeepsAtMostTheBlockLimitAndCountsTheRest) {
  const PixyBlock a = normal(1, 100, 80, 10, 20);
  std::vector<std::uint8_t> bytes = encode_frame({});
  for (std::size_t i = 0; i < kPixyMaxBlocksPerFrame + 100; ++i) encode_block(a, bytes);
  PixyBlockParser p;
  EXPECT_TRUE(p.feed(bytes).empty());
  const std::optional<PixyFrame> frame = p.flush();
  ASSERT_TRUE(frame.has_value());
  EXPECT_EQ(frame->blocks.size(), kPixyMaxBlocksPerFrame);
  EXPECT_EQ(p.counters().blocks_over_frame_limit, 100u);
  EXPECT_EQ(p.counters().blocks_ok, kPixyMaxBlocksPerFrame + 100);
  // The next frame starts with a clean count.
  std::vector<std::uint8_t> next = encode_frame({a, a});
  p.feed(next);
  const std::optional<PixyFrame> second = p.flush();
  ASSERT_TRUE(second.has_value());
  EXPECT_EQ(second->blocks.size(), 2u);
  expect_bytes_add_up(p);
}

TEST(PixyProtocol, ColourCodeWithZeroChecksumRoundTrips) {
  // 012 + 50 + 50 + 30 + 40 = 180; angle -180 makes the sum 0.
  const PixyBlock z = colour_code(012, 50, 50, 30, 40, -180);
  ASSERT_EQ(pixy_block_checksum(z), 0u);
  PixyBlockParser p;
  expect_frames_are(p.feed(stream_of({{z}})), {{z}});
}

TEST(PixyProtocol, EncoderRefusesBlocksTheStreamCannotCarry) {
  EXPECT_THROW(encode_frame({normal(0, 1, 1, 1, 1)}), std::invalid_argument);
  EXPECT_THROW(encode_frame({normal(1, 0xaa54, 0, 0, 0)}), std::invalid_argument);  // checksum 0xaa55
  EXPECT_THROW(encode_frame({colour_code(012, 0xaa4c, 0, 0, 0, 0)}), std::invalid_argument);  // 0xaa56
  EXPECT_THROW(encode_frame({normal(1, 0xffff, 0, 0, 0)}), std::invalid_argument);  // normal, checksum 0
}

TEST(PixyProtocol, ZeroSignatureBlockIsRejected) {
  // A sync followed by zeros matches its (zero) checksum but is no detection.
  const Bytes bytes = concat({{0x55, 0xaa}, {0x56, 0xaa}, Bytes(14, 0x00), block_bytes(normal(2, 9, 9, 3, 6)),
                              {0x55, 0xaa, 0x55, 0xaa}});
  PixyBlockParser p;
  expect_frames_are(p.feed(bytes), {{normal(2, 9, 9, 3, 6)}});
  EXPECT_EQ(p.counters().zero_signature_blocks, 1u);
  expect_bytes_add_up(p);
}

TEST(PixyProtocol, FuzzedBuffersNeverBreakTheCounters) {
  std::mt19937 prng(20240611);
  std::uniform_int_distribution<int> len(0, 300), any(0, 255), pick(0, 9), chunk(0, 37);
  const std::uint8_t special[] = {0x55, 0xaa, 0x56, 0x00};
  const auto stream = stream_of(sample_frames());
  std::uint64_t total_blocks = 0, total_frames = 0;
  for (int trial = 0; trial < 10000; ++trial) {
    // Random bytes biased towards sync and zero bytes, sometimes with a piece
    // of a valid stream in them.
    Bytes bytes(static_cast<std::size_t>(len(prng)));
    for (auto& b : bytes) {
      const int r = pick(prng);
      b = r < 4 ? special[r] : static_cast<std::uint8_t>(any(prng));
    }
    if (trial % 3 == 0 && !bytes.empty()) {
      const std::size_t at = static_cast<std::size_t>(any(prng)) % bytes.size();
      bytes.insert(bytes.begin() + static_cast<std::ptrdiff_t>(at), stream.begin(),
                   stream.begin() + static_cast<std::ptrdiff_t>(static_cast<std::size_t>(any(prng)) % stream.size()));
    }

    PixyBlockParser whole;
    std::vector<PixyFrame> want = whole.feed(bytes);

    PixyBlockParser p;
    std::vector<PixyFrame> got;
    for (std::size_t i = 0; i < bytes.size();) {
      const std::size_t n = std::min<std::size_t>(static_cast<std::size_t>(chunk(prng)), bytes.size() - i);
      for (PixyFrame& f : p.feed(bytes.data() + i, n)) got.push_back(std::move(f));
      i += n;
      expect_bytes_add_up(p);
    }
    expect_same_frames(got, want);
    expect_same_counters(p.counters(), whole.counters());

    const PixyParserCounters c = p.counters();
    std::uint64_t in_frames = 0;
    for (std::size_t i = 0; i < got.size(); ++i) {
      EXPECT_EQ(got[i].index, i);
      in_frames += got[i].blocks.size();
    }
    std::uint64_t open_blocks = 0;
    const bool was_open = p.frame_open();
    if (std::optional<PixyFrame> last = p.flush()) open_blocks = last->blocks.size();
    EXPECT_EQ(c.blocks_ok, in_frames + open_blocks + c.blocks_outside_frame + c.blocks_over_frame_limit);
    EXPECT_EQ(c.frames, got.size());
    EXPECT_EQ(c.frame_syncs, got.size() + (was_open ? 1u : 0u));
    EXPECT_LE(c.colour_code_blocks_ok, c.blocks_ok);
    EXPECT_EQ(c.bytes_in, bytes.size());
    if (::testing::Test::HasFailure()) FAIL() << "trial " << trial;
    total_blocks += c.blocks_ok;
    total_frames += c.frames;
  }
  // The inserted stream pieces exercised the happy path too.
  EXPECT_GT(total_blocks, 1000u);
  EXPECT_GT(total_frames, 1000u);
}

}  // namespace
}  // namespace pixyslam::pixy
