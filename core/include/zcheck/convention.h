#pragma once
// Conventions as data.
//
// A Convention says how one graphics API lays out the spaces of the transform chain:
//   eye    — camera at the origin; which way it looks and which way +y points,
//   NDC    — after the divide by w; the range of z and which way +y points,
//   window — continuous viewport coordinates; where the origin is,
// and how matrices are printed. It never changes the picture: the same camera (position,
// orientation, field of view) yields the same image in every convention; only numbers
// change. Pixel (col,row) has row 0 at the top of the stored image in every convention,
// and pixel centres are at +0.5 in window coordinates.
//
// Depth settings are the switches orthogonal to the preset: reversed-Z (which lives in the
// projection matrix: clipFromEye maps the near plane to the far end of NDC z), the depth
// range [min,max] the viewport maps NDC z to (glDepthRange / MinDepth-MaxDepth), and the
// storage format of the depth buffer.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

namespace zcheck {

enum class NdcDepthRange {
    MinusOneToOne,  // OpenGL: z_ndc in [-1, 1]  (GLM's _NO)
    ZeroToOne,      // Direct3D, Vulkan, Metal: z_ndc in [0, 1]  (GLM's _ZO)
};

struct Convention {
    std::string name;
    int eyeForwardZ;        // z of the viewing direction in eye space: -1 (looks down -Z, RH) or +1
    int eyeUpY;             // +1: eye +y points up in the image; -1: down (opencv)
    NdcDepthRange ndcDepth;
    int ndcUpY;             // +1: NDC +y points up in the image; -1: down (vulkan, opencv)
    bool windowOriginTop;   // true: window y = 0 is the top edge and grows downwards
    bool rowVectors;        // matrices are printed for row vectors (p' = p·M), as Direct3D does

    double ndcZMin() const { return ndcDepth == NdcDepthRange::MinusOneToOne ? -1.0 : 0.0; }

