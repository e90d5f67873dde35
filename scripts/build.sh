#!/usr/bin/env bash
# Configures and builds zcheck (Release) into ./build, then installs it into /usr/local:
# the zcheck command, the C++ package (find_package(zcheck)) and the Python module (import
# zcheck, for Debian's python3). Idempotent and incremental.
set -euo pipefail
cd "$(dirname "$0")/.."
./scripts/deps.sh
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release > /dev/null
cmake --build build --parallel "$(nproc)"
sudo=""
[[ $(id -u) -eq 0 ]] || sudo=sudo
$sudo cmake --install build > /dev/null
