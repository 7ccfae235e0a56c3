#pragma once

#include <cstddef>
#include <string>
#include <string_view>

namespace pixyslam::dds {

// Text another participant sent (a robot_id, a participant's name or
// properties) made fit for a log line: control bytes, which could drive the
// reader's terminal (escape sequences), become '?', and at most max_bytes are
// kept ("..." marks a cut).
inline std::string printable(std::string_view text, std::size_t max_bytes = 64) {
  std::string out;
  const std::size_t n = text.size() <= max_bytes ? text.size() : max_bytes;
  out.reserve(n + 3);
  for (std::size_t i = 0; i < n; ++i) {
    const auto c = static_cast<unsigned char>(text[i]);
    out.push_back(c < 0x20 || c == 0x7f ? '?' : static_cast<char>(c));
  }
  if (n < text.size()) out += "...";
  return out;
}

}  // namespace pixyslam::dds
