#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

namespace pixyslam::encoder {

// The Arduino -> Pi encoder line protocol (full text: docs/arduino_protocol.md).
//
//   line     = "$" body "*" HEX HEX ( "\r\n" | "\n" )
//   body     = "ENC," u32 "," u32 "," i32 "," i32      seq, arduino_time_us, left, right
//            | "RST," version "," u32                  firmware version, ticks per revolution
//   checksum = XOR of every byte of `body` (between '$' and '*'), two hex digits
//   u32      = 1 to 10 decimal digits, value <= 4294967295
//   i32      = [ "-" ] 1 to 10 decimal digits, value in [-2147483648, 2147483647]
//   version  = 1 to 16 of [0-9A-Za-z._-]
//
// e.g. "$ENC,1,20000,12,-7*52\r\n" and "$ENC,0,0,0,0*48\r\n".

// Longest line kept, from '$' up to and including the '\n'. The longest valid
// ENC line is 55 bytes, the longest valid RST line 37.
inline constexpr std::size_t kArduinoMaxLineBytes = 80;
inline constexpr std::size_t kArduinoMaxVersionChars = 16;

// One encoder sample exactly as the Arduino sent it: cumulative tick counters
// that wrap modulo 2^32, and the Arduino's micros() clock, which wraps every
// 2^32 us (~71.6 min). seq counts lines since the Arduino booted, from 0.
struct EncoderSample {
  std::uint32_t seq = 0;
  std::uint32_t arduino_time_us = 0;
  std::int32_t left_ticks = 0;
  std::int32_t right_ticks = 0;

  friend bool operator==(const EncoderSample& a, const EncoderSample& b) {
    return a.seq == b.seq && a.arduino_time_us == b.arduino_time_us &&
           a.left_ticks == b.left_ticks && a.right_ticks == b.right_ticks;
  }
  friend bool operator!=(const EncoderSample& a, const EncoderSample& b) { return !(a == b); }
};

// The hello line the sketch sends once after boot: counters, clock and seq
// restart from 0. ticks_per_revolution is the firmware's compiled-in value
// (0 = not known to the firmware).
struct EncoderReset {
  std::string firmware_version;
  std::uint32_t ticks_per_revolution = 0;

  friend bool operator==(const EncoderReset& a, const EncoderReset& b) {
    return a.firmware_version == b.firmware_version &&
           a.ticks_per_revolution == b.ticks_per_revolution;
  }
  friend bool operator!=(const EncoderReset& a, const EncoderReset& b) { return !(a == b); }
};

using ArduinoMessage = std::variant<EncoderSample, EncoderReset>;

// Running totals since construction. Every line that starts with '$' ends as
// exactly one of: a sample, a reset, or one of the rejection counters.
struct ArduinoParserCounters {
  std::uint64_t bytes_in = 0;
  std::uint64_t bytes_skipped = 0;  // outside any line: garbage before '$', blank line ends,
                                    // the tail of an over-long line
  std::uint64_t samples = 0;        // valid ENC lines
  std::uint64_t resets = 0;         // valid RST lines
  std::uint64_t bad_framing = 0;    // no '*', or not exactly two hex digits after it
  std::uint64_t bad_checksum = 0;   // framing fine, XOR does not match
  std::uint64_t unknown_type = 0;   // checksum fine, tag neither ENC nor RST
  std::uint64_t wrong_field_count = 0;  // ENC without 4 fields, RST without 2
  std::uint64_t bad_field = 0;      // a field that is not a number in range (or a bad version)
  std::uint64_t overlong_lines = 0;     // no '\n' within kArduinoMaxLineBytes
  std::uint64_t unterminated_lines = 0;  // a new '$' arrived before the line's '\n'

  std::uint64_t rejected_lines() const {
    return bad_framing + bad_checksum + unknown_type + wrong_field_count + bad_field +
           overlong_lines + unterminated_lines;
  }
};

// Incremental parser of the line protocol above. Bytes may be fed in chunks of
// any size split anywhere: the messages and counters depend only on the
// concatenated bytes. Never throws on any input and never buffers more than
// kArduinoMaxLineBytes. Resynchronises on every '$' (it never occurs inside a
// valid line): bytes before a '$' are skipped, a line cut short by a new '$' is
// dropped, an over-long line is dropped with everything up to the next '$' or
// '\n'. Both "\n" and "\r\n" end a line. Thread-compatible.
class ArduinoLineParser {
 public:
  using MessageCallback = std::function<void(const ArduinoMessage&)>;

  // Parses `size` bytes; calls `on_message` for every valid line completed by
  // them, in order. Exceptions from the callback propagate (the parser stays usable).
  void feed(const std::uint8_t* data, std::size_t size, const MessageCallback& on_message);
  void feed(const char* data, std::size_t size, const MessageCallback& on_message);
  // Same, returning the messages.
  std::vector<ArduinoMessage> feed(const std::uint8_t* data, std::size_t size);
  std::vector<ArduinoMessage> feed(const char* data, std::size_t size);
  std::vector<ArduinoMessage> feed(std::string_view bytes) { return feed(bytes.data(), bytes.size()); }

  const ArduinoParserCounters& counters() const { return counters_; }
  // Bytes of an unfinished line held until its '\n' arrives.
  std::size_t bytes_buffered() const;

 private:
  enum class State { kHunting, kInLine, kDiscarding };

  void end_line(const MessageCallback& on_message);

  State state_ = State::kHunting;
  std::array<char, kArduinoMaxLineBytes - 2> text_{};  // after the '$', before the '\n'
  std::size_t stored_ = 0;
  ArduinoParserCounters counters_;
};

// XOR of the bytes of `body` (the text between '$' and '*').
std::uint8_t arduino_checksum(std::string_view body);

// Complete lines ("$...*CS\r\n") as the sketch writes them; the version is
// written as given (callers keep it within the grammar).
std::string format_line(const EncoderSample& sample);
std::string format_line(const EncoderReset& reset);

}  // namespace pixyslam::encoder
