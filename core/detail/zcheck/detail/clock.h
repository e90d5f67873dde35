#pragma once
// Internal to zcheck (core/detail, never installed): the wall clock every timing reads.
//
//   const auto start = zcheck::Clock::now();
//   ...
//   report.traceMs = zcheck::millisecondsSince(start);
#include <chrono>

namespace zcheck {

using Clock = std::chrono::steady_clock;

// Wall time since `start`, in milliseconds.
inline double millisecondsSince(Clock::time_point start)
{
    return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

// Wall time since `start`, in seconds.
inline double secondsSince(Clock::time_point start) { return std::chrono::duration<double>(Clock::now() - start).count(); }

}  // namespace zcheck
