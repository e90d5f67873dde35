#!/usr/bin/env bash
# Configures and builds zcheck (Release) into ./build, then installs it into ZCHECK_PREFIX
# (default /usr/local): the zcheck command, the C++ package (find_package(zcheck)) and the Python
# module (import zcheck, for Debian's python3; docs/python.md says how other interpreters find it).
# A prefix the user can write needs no root. Idempotent and incremental.
set -euo pipefail
cd "$(dirname "$0")/.."
prefix=${ZCHECK_PREFIX:-/usr/local}
./scripts/deps.sh
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release > /dev/null
cmake --build build --parallel "$(nproc)"
mkdir -p "$prefix" 2> /dev/null || true
sudo=""
if [[ ! -w $prefix ]]; then
    [[ $(id -u) -eq 0 ]] || sudo=sudo
fi
$sudo cmake --install build --prefix "$prefix" > /dev/null