    // The presets: opengl, direct3d, vulkan, metal, opencv. Throws Error for another name.
    static Convention preset(const std::string& name);
    static const std::vector<std::string>& presetNames();
};

enum class DepthFormat {
    Float32,  // IEEE binary32, round to nearest
    Unorm24,  // stores round(d · (2^24 − 1))
    Unorm16,  // stores round(d · (2^16 − 1))
};

std::string toString(DepthFormat format);
DepthFormat depthFormatFromName(const std::string& name);  // throws Error naming the value
const std::vector<std::string>& depthFormatNames();

// The largest code of a unorm format, 2^N − 1.
inline double unormMax(DepthFormat format) { return format == DepthFormat::Unorm24 ? 16777215.0 : 65535.0; }

// std::nearbyint(x) for 0 ≤ x < 2^52 (or NaN), inline: adding 2^52 leaves no fraction bits,
// so the sum is rounded to an integer in the current rounding mode, and subtracting 2^52
// again is exact. (The library call costs the rasterizer a call per pixel.)
inline double nearbyintNonNegative(double x)
{
    constexpr double kNoFractionBits = 4503599627370496.0;  // 2^52
    return (x + kNoFractionBits) - kNoFractionBits;
}

// The code a unorm depth buffer stores for window depth `windowDepth`: round(clamp(d, 0, 1)·(2^N − 1)),
// as a double (exact: at most 2^24 − 1). Codes order as the values they stand for.
inline double unormCode(DepthFormat format, double windowDepth)
{
    return nearbyintNonNegative(std::clamp(windowDepth, 0.0, 1.0) * unormMax(format));
}

// The value a unorm format's code `code` (an integer, 0 ≤ code ≤ 2^N − 1) stands for:
// code / (2^N − 1) as the division rounds it, bit for bit, without a division (the raster stores
// one per pixel). 1/(2^N − 1) = 2^−N + 2^−2N + …, so the exact quotient is the code's N bits
// repeated below the binary point. t (the first two copies for N = 24, three for N = 16) is
// exact, t · 2^−48 too, and their sum, the first 96 bits of the quotient, is rounded once. The
// bits past the 96th add less than one unit of the 96th (the quotient times 2^−96), and every
// midpoint between two doubles here is a multiple of 2^−77, so they could change the rounding
// only where the 96-bit sum were itself a midpoint. It never is: a midpoint's last set bit lies
// 53 places below its leading bit, the sum's (the code's lowest set bit, in its last copy) at
// least 96 − N places. tests/test_core.cpp checks every code of both formats.
inline double unormValue(DepthFormat format, double code)
{
    const double t = code * (format == DepthFormat::Unorm24 ? 0x1p-24 + 0x1p-48 : 0x1p-16 + 0x1p-32 + 0x1p-48);
    return t + t * 0x1p-48;
}

// The binary32 number nearest x, as a double: what a float32 buffer or file keeps of x. Every
// place zcheck rounds to binary32 on purpose and reads the value back as a double goes through
// this, because a compiler may lose that rounding: GCC 12's basic-block SLP vectoriser (Debian
// 12's 12.2) takes double(float(x)) for x where it packs two or more such conversions side by
// side. zcheck builds with that vectoriser off (CMakeLists.txt) but for its trace and raster
// kernels, which are faster with it; the empty asm keeps the rounding there, and in a
// consumer's code built with it on (tests/test_binary32.cpp).
inline double roundedToBinary32(double x)
{
    float kept = static_cast<float>(x);
#if defined(__GNUC__) && (defined(__x86_64__) || defined(__i386__))
    asm("" : "+x"(kept));  // the float as such: the conversion back is not folded into the one before
#else
    const volatile float opaque = kept;
    kept = opaque;
#endif
    return static_cast<double>(kept);
}

// The value the depth buffer stores for window depth `windowDepth` (clamped to [0,1] for
// unorm formats, rounded to the nearest code), returned as a double so that all formats
// compare alike. Inline: the rasterizer calls it per pixel.
inline double quantizeDepth(DepthFormat format, double windowDepth)
{
    if (format == DepthFormat::Float32) return roundedToBinary32(windowDepth);
    return unormValue(format, unormCode(format, windowDepth));
}

// The storage quantum q at a stored value: 1 LSB = 1/(2^N − 1) for unorm-N, the spacing of
// binary32 numbers above |value| (1 ulp) for float32: the next binary32 up, whose bits are
// |value|'s plus one (what std::nextafter(|value|, +inf) gives for every finite value; +inf
// and NaN give NaN either way), less |value|. No library call, so a loop of these is
// vectorised (the comparison takes one per pixel of a float32 map).
inline double storageQuantum(DepthFormat format, double windowDepth)
{
    if (format != DepthFormat::Float32) return 1.0 / unormMax(format);
    const float magnitude = std::fabs(static_cast<float>(windowDepth));
    std::uint32_t bits;
    std::memcpy(&bits, &magnitude, sizeof bits);
    ++bits;
    float next;
    std::memcpy(&next, &bits, sizeof next);
    return static_cast<double>(next) - static_cast<double>(magnitude);
}

// 2^N − 1 where q is a unorm format's storageQuantum, else 0 (inQuanta's test, lane by lane too).
inline double unormCodesPerUnit(double q)
{
    if (q == storageQuantum(DepthFormat::Unorm24, 0.0)) return unormMax(DepthFormat::Unorm24);
    if (q == storageQuantum(DepthFormat::Unorm16, 0.0)) return unormMax(DepthFormat::Unorm16);
    return 0.0;
}

// A value x in quanta q, x / q. A unorm format's quantum is exactly 1/(2^N − 1), which its
// storageQuantum can only round: where q is that double, whatever gave it (a format, a map's
// own quanta), x · (2^N − 1), the exact quotient rounded once (and in the comparison's vector
// forms one multiplication a pixel instead of a division); any other q divides. (The division
// is made either way, so that a loop of these needs no branch: a compiler may not make a
// trapping operation the code skipped.)
inline double inQuanta(double x, double q)
{
    const double codesPerUnit = unormCodesPerUnit(q), quotient = x / q;
    return codesPerUnit != 0.0 ? x * codesPerUnit : quotient;
}

struct DepthSettings {
    DepthFormat format = DepthFormat::Float32;
    bool reversed = false;   // reversed-Z: near → far end of the range, depth test GREATER
    double rangeMin = 0.0;   // window depth of NDC z_min (glDepthRange near argument)
    double rangeMax = 1.0;   // window depth of NDC z = 1
};

}  // namespace zcheck
