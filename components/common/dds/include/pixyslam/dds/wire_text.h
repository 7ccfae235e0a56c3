#pragma once

#include <cstddef>
#include <string>
#include <string_view>

namespace pixyslam::dds {

// Length (1-4) of the well-formed UTF-8 sequence starting at text[i], its code
// point in *code_point; 0 when the bytes there are not one (RFC 3629: no
// overlong forms, no surrogates, nothing above U+10FFFF, no cut sequence).
inline std::size_t utf8_sequence(std::string_view text, std::size_t i, char32_t* code_point) {
  const auto byte = [&](std::size_t k) { return static_cast<unsigned char>(text[k]); };
  const unsigned char lead = byte(i);
  std::size_t length = 0;
  char32_t cp = 0;
  char32_t min = 0;
  if (lead < 0x80) {
    *code_point = lead;
    return 1;
  } else if (lead >= 0xc2 && lead <= 0xdf) {
    length = 2, cp = lead & 0x1fu, min = 0x80;
  } else if (lead >= 0xe0 && lead <= 0xef) {
    length = 3, cp = lead & 0x0fu, min = 0x800;
  } else if (lead >= 0xf0 && lead <= 0xf4) {
    length = 4, cp = lead & 0x07u, min = 0x10000;
  } else {
    return 0;  // a continuation byte, or a lead byte no code point starts with
  }
  if (text.size() - i < length) return 0;
  for (std::size_t k = 1; k < length; ++k) {
    if ((byte(i + k) & 0xc0u) != 0x80u) return 0;
    cp = (cp << 6) | (byte(i + k) & 0x3fu);
  }
  if (cp < min || cp > 0x10ffff || (cp >= 0xd800 && cp <= 0xdfff)) return 0;
  *code_point = cp;
  return length;
}

// A code point that a terminal may act on: C0, DEL and C1 (U+0080-U+009F, of
// which U+009B is an 8-bit escape-sequence start).
inline bool control_code_point(char32_t cp) { return cp < 0x20 || (cp >= 0x7f && cp <= 0x9f); }

// Text another participant sent (a robot_id, a participant's name or
// properties) made fit for a log line: control characters, which could drive
// the reader's terminal (escape sequences), and bytes that are not UTF-8
// become '?', and at most max_bytes are kept, cut between characters ("..."
// marks a cut).
inline std::string printable(std::string_view text, std::size_t max_bytes = 64) {
  std::string out;
  out.reserve((text.size() <= max_bytes ? text.size() : max_bytes) + 3);
  std::size_t i = 0;
  while (i < text.size()) {
    char32_t cp = 0;
    const std::size_t length = utf8_sequence(text, i, &cp);
    const bool plain = length > 0 && !control_code_point(cp);
    const std::size_t kept = plain ? length : 1;
    if (out.size() + kept > max_bytes) break;
    if (plain) {
      out.append(text.substr(i, length));
    } else {
      out.push_back('?');
    }
    i += length > 0 ? length : 1;
  }
  if (i < text.size()) out += "...";
  return out;
}

}  // namespace pixyslam::dds
