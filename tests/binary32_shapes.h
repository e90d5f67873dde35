#pragma once
// The two shapes in which GCC 12's SLP vectoriser dropped the rounding of double(float(x))
// (CMakeLists.txt), over a rounding to binary32 `Round` (x ↦ the double of the nearest float),
// and what they must give. Each test that includes this instantiates them in its own source,
// built with its own flags: tests/test_core.cpp with double(float(x)) as zcheck's build takes it
// (the SLP vectoriser off), tests/test_binary32.cpp with roundedToBinary32 and the vectoriser on.
#include <catch2/catch.hpp>

#include <cstddef>
#include <vector>

namespace binary32_shapes {

struct TwoDoubles {
    double x, y;
};
struct ThreeDoubles {
    double x, y, z;
};

// Each out of line, so that it is compiled as the loop it is and not folded into the test's
// constants. Written with double(float(x)) and built with the vectoriser on, the first came back
// unrounded and the second gave 0 for x and y, at -O2 and -O3 alike.
template <class Round>
[[gnu::noinline]] void roundEach(TwoDoubles* p, int n)
{
    for (int i = 0; i < n; ++i) p[i].x = Round::of(p[i].x), p[i].y = Round::of(p[i].y);
}
template <class Round>
[[gnu::noinline]] void whatBinary32Leaves(const ThreeDoubles* p, int n, float* left)
{
    for (int i = 0; i < n; ++i) {
        left[3 * i] = float(Round::of(p[i].x) - p[i].x);
        left[3 * i + 1] = float(Round::of(p[i].y) - p[i].y);
        left[3 * i + 2] = float(Round::of(p[i].z) - p[i].z);
    }
}

// Both shapes, every count from 1 to 5 (read through a volatile, so that the calls stay calls):
// the loops' vector bodies take 4 at a time, what is left over goes through the packed scalar code.
template <class Round>
void requireBothShapesRound()
{
    for (volatile int count = 1; count <= 5; count = count + 1) {
        const int n = count;
        INFO(n << " at a time");
        std::vector<TwoDoubles> pairs(std::size_t(n), TwoDoubles{0.1, 0.2});  // no binary32 numbers
        roundEach<Round>(pairs.data(), n);
        for (const TwoDoubles& p : pairs) {
            REQUIRE(p.x == 0.100000001490116119384765625);  // 13421773 / 2^27
            REQUIRE(p.y == 0.20000000298023223876953125);   // 13421773 / 2^26
        }
        // A UTM easting and northing: binary32 holds multiples of 2^-5 near 512,346 and of 2^-1
        // near 4,212,347 (the differences below are exact in double, and their float the nearest).
        const std::vector<ThreeDoubles> utm(std::size_t(n), ThreeDoubles{512346.123456789, 4212346.987654321, 96.25});
        std::vector<float> left(3 * utm.size());
        whatBinary32Leaves<Round>(utm.data(), n, left.data());
        for (std::size_t i = 0; i < utm.size(); ++i) {
            REQUIRE(left[3 * i] == float(512346.125 - 512346.123456789));
            REQUIRE(left[3 * i + 1] == float(4212347.0 - 4212346.987654321));
            REQUIRE(left[3 * i + 2] == 0.0f);  // 96.25 is a binary32 number
        }
    }
}

}  // namespace binary32_shapes
