#!/usr/bin/env bash
# Install, build, and run the whole test suite (what CI runs):
#   1. every CTest test: C++ unit tests, CLI shell tests, the bad-input catalogue, the Python
#      module's pytest suite, and a consumer project built against the installed package;
#   2. each libFuzzer harness for ZCHECK_FUZZ_SECONDS (default 60) under ASan + UBSan;
#   3. the whole CTest suite again, built with ASan + UBSan (but for the Python and package
#      tests, which need an uninstrumented build).
set -euo pipefail
cd "$(dirname "$0")/.."
./scripts/deps.sh --test
./scripts/build.sh
(cd build && ctest --output-on-failure --parallel "$(nproc)" --timeout 600)
fuzz/run.sh "${ZCHECK_FUZZ_SECONDS:-60}"
./scripts/sanitize.sh
