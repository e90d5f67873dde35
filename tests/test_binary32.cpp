// roundedToBinary32 (zcheck/convention.h) where GCC's SLP vectoriser is on, as in the trace's and
// the raster's kernels (CMakeLists.txt: ZCHECK_SLP_VECTORISED, which this file is built with): the
// two shapes in which GCC 12 dropped double(float(x)) keep their rounding through it, and so does
// a float32 buffer's value (quantizeDepth). tests/test_core.cpp has the shapes written plainly,
// built as the rest of zcheck is.
#include "zcheck/convention.h"

#include "binary32_shapes.h"

#include <catch2/catch.hpp>

#include <vector>

using namespace zcheck;

namespace {

struct HelperRound {
    static double of(double x) { return roundedToBinary32(x); }
};
struct Float32BufferRound {  // the value a float32 depth buffer stores
    static double of(double x) { return quantizeDepth(DepthFormat::Float32, x); }
};

}  // namespace

TEST_CASE("roundedToBinary32 rounds where the SLP vectoriser packs the conversions", "[core]")
{
    binary32_shapes::requireBothShapesRound<HelperRound>();
    binary32_shapes::requireBothShapesRound<Float32BufferRound>();
}
