#include "pixyslam/mcap/crc32.h"

#include <array>

namespace pixyslam::mcap {
namespace {

// Four tables for slicing-by-4: table[k][b] is the CRC of byte b followed by k zero bytes.
using Tables = std::array<std::array<std::uint32_t, 256>, 4>;

Tables make_tables() {
  Tables t{};
  for (std::uint32_t b = 0; b < 256; ++b) {
    std::uint32_t c = b;
    for (int bit = 0; bit < 8; ++bit) c = (c & 1u) ? (c >> 1) ^ 0xEDB88320u : c >> 1;
    t[0][b] = c;
  }
  for (std::size_t k = 1; k < 4; ++k) {
    for (std::size_t b = 0; b < 256; ++b) t[k][b] = (t[k - 1][b] >> 8) ^ t[0][t[k - 1][b] & 0xFFu];
  }
  return t;
}

const Tables& tables() {
  static const Tables t = make_tables();
  return t;
}

}  // namespace

std::uint32_t crc32(const std::uint8_t* data, std::size_t size, std::uint32_t previous) {
  const Tables& t = tables();
  std::uint32_t c = ~previous;
  std::size_t i = 0;
  for (; i + 4 <= size; i += 4) {
    c ^= static_cast<std::uint32_t>(data[i]) | static_cast<std::uint32_t>(data[i + 1]) << 8 |
         static_cast<std::uint32_t>(data[i + 2]) << 16 | static_cast<std::uint32_t>(data[i + 3]) << 24;
    c = t[3][c & 0xFFu] ^ t[2][(c >> 8) & 0xFFu] ^ t[1][(c >> 16) & 0xFFu] ^ t[0][c >> 24];
  }
  for (; i < size; ++i) c = (c >> 8) ^ t[0][(c ^ data[i]) & 0xFFu];
  return ~c;
}

std::uint32_t crc32(std::string_view bytes, std::uint32_t previous) {
  return crc32(reinterpret_cast<const std::uint8_t*>(bytes.data()), bytes.size(), previous);
}

}  // namespace pixyslam::mcap
