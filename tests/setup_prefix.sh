#!/usr/bin/env bash
# The set-up installs into ZCHECK_PREFIX: the command, the C++ package and the Python module land
# under it and work from there, and nothing is written to the default prefix's zcheck files.
#   setup_prefix.sh SOURCE_DIR PYTHON
set -euo pipefail
source_dir=$1
python=$2
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
prefix="$tmp/prefix with space"
ZCHECK_PREFIX="$prefix" "$source_dir/scripts/build.sh" > "$tmp/build.log" 2>&1 || { cat "$tmp/build.log" >&2; exit 1; }
version=$(sed -n 's/^project(zcheck VERSION \([0-9.]*\).*/\1/p' "$source_dir/CMakeLists.txt")
[[ $("$prefix/bin/zcheck" --version) == *"$version"* ]]
test -f "$prefix/lib/cmake/zcheck/zcheckConfig.cmake"
test -f "$prefix/include/zcheck/checker.h"
site=$("$python" -c 'import sys; print(f"lib/python{sys.version_info[0]}.{sys.version_info[1]}/dist-packages")')
got=$(cd "$tmp" && env -u PYTHONPATH PYTHONPATH="$prefix/$site" "$python" -c \
      'import zcheck; print(zcheck.__file__); print(zcheck.Scene.from_file("builtin:default").triangle_count)')
[[ $got == "$prefix/$site/zcheck/__init__.py"$'\n'3332 ]] || { echo "setup_prefix: imported $got" >&2; exit 1; }
# A venv of the same interpreter with --system-site-packages sees the module on that path too.
"$python" -m venv --system-site-packages "$tmp/venv"
got=$(cd "$tmp" && env -u PYTHONPATH PYTHONPATH="$prefix/$site" "$tmp/venv/bin/python" -c 'import zcheck, numpy; print(zcheck.__file__)')
[[ $got == "$prefix/$site/zcheck/__init__.py" ]] || { echo "setup_prefix: the venv imported $got" >&2; exit 1; }
echo "setup_prefix: 1 passed, 0 failed"
