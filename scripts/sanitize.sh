#!/usr/bin/env bash
# Builds zcheck and its tests with AddressSanitizer + UBSan (-fno-sanitize-recover: any
# undefined behaviour fails the test) into ./build-asan and runs the test suite there.
# Extra arguments go to ctest, e.g. `scripts/sanitize.sh -L unit` for the unit tests only.
set -euo pipefail
cd "$(dirname "$0")/.."
./scripts/deps.sh
cmake -S . -B build-asan -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DZCHECK_SANITIZE=ON > /dev/null
cmake --build build-asan --parallel "$(nproc)"
cd build-asan
export ASAN_OPTIONS=detect_leaks=1:abort_on_error=1:allocator_may_return_null=1
export UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
ctest --output-on-failure --parallel "$(nproc)" --timeout 1800 "$@"
