#include <stdexcept>
#include <string>
#include <vector>

#include "mcap_format.h"

#ifdef PIXYSLAM_MCAP_HAVE_ZSTD
#include <zstd.h>
#endif
#ifdef PIXYSLAM_MCAP_HAVE_LZ4
#include <lz4frame.h>
#endif

namespace pixyslam::mcap::detail {
namespace {

#ifdef PIXYSLAM_MCAP_HAVE_ZSTD
std::vector<std::uint8_t> zstd_compress(const std::vector<std::uint8_t>& in, int level) {
  std::vector<std::uint8_t> out(ZSTD_compressBound(in.size()));
  const std::size_t n =
      ZSTD_compress(out.data(), out.size(), in.data(), in.size(), level == 0 ? ZSTD_CLEVEL_DEFAULT : level);
  if (ZSTD_isError(n))
    throw std::runtime_error(std::string("zstd compression failed: ") + ZSTD_getErrorName(n));
  out.resize(n);
  return out;
}

std::vector<std::uint8_t> zstd_decompress(const std::uint8_t* data, std::size_t size, std::size_t expected) {
  // The sizes the frame headers state, checked before allocating (a damaged
  // uncompressed_size must not cost a gigabyte of zeroed memory).
  unsigned long long stated = 0;
  bool all_stated = true;
  for (std::size_t at = 0; at < size;) {
    const unsigned long long content = ZSTD_getFrameContentSize(data + at, size - at);
    const std::size_t frame = ZSTD_findFrameCompressedSize(data + at, size - at);
    if (content == ZSTD_CONTENTSIZE_ERROR || ZSTD_isError(frame)) {
      throw std::runtime_error("zstd: not a valid zstd frame at byte " + std::to_string(at) + " of the records");
    }
    if (content == ZSTD_CONTENTSIZE_UNKNOWN) all_stated = false;
    stated += content == ZSTD_CONTENTSIZE_UNKNOWN ? 0 : content;
    at += frame;
  }
  if (all_stated && stated != expected) {
    throw std::runtime_error("zstd frames hold " + std::to_string(stated) + " bytes, uncompressed_size says " +
                             std::to_string(expected));
  }
  std::vector<std::uint8_t> out(expected);
  const std::size_t n = ZSTD_decompress(out.data(), out.size(), data, size);
  if (ZSTD_isError(n)) throw std::runtime_error(std::string("zstd: ") + ZSTD_getErrorName(n));
  if (n != expected) {
    throw std::runtime_error("zstd data decodes to " + std::to_string(n) + " bytes, uncompressed_size says " +
                             std::to_string(expected));
  }
  return out;
}
#endif

#ifdef PIXYSLAM_MCAP_HAVE_LZ4
std::vector<std::uint8_t> lz4_compress(const std::vector<std::uint8_t>& in, int level) {
  LZ4F_preferences_t prefs{};
  prefs.compressionLevel = level;
  prefs.frameInfo.contentSize = in.size();
  std::vector<std::uint8_t> out(LZ4F_compressFrameBound(in.size(), &prefs));
  const std::size_t n = LZ4F_compressFrame(out.data(), out.size(), in.data(), in.size(), &prefs);
  if (LZ4F_isError(n))
    throw std::runtime_error(std::string("lz4 compression failed: ") + LZ4F_getErrorName(n));
  out.resize(n);
  return out;
}

std::vector<std::uint8_t> lz4_decompress(const std::uint8_t* data, std::size_t size, std::size_t expected) {
  LZ4F_dctx* ctx = nullptr;
  if (LZ4F_isError(LZ4F_createDecompressionContext(&ctx, LZ4F_VERSION))) {
    throw std::runtime_error("lz4: cannot create a decompression context");
  }
  // The content size the frame header states (0: not stated), checked before allocating.
  LZ4F_frameInfo_t frame{};
  std::size_t in_pos = size;
  std::size_t hint = LZ4F_getFrameInfo(ctx, &frame, data, &in_pos);
  std::string error;
  if (LZ4F_isError(hint)) {
    error = std::string("lz4: ") + LZ4F_getErrorName(hint);
  } else if (frame.contentSize != 0 && frame.contentSize != expected) {
    error = "lz4 frame holds " + std::to_string(frame.contentSize) + " bytes, uncompressed_size says " +
            std::to_string(expected);
  }
  if (!error.empty()) {
    LZ4F_freeDecompressionContext(ctx);
    throw std::runtime_error(error);
  }
  std::vector<std::uint8_t> out(expected);
  std::size_t out_pos = 0;
  while (hint != 0 && error.empty()) {
    std::size_t in_n = size - in_pos;
    std::size_t out_n = out.size() - out_pos;
    hint = LZ4F_decompress(ctx, out.data() + out_pos, &out_n, data + in_pos, &in_n, nullptr);
    if (LZ4F_isError(hint)) {
      error = std::string("lz4: ") + LZ4F_getErrorName(hint);
    } else {
      in_pos += in_n;
      out_pos += out_n;
      if (hint != 0 && in_n == 0 && out_n == 0)
        error = "lz4: frame truncated or larger than uncompressed_size";
    }
  }
  LZ4F_freeDecompressionContext(ctx);
  if (!error.empty()) throw std::runtime_error(error);
  if (out_pos != expected || in_pos != size) {
    throw std::runtime_error("lz4 data decodes to " + std::to_string(out_pos) + " bytes (" +
                             std::to_string(size - in_pos) + " input bytes left), uncompressed_size says " +
                             std::to_string(expected));
  }
  return out;
}
#endif

}  // namespace

std::vector<std::uint8_t> compress_chunk(const std::string& compression, const std::vector<std::uint8_t>& in,
                                         int level) {
  if (compression.empty()) return in;
#ifdef PIXYSLAM_MCAP_HAVE_ZSTD
  if (compression == "zstd") return zstd_compress(in, level);
#endif
#ifdef PIXYSLAM_MCAP_HAVE_LZ4
  if (compression == "lz4") return lz4_compress(in, level);
#endif
  (void)level;
  throw std::runtime_error("compression '" + compression + "' is not available in this build");
}

std::vector<std::uint8_t> decompress_chunk(const std::string& compression, const std::uint8_t* data,
                                           std::size_t size, std::uint64_t uncompressed_size) {
  if (compression.empty()) {
    if (size != uncompressed_size) {
      throw std::runtime_error("uncompressed chunk holds " + std::to_string(size) +
                               " bytes, uncompressed_size says " + std::to_string(uncompressed_size));
    }
    return std::vector<std::uint8_t>(data, data + size);
  }
  const auto expected = static_cast<std::size_t>(uncompressed_size);
#ifdef PIXYSLAM_MCAP_HAVE_ZSTD
  if (compression == "zstd") return zstd_decompress(data, size, expected);
#endif
#ifdef PIXYSLAM_MCAP_HAVE_LZ4
  if (compression == "lz4") return lz4_decompress(data, size, expected);
#endif
  (void)expected;
  throw std::runtime_error("compression '" + compression + "' is not supported by this build");
}

}  // namespace pixyslam::mcap::detail
