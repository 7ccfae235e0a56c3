#pragma once

#include <cstddef>
#include <cstdint>
#include <string_view>

namespace pixyslam::mcap {

// CRC-32 as used by MCAP, zlib and PNG: reflected polynomial 0xEDB88320,
// initial value and final XOR 0xFFFFFFFF; crc32("123456789") == 0xCBF43926.
// Incremental: crc32(b, crc32(a)) == crc32(a followed by b); start from 0.
std::uint32_t crc32(const std::uint8_t* data, std::size_t size, std::uint32_t previous = 0);
std::uint32_t crc32(std::string_view bytes, std::uint32_t previous = 0);

}  // namespace pixyslam::mcap
