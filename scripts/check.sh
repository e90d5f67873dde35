#!/usr/bin/env bash
# The main job: install, build, and run a consistency check on the built-in default scene.
# Extra arguments go to `zcheck check`.
set -euo pipefail
cd "$(dirname "$0")/.."
./scripts/build.sh
exec ./build/cli/zcheck check "$@"
