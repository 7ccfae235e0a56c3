// libFuzzer target: arbitrary serial bytes into the Arduino line parser, in
// chunks whose sizes come from the input (a line may be cut anywhere). The
// parser must never crash, never buffer more than one line, deliver what its
// counters say, and end every line it closed (each began with a '$') as
// exactly one message or rejection.

#include <algorithm>
#include <cstddef>
#include <cstdint>

#include "fuzz_common.h"
#include "pixyslam/encoder/arduino_line_parser.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  pixyslam::encoder::ArduinoLineParser parser;
  const std::size_t chunk = 1 + data[0] % 64;
  std::size_t messages = 0;
  for (std::size_t at = 1; at < size; at += chunk) {
    const std::size_t n = at + chunk <= size ? chunk : size - at;
    parser.feed(data + at, n, [&](const pixyslam::encoder::ArduinoMessage&) { ++messages; });
    FUZZ_CHECK(parser.bytes_buffered() <= pixyslam::encoder::kArduinoMaxLineBytes);
  }
  const pixyslam::encoder::ArduinoParserCounters& c = parser.counters();
  const auto dollars = static_cast<std::uint64_t>(std::count(data + 1, data + size, '$'));
  FUZZ_CHECK(messages == c.samples + c.resets);
  FUZZ_CHECK(c.samples + c.resets + c.rejected_lines() <= dollars);
  FUZZ_CHECK(c.bytes_in == size - 1);
  return 0;
}
