#include "png_codec.h"

#include "zcheck/camera.h"
#include "zcheck/error.h"

#include <png.h>

#include <csetjmp>
#include <cstdio>
#include <cstring>
#include <vector>

namespace zcheck {

namespace {

void appendToString(png_structp png, png_bytep data, png_size_t length)
{
    static_cast<std::string*>(png_get_io_ptr(png))->append(reinterpret_cast<const char*>(data), length);
}

void noFlush(png_structp) {}

// libpng reports errors by longjmp: this function holds nothing that needs destroying
// between setjmp and the calls that may jump. Returns false on a libpng error.
bool encode(std::string& out, int width, int height, int channels, int bitDepth, png_bytep* rows)
{
    png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, nullptr, nullptr, nullptr);
    if (!png) return false;
    png_infop info = png_create_info_struct(png);
    if (!info || setjmp(png_jmpbuf(png))) {
        png_destroy_write_struct(&png, info ? &info : nullptr);
        return false;
    }
    png_set_write_fn(png, &out, appendToString, noFlush);
    png_set_IHDR(png, info, png_uint_32(width), png_uint_32(height), bitDepth,
                 channels == 1 ? PNG_COLOR_TYPE_GRAY : PNG_COLOR_TYPE_RGB, PNG_INTERLACE_NONE,
                 PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
    png_write_info(png, info);
    if (bitDepth == 16) png_set_swap(png);  // PNG stores 16-bit samples big-endian; ours are little-endian
    png_write_image(png, rows);
    png_write_end(png, nullptr);
    png_destroy_write_struct(&png, &info);
    return true;
}

}  // namespace

std::string encodePng(int width, int height, int channels, int bitDepth, const void* samples)
{
    const std::size_t rowBytes = std::size_t(width) * std::size_t(channels) * std::size_t(bitDepth / 8);
    std::vector<png_bytep> rows(static_cast<std::size_t>(height));
    for (int y = 0; y < height; ++y)
        rows[std::size_t(y)] = const_cast<png_bytep>(static_cast<const png_byte*>(samples) + std::size_t(y) * rowBytes);
    std::string out;
    if (!encode(out, width, height, channels, bitDepth, rows.data())) throw Error("libpng failed to encode an image");
    return out;
}

}  // namespace zcheck

namespace zcheck {

namespace {

struct MemoryReader {
    const std::string* bytes;
    std::size_t at;
};

void readFromMemory(png_structp png, png_bytep data, png_size_t length)
{
    auto* reader = static_cast<MemoryReader*>(png_get_io_ptr(png));
    if (length > reader->bytes->size() - reader->at) png_error(png, "the file ends early (truncated)");
    std::memcpy(data, reader->bytes->data() + reader->at, length);
    reader->at += length;
}

// libpng reports errors by longjmp: nothing with a destructor lives between setjmp and the
// calls that may jump; the message is copied into `error`.
void keepMessage(png_structp png, png_const_charp message)
{
    char* error = static_cast<char*>(png_get_error_ptr(png));
    std::snprintf(error, 256, "%s", message);
    png_longjmp(png, 1);
}
void ignoreWarning(png_structp, png_const_charp) {}

enum class Step { HeaderRead, Done, Failed };

// Reads the header (step 1) or, given rows, the image (step 2).
Step decode(MemoryReader& reader, char* error, png_uint_32& width, png_uint_32& height, int& bitDepth, int& colourType,
            int& interlace, png_bytep* rows)
{
    png_structp png = png_create_read_struct(PNG_LIBPNG_VER_STRING, error, keepMessage, ignoreWarning);
    if (!png) return Step::Failed;
    png_infop info = png_create_info_struct(png);
    if (!info || setjmp(png_jmpbuf(png))) {
        png_destroy_read_struct(&png, info ? &info : nullptr, nullptr);
        return Step::Failed;
    }
    png_set_read_fn(png, &reader, readFromMemory);
    png_set_user_limits(png, Camera::kMaxImageSide, Camera::kMaxImageSide);
    png_read_info(png, info);
    png_get_IHDR(png, info, &width, &height, &bitDepth, &colourType, &interlace, nullptr, nullptr);
    if (!rows) {
        png_destroy_read_struct(&png, &info, nullptr);
        return Step::HeaderRead;
    }
    png_set_swap(png);  // PNG stores 16-bit samples big-endian; ours are little-endian
    png_read_image(png, rows);
    png_read_end(png, nullptr);
    png_destroy_read_struct(&png, &info, nullptr);
    return Step::Done;
}

}  // namespace

Png16 decodePng16(const std::string& bytes, const std::function<void(long long, long long)>& acceptSize)
{
    char error[256] = "corrupt PNG";
    png_uint_32 width = 0, height = 0;
    int bitDepth = 0, colourType = 0, interlace = 0;
    MemoryReader reader{&bytes, 0};
    if (decode(reader, error, width, height, bitDepth, colourType, interlace, nullptr) != Step::HeaderRead)
        throw Error(std::string("malformed PNG: ") + error);
    acceptSize(width, height);
    if (colourType != PNG_COLOR_TYPE_GRAY || bitDepth != 16)
        throw Error("a PNG depth map must be 16-bit greyscale; this one is " + std::to_string(bitDepth) + "-bit " +
                    (colourType == PNG_COLOR_TYPE_GRAY         ? "greyscale"
                     : colourType == PNG_COLOR_TYPE_RGB        ? "RGB"
                     : colourType == PNG_COLOR_TYPE_RGB_ALPHA  ? "RGBA"
                     : colourType == PNG_COLOR_TYPE_GRAY_ALPHA ? "greyscale with alpha"
                                                               : "palette") +
                    " (8 bits cannot hold depth)");
    if (interlace != PNG_INTERLACE_NONE) throw Error("interlaced PNG depth maps are not supported");
    Png16 out;
    out.width = int(width), out.height = int(height);
    out.codes.resize(std::size_t(width) * height);
    std::vector<png_bytep> rows(static_cast<std::size_t>(height));
    for (std::size_t y = 0; y < height; ++y) rows[y] = reinterpret_cast<png_bytep>(out.codes.data() + y * width);
    reader.at = 0;
    if (decode(reader, error, width, height, bitDepth, colourType, interlace, rows.data()) != Step::Done)
        throw Error(std::string("malformed PNG: ") + error);
    return out;
}

}  // namespace zcheck
