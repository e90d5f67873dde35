#!/usr/bin/env bash
# Builds zcheck and its tests with AddressSanitizer + UBSan (-fno-sanitize-recover: any
# undefined behaviour fails the test) into ./build-asan and runs the test suite there.
# Extra arguments go to ctest, e.g. `scripts/sanitize.sh -L unit` for the unit tests only.
set -euo pipefail
cd "$(dirname "$0")/.."
./scripts/deps.sh
# Line tables only (-g1): a report's stack still names file and line, and the build takes 16
# minutes on 2 cores instead of 21 with -g (the tests below take 21-24 more).
cmake -S . -B build-asan -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O2 -g1 -DNDEBUG" \
    -DZCHECK_SANITIZE=ON > /dev/null
cmake --build build-asan --parallel "$(nproc)"
cd build-asan
# intercept_tls_get_addr=0: GCC 12's runtime guesses the layout of a dynamic-TLS block from its
# address (google/sanitizers#1322); a wrong guess gives LeakSanitizer a bogus range and its tracer
# dies with "Tracer caught signal 11" at exit, at random. Leak checking itself stays on.
export ASAN_OPTIONS=detect_leaks=1:abort_on_error=1:allocator_may_return_null=1:intercept_tls_get_addr=0
export UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
# The sweeps take a third of their cases here (tests/sweep.h): this build runs the fits ~17× as
# slowly, and the plain build's run takes every case. ZCHECK_TEST_SWEEP=all takes them all.
export ZCHECK_TEST_SWEEP=${ZCHECK_TEST_SWEEP:-sample}
ctest --output-on-failure --parallel "$(nproc)" --timeout 1800 "$@"
