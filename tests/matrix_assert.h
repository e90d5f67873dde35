#pragma once
// Element-wise matrix comparison for tests, naming the row and column that differ.
#include <catch2/catch.hpp>
#include <glm/glm.hpp>

// Each element within `tolerance` absolutely or relatively (GLM indexes [column][row]).
inline void requireMatrixNear(const glm::dmat4& actual, const glm::dmat4& expected, double tolerance = 1e-12)
{
    for (int c = 0; c < 4; ++c)
        for (int r = 0; r < 4; ++r) {
            INFO("row " << r << " column " << c);
            REQUIRE(actual[c][r] == Approx(expected[c][r]).margin(tolerance).epsilon(tolerance));
        }
}
