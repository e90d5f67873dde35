#pragma once
// How much of a sweep a test run takes. A sweep is a test that runs the same code over many
// cases: a fit over several departures on each of several setups, a property over the whole
// mistake catalogue. The plain build's run takes every case. Under the sanitizers
// (scripts/sanitize.sh sets ZCHECK_TEST_SWEEP=sample), whose build runs the fits' arithmetic
// about 17× as slowly, a sweep takes a third of its cases: in round r (a setup) the cases i
// with (r + i) % 3 == 0, which third turning from round to round, so that over any three
// rounds every case runs once. ZCHECK_TEST_SWEEP=all (or unset) takes them all; any
// other value stops the test with a message naming it.
#include <cstddef>
#include <cstdlib>
#include <initializer_list>
#include <stdexcept>
#include <string>
#include <vector>

namespace zcheck::testing {

// Whether this run takes case `item` of round `round` of a sweep.
inline bool sweepTakes(std::size_t round, std::size_t item)
{
    static const bool sample = [] {
        const char* value = std::getenv("ZCHECK_TEST_SWEEP");
        const std::string mode = value ? value : "all";
        if (mode != "all" && mode != "sample")
            throw std::invalid_argument("ZCHECK_TEST_SWEEP='" + mode + "' must be all or sample");
        return mode == "sample";
    }();
    return !sample || (round + item) % 3 == 0;
}

// The cases of round `round` this run takes, in their order.
template <class T>
std::vector<T> sweepCases(std::size_t round, std::initializer_list<T> cases)
{
    std::vector<T> taken;
    std::size_t item = 0;
    for (const T& c : cases)
        if (sweepTakes(round, item++)) taken.push_back(c);
    return taken;
}

}  // namespace zcheck::testing
