#!/usr/bin/env bash
# Install, build, and run the test suite (the README's second command).
#   ./scripts/test.sh          every CTest test: C++ unit tests, command-line tests, the bad-input
#                              catalogue, the installed package, the Python module's pytest suite,
#                              Blender headless, Mesa's OpenGL, and every example of the documents
#                              (README.md, docs/*.md); a few minutes from a built tree on 2 cores.
#   ./scripts/test.sh --full   also each libFuzzer harness for ZCHECK_FUZZ_SECONDS (default 60)
#                              under ASan + UBSan, then the whole CTest suite again built with
#                              ASan + UBSan (but for the Python and package tests, which need an
#                              uninstrumented build; its sweeps take a third of their cases,
#                              tests/sweep.h). This is what CI runs (.ci/run).
# Extra arguments after the options go to the first ctest (e.g. -L unit, -R verify).
set -euo pipefail
cd "$(dirname "$0")/.."
full=false
if [[ ${1:-} == --full ]]; then
    full=true
    shift
fi
stage() { echo "test.sh: $1 done after $SECONDS s" >&2; }
./scripts/deps.sh --test
stage "set-up"
./scripts/build.sh
stage "build and install"
(cd build && ctest --output-on-failure --parallel "$(nproc)" --timeout 600 "$@")
stage "tests"
if $full; then
    fuzz/run.sh "${ZCHECK_FUZZ_SECONDS:-60}"
    stage "fuzzing"
    ./scripts/sanitize.sh
    stage "tests under the sanitizers"
fi
