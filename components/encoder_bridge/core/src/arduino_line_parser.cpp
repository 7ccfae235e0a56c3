#include "pixyslam/encoder/arduino_line_parser.h"

#include <algorithm>
#include <limits>

namespace pixyslam::encoder {
namespace {

constexpr std::size_t kMaxFields = 5;  // an ENC line

bool parse_digits(std::string_view s, std::uint64_t& out) {
  if (s.empty() || s.size() > 10) return false;
  std::uint64_t v = 0;
  for (const char c : s) {
    if (c < '0' || c > '9') return false;
    v = v * 10 + static_cast<std::uint64_t>(c - '0');
  }
  out = v;
  return true;
}

bool parse_u32(std::string_view s, std::uint32_t& out) {
  std::uint64_t v = 0;
  if (!parse_digits(s, v) || v > std::numeric_limits<std::uint32_t>::max()) return false;
  out = static_cast<std::uint32_t>(v);
  return true;
}

bool parse_i32(std::string_view s, std::int32_t& out) {
  const bool negative = !s.empty() && s.front() == '-';
  if (negative) s.remove_prefix(1);
  std::uint64_t v = 0;
  if (!parse_digits(s, v)) return false;
  const std::uint64_t limit = negative ? std::uint64_t{1} << 31 : (std::uint64_t{1} << 31) - 1;
  if (v > limit) return false;
  out = negative ? static_cast<std::int32_t>(-static_cast<std::int64_t>(v)) : static_cast<std::int32_t>(v);
  return true;
}

bool valid_version(std::string_view s) {
  if (s.empty() || s.size() > kArduinoMaxVersionChars) return false;
  for (const char c : s) {
    const bool ok = (c >= '0' && c <= '9') || (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') ||
                    c == '.' || c == '_' || c == '-';
    if (!ok) return false;
  }
  return true;
}

int hex_value(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  return -1;
}

std::string with_checksum(const std::string& body) {
  static constexpr char kHex[] = "0123456789ABCDEF";
  const std::uint8_t cs = arduino_checksum(body);
  std::string line;
  line.reserve(body.size() + 6);
  line += '$';
  line += body;
  line += '*';
  line += kHex[cs >> 4];
  line += kHex[cs & 0x0f];
  line += "\r\n";
  return line;
}

}  // namespace

std::uint8_t arduino_checksum(std::string_view body) {
  std::uint8_t x = 0;
  for (const char c : body) x = static_cast<std::uint8_t>(x ^ static_cast<std::uint8_t>(c));
  return x;
}

std::string format_line(const EncoderSample& s) {
  return with_checksum("ENC," + std::to_string(s.seq) + "," + std::to_string(s.arduino_time_us) + "," +
                       std::to_string(s.left_ticks) + "," + std::to_string(s.right_ticks));
}

std::string format_line(const EncoderReset& r) {
  return with_checksum("RST," + r.firmware_version + "," + std::to_string(r.ticks_per_revolution));
}

std::size_t ArduinoLineParser::bytes_buffered() const {
  return state_ == State::kInLine ? stored_ + 1 : 0;
}

void ArduinoLineParser::feed(const char* data, std::size_t size, const MessageCallback& on_message) {
  feed(reinterpret_cast<const std::uint8_t*>(data), size, on_message);
}

std::vector<ArduinoMessage> ArduinoLineParser::feed(const std::uint8_t* data, std::size_t size) {
  std::vector<ArduinoMessage> out;
  feed(data, size, [&out](const ArduinoMessage& m) { out.push_back(m); });
  return out;
}

std::vector<ArduinoMessage> ArduinoLineParser::feed(const char* data, std::size_t size) {
  return feed(reinterpret_cast<const std::uint8_t*>(data), size);
}

void ArduinoLineParser::feed(const std::uint8_t* data, std::size_t size,
                             const MessageCallback& on_message) {
  for (std::size_t i = 0; i < size; ++i) {
    const char c = static_cast<char>(data[i]);
    ++counters_.bytes_in;
    switch (state_) {
      case State::kHunting:
      case State::kDiscarding:
        if (c == '$') {
          state_ = State::kInLine;
          stored_ = 0;
        } else {
          ++counters_.bytes_skipped;
          if (c == '\n') state_ = State::kHunting;
        }
        break;
      case State::kInLine:
        if (c == '\n') {
          end_line(on_message);
        } else if (c == '$') {
          ++counters_.unterminated_lines;  // the '$' opens the next line
          stored_ = 0;
        } else if (stored_ == text_.size()) {
          ++counters_.overlong_lines;
          ++counters_.bytes_skipped;
          state_ = State::kDiscarding;
          stored_ = 0;
        } else {
          text_[stored_++] = c;
        }
        break;
    }
  }
}

void ArduinoLineParser::end_line(const MessageCallback& on_message) {
  std::string_view text(text_.data(), stored_);
  // Leave a clean state first: the callback may throw.
  state_ = State::kHunting;
  stored_ = 0;

  if (!text.empty() && text.back() == '\r') text.remove_suffix(1);
  const std::size_t star = text.find('*');
  if (star == std::string_view::npos || text.size() - star != 3) {
    ++counters_.bad_framing;
    return;
  }
  const int hi = hex_value(text[star + 1]);
  const int lo = hex_value(text[star + 2]);
  if (hi < 0 || lo < 0) {
    ++counters_.bad_framing;
    return;
  }
  const std::string_view body = text.substr(0, star);
  if (arduino_checksum(body) != static_cast<std::uint8_t>(hi * 16 + lo)) {
    ++counters_.bad_checksum;
    return;
  }

  // Fields split at ','; the first is the type tag. Only lines with at most
  // kMaxFields fields are split (no valid line has more).
  const std::size_t n = static_cast<std::size_t>(std::count(body.begin(), body.end(), ',')) + 1;
  std::array<std::string_view, kMaxFields> field{};
  field[0] = body.substr(0, body.find(','));
  if (n <= kMaxFields) {
    std::size_t begin = 0;
    for (std::size_t k = 0; k < n; ++k) {
      const std::size_t comma = body.find(',', begin);
      field[k] = body.substr(begin, comma == std::string_view::npos ? comma : comma - begin);
      begin = comma + 1;
    }
  }

  if (field[0] == "ENC") {
    if (n != 5) {
      ++counters_.wrong_field_count;
      return;
    }
    EncoderSample s;
    if (!parse_u32(field[1], s.seq) || !parse_u32(field[2], s.arduino_time_us) ||
        !parse_i32(field[3], s.left_ticks) || !parse_i32(field[4], s.right_ticks)) {
      ++counters_.bad_field;
      return;
    }
    ++counters_.samples;
    on_message(ArduinoMessage(s));
  } else if (field[0] == "RST") {
    if (n != 3) {
      ++counters_.wrong_field_count;
      return;
    }
    EncoderReset r;
    if (!valid_version(field[1]) || !parse_u32(field[2], r.ticks_per_revolution)) {
      ++counters_.bad_field;
      return;
    }
    r.firmware_version = std::string(field[1]);
    ++counters_.resets;
    on_message(ArduinoMessage(std::move(r)));
  } else {
    ++counters_.unknown_type;
  }
}

}  // namespace pixyslam::encoder
