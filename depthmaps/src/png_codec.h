#pragma once
// PNG in memory with libpng (private to zcheck_io and zcheck_imageio). Encoding: the caller writes the
// bytes with writeFileBytes, which checks every write, or embeds them (data: URIs). Decoding:
// 16-bit greyscale depth maps only, the size checked before any row is allocated.
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace zcheck {

// `samples` holds width·height·channels values, rows from the top: bytes for bitDepth 8,
// native-endian uint16 for bitDepth 16. channels: 1 (grey) or 3 (RGB).
std::string encodePng(int width, int height, int channels, int bitDepth, const void* samples);

}  // namespace zcheck

namespace zcheck {

// A 16-bit greyscale PNG decoded from memory: the stored codes, row 0 at the top. The
// header is read first and `acceptSize(width, height)` may throw before any row is
// allocated. Throws Error (prefixed by nothing: the caller names the file) for anything
// else: another colour type or bit depth, interlacing, a corrupt or truncated stream.
struct Png16 {
    int width = 0, height = 0;
    std::vector<std::uint16_t> codes;
};
Png16 decodePng16(const std::string& bytes, const std::function<void(long long width, long long height)>& acceptSize);

}  // namespace zcheck
