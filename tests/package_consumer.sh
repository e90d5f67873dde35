#!/usr/bin/env bash
# The installed package works for a consumer: `cmake --install` into a fresh prefix, then
# examples/cpp configures with find_package(zcheck), builds against it, and runs.
set -euo pipefail
build=$1
source_dir=$2
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
cmake --install "$build" --prefix "$tmp/prefix" > /dev/null
# Nothing of the build tree may leak into what was installed.
if grep -rIl "$build\|$source_dir" "$tmp/prefix/include" "$tmp/prefix/lib/cmake"; then
    echo "package_consumer: build-tree paths in the installed headers or CMake files" >&2
    exit 1
fi
test -f "$tmp/prefix/include/zcheck/version.h"
# Nothing that only makes zcheck fast is installed, and no installed header reaches for it.
for internal in kernel_choice.h lane_mask.h streaming_stores.h clock.h percentile.h slope_table.h detail; do
    test ! -e "$tmp/prefix/include/zcheck/$internal"
done
! grep -rlE '"zcheck/detail/|ZCHECK_ALWAYS_INLINE|<immintrin.h>' "$tmp/prefix/include"
test ! -e "$tmp/prefix/include/zcheck/version.h.in"
cmake -S "$source_dir/examples/cpp" -B "$tmp/example" -DCMAKE_PREFIX_PATH="$tmp/prefix" > "$tmp/configure.log" 2>&1 ||
    { cat "$tmp/configure.log" >&2; exit 1; }
cmake --build "$tmp/example" > "$tmp/build.log" 2>&1 || { cat "$tmp/build.log" >&2; exit 1; }
# Every installed header at once, in one translation unit of a consumer, linked against the
# package: no name is defined twice (regression: zcheck::ClipPlanes was, in camera_sources.h and clip.h).
mkdir -p "$tmp/all_headers"
{
    for header in "$tmp/prefix/include/zcheck/"*.h; do echo "#include <zcheck/$(basename "$header")>"; done
    echo 'int main() { return zcheck::Camera(zcheck::CameraSpec{}).width() > 0 ? 0 : 1; }'
} > "$tmp/all_headers/all_headers.cpp"
cat > "$tmp/all_headers/CMakeLists.txt" << 'CMAKE'
cmake_minimum_required(VERSION 3.16)
project(all_headers CXX)
set(CMAKE_CXX_STANDARD 17)
find_package(zcheck REQUIRED)
add_executable(all_headers all_headers.cpp)
target_link_libraries(all_headers PRIVATE zcheck::zcheck)
CMAKE
[[ $(grep -c '#include' "$tmp/all_headers/all_headers.cpp") -ge 30 ]]
cmake -S "$tmp/all_headers" -B "$tmp/all_headers/build" -DCMAKE_PREFIX_PATH="$tmp/prefix" > "$tmp/all_configure.log" 2>&1 ||
    { cat "$tmp/all_configure.log" >&2; exit 1; }
cmake --build "$tmp/all_headers/build" > "$tmp/all_build.log" 2>&1 || { cat "$tmp/all_build.log" >&2; exit 1; }
"$tmp/all_headers/build/all_headers"
"$tmp/example/consistency_gate" > "$tmp/out.txt"
[[ $(grep -c "CONSISTENT" "$tmp/out.txt") -eq 5 ]]
! grep -q "INCONSISTENT" "$tmp/out.txt"
# A map with its rows flipped: inconsistent (exit 1), and the diagnosis names the y-flip.
set +e
"$tmp/example/verify_map" > "$tmp/verify.txt"
status=$?
set -e
[[ $status -eq 1 ]]
grep -q "^map INCONSISTENT$" "$tmp/verify.txt"
grep -q "^consistent if y-flip:" "$tmp/verify.txt"
# The installed command-line tool runs from the prefix (no build-tree paths compiled in).
"$tmp/prefix/bin/zcheck" --version | grep -q "$(cat "$source_dir/CMakeLists.txt" | sed -n 's/^project(zcheck VERSION \([0-9.]*\).*/\1/p')"
# It starts without OpenImageIO, and loads it (the installed plugin) when it writes an image.
! ldd "$tmp/prefix/bin/zcheck" | grep -q OpenImageIO
# Nor any GL library: `bench --reference` loads its llvmpipe yardstick as a plugin.
! ldd "$tmp/prefix/bin/zcheck" | grep -qi "libEGL\|libGL"
"$tmp/prefix/bin/zcheck" export --quantity eye-z -o "$tmp/depth.exr" > /dev/null
"$tmp/prefix/bin/zcheck" verify --depth-map "$tmp/depth.exr" --quantity eye-z > /dev/null
echo "package_consumer: 1 passed, 0 failed"
