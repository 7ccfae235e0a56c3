// Tests of the Arduino encoder line protocol: checksum, formatting, the
// incremental parser under arbitrary splits, garbage, bad lines and over-long
// input (docs/arduino_protocol.md).

#include <algorithm>
#include <cstdint>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "pixyslam/encoder/arduino_line_parser.h"

namespace pixyslam::encoder {
namespace {

// A line with a correct checksum around an arbitrary body (the checksum itself
// is checked against hand-computed values below).
std::string line(const std::string& body, const char* end = "\r\n") {
  static const char* kHex = "0123456789ABCDEF";
  const std::uint8_t cs = arduino_checksum(body);
  return "$" + body + "*" + kHex[cs >> 4] + kHex[cs & 15] + end;
}

bool same_counters(const ArduinoParserCounters& a, const ArduinoParserCounters& b) {
  return a.bytes_in == b.bytes_in && a.bytes_skipped == b.bytes_skipped && a.samples == b.samples &&
         a.resets == b.resets && a.bad_framing == b.bad_framing && a.bad_checksum == b.bad_checksum &&
         a.unknown_type == b.unknown_type && a.wrong_field_count == b.wrong_field_count &&
         a.bad_field == b.bad_field && a.overlong_lines == b.overlong_lines &&
         a.unterminated_lines == b.unterminated_lines;
}

const EncoderSample& sample_of(const ArduinoMessage& m) { return std::get<EncoderSample>(m); }

// A stream with every kind of line: resets, samples at the extremes of their
// ranges, both line ends, garbage, and each rejection reason.
std::string mixed_stream() {
  std::string s;
  s += std::string("\x00\xff noise", 8);
  s += line("RST,1.2.0,1320");
  s += line("ENC,0,16,0,0", "\n");
  s += line("ENC,1,20016,-5,7");
  s += "$ENC,2,40016,-9,14*00\r\n";  // bad checksum
  s += line("ENC,3,60016,-14,21");
  s += line("ENC,4294967295,4294967295,2147483647,-2147483648");
  s += line("ENC,5,6,7");             // wrong field count
  s += line("ENC,5,x,7,8");           // not a number
  s += "$ENC,6,7,8";                  // unterminated: cut by the next '$'
  s += line("ENC,7,80016,-18,28");
  s += "\r\n\r\n";
  s += line("ABC,1");                 // unknown type
  s += "$ENC,8,100016,-20,30\r\n";    // no checksum
  s += line("ENC,9,120016,-25,35");
  return s;
}

std::vector<ArduinoMessage> expected_mixed() {
  return {EncoderReset{"1.2.0", 1320},
          EncoderSample{0, 16, 0, 0},
          EncoderSample{1, 20016, -5, 7},
          EncoderSample{3, 60016, -14, 21},
          EncoderSample{4294967295u, 4294967295u, 2147483647, -2147483647 - 1},
          EncoderSample{7, 80016, -18, 28},
          EncoderSample{9, 120016, -25, 35}};
}

TEST(ArduinoChecksum, MatchesTheHandComputedExamples) {
  // docs/arduino_protocol.md works these out byte by byte.
  EXPECT_EQ(arduino_checksum("ENC,1,20000,12,-7"), 0x52);
  EXPECT_EQ(arduino_checksum("ENC,0,0,0,0"), 0x48);
  EXPECT_EQ(arduino_checksum(""), 0x00);
  EXPECT_EQ(format_line(EncoderSample{1, 20000, 12, -7}), "$ENC,1,20000,12,-7*52\r\n");
  EXPECT_EQ(format_line(EncoderSample{0, 0, 0, 0}), "$ENC,0,0,0,0*48\r\n");
}

TEST(ArduinoLineParser, ParsesTheDocumentedExamples) {
  ArduinoLineParser p;
  const auto m = p.feed(std::string_view("$ENC,1,20000,12,-7*52\r\n$ENC,1,20000,12,-8*5d\n"));
  ASSERT_EQ(m.size(), 2u);
  EXPECT_EQ(sample_of(m[0]), (EncoderSample{1, 20000, 12, -7}));
  EXPECT_EQ(sample_of(m[1]), (EncoderSample{1, 20000, 12, -8}));  // lower-case hex accepted
  EXPECT_EQ(p.counters().samples, 2u);
  EXPECT_EQ(p.counters().rejected_lines(), 0u);
  EXPECT_EQ(p.counters().bytes_skipped, 0u);
}

TEST(ArduinoLineParser, ParsesResetLines) {
  ArduinoLineParser p;
  const std::string text = format_line(EncoderReset{"fw-2.1_rc.3", 1320});
  EXPECT_EQ(text, line("RST,fw-2.1_rc.3,1320"));
  const auto m = p.feed(text);
  ASSERT_EQ(m.size(), 1u);
  ASSERT_TRUE(std::holds_alternative<EncoderReset>(m[0]));
  EXPECT_EQ(std::get<EncoderReset>(m[0]), (EncoderReset{"fw-2.1_rc.3", 1320}));
  EXPECT_EQ(p.counters().resets, 1u);
}

TEST(ArduinoLineParser, FormatThenParseRoundTripsTheExtremes) {
  const std::vector<EncoderSample> samples = {
      {0, 0, 0, 0},
      {4294967295u, 4294967295u, 2147483647, -2147483647 - 1},
      {123456, 4000000000u, -1, 1},
  };
  ArduinoLineParser p;
  for (const EncoderSample& s : samples) {
    const std::string text = format_line(s);
    EXPECT_LE(text.size(), 55u);
    const auto m = p.feed(text);
    ASSERT_EQ(m.size(), 1u) << text;
    EXPECT_EQ(sample_of(m[0]), s) << text;
  }
}

TEST(ArduinoLineParser, WholeStreamGivesTheValidLinesAndCountsEachReason) {
  ArduinoLineParser p;
  const std::string s = mixed_stream();
  const auto m = p.feed(s);
  EXPECT_EQ(m, expected_mixed());
  const ArduinoParserCounters& c = p.counters();
  EXPECT_EQ(c.bytes_in, s.size());
  EXPECT_EQ(c.samples, 6u);
  EXPECT_EQ(c.resets, 1u);
  EXPECT_EQ(c.bad_checksum, 1u);
  EXPECT_EQ(c.wrong_field_count, 1u);
  EXPECT_EQ(c.bad_field, 1u);
  EXPECT_EQ(c.unterminated_lines, 1u);
  EXPECT_EQ(c.unknown_type, 1u);
  EXPECT_EQ(c.bad_framing, 1u);
  EXPECT_EQ(c.overlong_lines, 0u);
  EXPECT_EQ(c.bytes_skipped, 8u + 4u);  // the leading noise and the two blank "\r\n"
  EXPECT_EQ(p.bytes_buffered(), 0u);
}

TEST(ArduinoLineParser, SplitAtEveryPositionGivesIdenticalResults) {
  const std::string s = mixed_stream();
  ArduinoLineParser whole;
  const auto expected = whole.feed(s);
  for (std::size_t i = 0; i <= s.size(); ++i) {
    ArduinoLineParser p;
    auto got = p.feed(s.data(), i);
    const auto rest = p.feed(s.data() + i, s.size() - i);
    got.insert(got.end(), rest.begin(), rest.end());
    ASSERT_EQ(got, expected) << "split at " << i;
    ASSERT_TRUE(same_counters(p.counters(), whole.counters())) << "split at " << i;
  }
}

TEST(ArduinoLineParser, SplitInThreeAtEveryPairOfPositions) {
  std::string s;
  for (std::uint32_t k = 0; k < 3; ++k) s += format_line(EncoderSample{k, 20000 * k, -3 * int(k), 4 * int(k)});
  ArduinoLineParser whole;
  const auto expected = whole.feed(s);
  ASSERT_EQ(expected.size(), 3u);
  for (std::size_t i = 0; i <= s.size(); ++i) {
    for (std::size_t j = i; j <= s.size(); ++j) {
      ArduinoLineParser p;
      std::vector<ArduinoMessage> got;
      const auto keep = [&got](const ArduinoMessage& m) { got.push_back(m); };
      p.feed(s.data(), i, keep);
      p.feed(s.data() + i, j - i, keep);
      p.feed(s.data() + j, s.size() - j, keep);
      ASSERT_EQ(got, expected) << "splits at " << i << ", " << j;
    }
  }
}

TEST(ArduinoLineParser, ByteByByteGivesIdenticalResults) {
  const std::string s = mixed_stream();
  ArduinoLineParser whole;
  const auto expected = whole.feed(s);
  ArduinoLineParser p;
  std::vector<ArduinoMessage> got;
  for (const char c : s) {
    const auto m = p.feed(&c, 1);
    got.insert(got.end(), m.begin(), m.end());
  }
  EXPECT_EQ(got, expected);
  EXPECT_TRUE(same_counters(p.counters(), whole.counters()));
}

TEST(ArduinoLineParser, GarbageAndBadChecksumsAreSkippedAndLaterLinesParsed) {
  // Given a good line, binary garbage, a line with one flipped digit and a good line,
  // when fed, then both good lines come out and the damaged one is counted.
  std::string bad = format_line(EncoderSample{11, 220000, 50, 60});
  bad[5] = '2';  // "$ENC,21,..." with the checksum of seq 11
  const std::string s = format_line(EncoderSample{10, 200000, 40, 50}) + "\x01\x02garbage*,,\x7f" + bad +
                        "more junk" + format_line(EncoderSample{12, 240000, 60, 70});
  ArduinoLineParser p;
  const auto m = p.feed(s);
  ASSERT_EQ(m.size(), 2u);
  EXPECT_EQ(sample_of(m[0]).seq, 10u);
  EXPECT_EQ(sample_of(m[1]).seq, 12u);
  EXPECT_EQ(p.counters().bad_checksum, 1u);
  EXPECT_EQ(p.counters().bytes_skipped, 13u + 9u);
  EXPECT_EQ(p.counters().rejected_lines(), 1u);
}

TEST(ArduinoLineParser, EachRejectionReasonIsCountedSeparately) {
  struct Case {
    std::string text;
    std::uint64_t ArduinoParserCounters::*counter;
  };
  const std::vector<Case> cases = {
      {"$ENC,0,0,0,0\r\n", &ArduinoParserCounters::bad_framing},     // no '*'
      {"$ENC,0,0,0,0*4\r\n", &ArduinoParserCounters::bad_framing},   // one digit
      {"$ENC,0,0,0,0*48x\r\n", &ArduinoParserCounters::bad_framing},  // text after it
      {"$ENC,0,0,0,0*G8\r\n", &ArduinoParserCounters::bad_framing},  // not hex
      {"$ENC,0,0,0,0*48\r\r\n", &ArduinoParserCounters::bad_framing},
      {"$ENC,0,0,0,0*49\r\n", &ArduinoParserCounters::bad_checksum},
      {line("XYZ,1,2,3,4"), &ArduinoParserCounters::unknown_type},
      {line("enc,0,0,0,0"), &ArduinoParserCounters::unknown_type},
      {line(""), &ArduinoParserCounters::unknown_type},
      {line("ENC,1,2,3"), &ArduinoParserCounters::wrong_field_count},
      {line("ENC,1,2,3,4,5"), &ArduinoParserCounters::wrong_field_count},
      {line("ENC,1,2,3,4,5,6,7,8"), &ArduinoParserCounters::wrong_field_count},
      {line("RST,1.0"), &ArduinoParserCounters::wrong_field_count},
      {line("ENC,4294967296,0,0,0"), &ArduinoParserCounters::bad_field},  // > u32
      {line("ENC,0,0,2147483648,0"), &ArduinoParserCounters::bad_field},  // > i32
      {line("ENC,0,0,0,-2147483649"), &ArduinoParserCounters::bad_field},
      {line("ENC,0,0,+5,0"), &ArduinoParserCounters::bad_field},
      {line("ENC,0,0, 5,0"), &ArduinoParserCounters::bad_field},
      {line("ENC,0,0,-,0"), &ArduinoParserCounters::bad_field},
      {line("ENC,0,,0,0"), &ArduinoParserCounters::bad_field},
      {line("ENC,-1,0,0,0"), &ArduinoParserCounters::bad_field},  // seq is unsigned
      {line("ENC,00000000001,0,0,0"), &ArduinoParserCounters::bad_field},  // 11 digits
      {line("ENC,0,0,0x10,0"), &ArduinoParserCounters::bad_field},
      {line("RST,1 0,1320"), &ArduinoParserCounters::bad_field},
      {line("RST,,1320"), &ArduinoParserCounters::bad_field},
      {line("RST,12345678901234567,1320"), &ArduinoParserCounters::bad_field},  // 17 chars
      {line("RST,1.0,-1"), &ArduinoParserCounters::bad_field},
  };
  for (const Case& c : cases) {
    ArduinoLineParser p;
    const std::string good = format_line(EncoderSample{1, 2, 3, 4});
    const auto m = p.feed(c.text + good);
    ASSERT_EQ(m.size(), 1u) << c.text;
    EXPECT_EQ(sample_of(m[0]), (EncoderSample{1, 2, 3, 4})) << c.text;
    EXPECT_EQ(p.counters().*c.counter, 1u) << c.text;
    EXPECT_EQ(p.counters().rejected_lines(), 1u) << c.text;
  }
}

TEST(ArduinoLineParser, AcceptsLeadingZerosAndNegativeZero) {
  ArduinoLineParser p;
  const auto m = p.feed(line("ENC,0000000007,0020000,-0,-0000000012"));
  ASSERT_EQ(m.size(), 1u);
  EXPECT_EQ(sample_of(m[0]), (EncoderSample{7, 20000, 0, -12}));
}

TEST(ArduinoLineParser, OverlongLineIsDroppedWithBoundedMemory) {
  // Given a '$' followed by 10000 bytes without '\n', then a good line: the buffer
  // never exceeds the line limit, one over-long line is counted, and the good
  // line after it is parsed.
  std::string s = "$" + std::string(10000, 'A') + format_line(EncoderSample{3, 4, 5, 6});
  ArduinoLineParser p;
  std::vector<ArduinoMessage> got;
  std::size_t most_buffered = 0;
  for (const char c : s) {
    p.feed(&c, 1, [&got](const ArduinoMessage& m) { got.push_back(m); });
    most_buffered = std::max(most_buffered, p.bytes_buffered());
  }
  EXPECT_LE(most_buffered, kArduinoMaxLineBytes);
  EXPECT_GT(most_buffered, 50u);  // a whole valid line does fit
  ASSERT_EQ(got.size(), 1u);
  EXPECT_EQ(sample_of(got[0]), (EncoderSample{3, 4, 5, 6}));
  EXPECT_EQ(p.counters().overlong_lines, 1u);
  EXPECT_EQ(p.counters().rejected_lines(), 1u);
  // The '$' and the 78 bytes held are the dropped line; the rest is skipped.
  EXPECT_EQ(p.counters().bytes_skipped, 10000u - (kArduinoMaxLineBytes - 2));
}

TEST(ArduinoLineParser, OverlongLineEndsAtTheNextNewline) {
  std::string s = "$" + std::string(500, '7') + "\r\n" + "tail" + format_line(EncoderSample{1, 1, 1, 1});
  ArduinoLineParser p;
  const auto m = p.feed(s);
  ASSERT_EQ(m.size(), 1u);
  EXPECT_EQ(p.counters().overlong_lines, 1u);
  EXPECT_EQ(p.counters().rejected_lines(), 1u);
}

TEST(ArduinoLineParser, LongestLegalLineIsKept) {
  // A line of exactly kArduinoMaxLineBytes (with "\r\n") reaches the checksum check.
  const std::string body = "ENC," + std::string(kArduinoMaxLineBytes - 10, '1');
  const std::string text = line(body);
  ASSERT_EQ(text.size(), kArduinoMaxLineBytes);
  ArduinoLineParser p;
  p.feed(text);
  EXPECT_EQ(p.counters().overlong_lines, 0u);
  EXPECT_EQ(p.counters().wrong_field_count, 1u);
  ArduinoLineParser q;
  q.feed(line(body + "1"));  // one byte more
  EXPECT_EQ(q.counters().overlong_lines, 1u);
}

TEST(ArduinoLineParser, RandomBytesNeverThrowAndEveryLineIsAccountedFor) {
  // Every '$' opens a line that ends as a message or exactly one rejection,
  // except a line still open at the end.
  std::mt19937 prng(42);
  const std::string alphabet = "$$**,,,\r\n\n0123456789-ENCRSTabc";
  std::uniform_int_distribution<int> pick(0, static_cast<int>(alphabet.size()) + 20);
  std::string s;
  for (int i = 0; i < 200000; ++i) {
    const int k = pick(prng);
    s += k < static_cast<int>(alphabet.size()) ? alphabet[static_cast<std::size_t>(k)]
                                               : static_cast<char>(prng() & 0xff);
    if (i % 997 == 0) s += format_line(EncoderSample{static_cast<std::uint32_t>(i), 1, 2, 3});
  }
  ArduinoLineParser p;
  std::size_t dollars = 0;
  for (const char c : s) dollars += c == '$';
  std::size_t most_buffered = 0;
  EXPECT_NO_THROW(for (std::size_t i = 0; i < s.size(); i += 37) {
    p.feed(s.data() + i, std::min<std::size_t>(37, s.size() - i), [](const ArduinoMessage&) {});
    most_buffered = std::max(most_buffered, p.bytes_buffered());
  });
  EXPECT_LE(most_buffered, kArduinoMaxLineBytes);
  const ArduinoParserCounters& c = p.counters();
  EXPECT_EQ(c.bytes_in, s.size());
  EXPECT_GE(c.samples, 150u);  // the embedded good lines (most survive the noise)
  EXPECT_EQ(c.samples + c.resets + c.rejected_lines() + (p.bytes_buffered() > 0 ? 1 : 0), dollars);
}

}  // namespace
}  // namespace pixyslam::encoder
