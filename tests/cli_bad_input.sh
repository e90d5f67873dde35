#!/usr/bin/env bash
# Bad input: every case must exit with status 2 and one line on stderr that names the
# problem; never a crash, a hang or a silently repaired value.
set -u
zcheck=$1
models=$2
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
failures=0
passed=0

camera() {  # camera PROJECTION-JSON [EXTRA-KEYS]
    printf '{"projection": %s, "view": {"eye": [0, 1, 3], "target": [0, 0, 0], "up": [0, 1, 0]}%s}\n' "$1" "${2:-}"
}

expect_usage_error() {  # expect_usage_error PATTERN ARGS...
    local pattern=$1
    shift
    local stderr
    stderr=$(timeout 60 "$zcheck" "$@" 2>&1 >/dev/null)
    local status=$?
    local lines
    lines=$(printf '%s\n' "$stderr" | grep -c .)
    if [[ $status -ne 2 ]]; then
        echo "FAIL (exit $status, expected 2): zcheck $*"; echo "  stderr: $stderr"; failures=$((failures + 1))
    elif [[ $lines -ne 1 ]]; then
        echo "FAIL ($lines lines on stderr, expected 1): zcheck $*"; echo "  stderr: $stderr"; failures=$((failures + 1))
    elif ! grep -qiE -- "$pattern" <<<"$stderr"; then
        echo "FAIL (message does not match /$pattern/): zcheck $*"; echo "  stderr: $stderr"; failures=$((failures + 1))
    else
        passed=$((passed + 1))
    fi
}

perspective='{"type": "perspective", "fovy_deg": 60, "near": 0.1, "far": 100}'
camera "$perspective" > "$tmp/good.json"
camera '{"type": "perspective", "fovy_deg": 60, "near": 0, "far": 100}' > "$tmp/near0.json"
camera '{"type": "perspective", "fovy_deg": 60, "near": -1, "far": 100}' > "$tmp/nearneg.json"
camera '{"type": "perspective", "fovy_deg": 60, "near": 5, "far": 5}' > "$tmp/fareq.json"
camera '{"type": "perspective", "fovy_deg": 60, "near": 5, "far": 1}' > "$tmp/farlt.json"
camera '{"type": "perspective", "fovy_deg": 0, "near": 0.1, "far": 100}' > "$tmp/fov0.json"
camera '{"type": "perspective", "fovy_deg": 1e400, "near": 0.1, "far": 100}' > "$tmp/fovinf.json"
camera "$perspective" ', "image": {"width": 0, "height": 480}' > "$tmp/width0.json"
camera "$perspective" ', "image": {"width": 100000, "height": 480}' > "$tmp/widthhuge.json"
camera "$perspective" ', "convention": "directx"' > "$tmp/convention.json"
camera "$perspective" ', "lens": 50' > "$tmp/unknownkey.json"
camera '{"type": "frustum", "left": 1, "right": -1, "bottom": -1, "top": 1, "near": 1, "far": 10}' > "$tmp/frustum.json"
printf '{"projection": %s, "view": {"eye": [0, 0, 0], "target": [0, 0, 0]}}\n' "$perspective" > "$tmp/degenerate.json"
printf '{"projection": %s, "view": {"eye": [0, 1, 0], "target": [0, 0, 0], "up": [0, 1, 0]}}\n' "$perspective" > "$tmp/upparallel.json"
printf '{"projection": %s, "view": {"eye": [0, 1, 3], "target": [0, 0, 0]' "$perspective" > "$tmp/truncated.json"
printf 'v 0 0 0\nv 1 0 0\nf 1 2 9\n' > "$tmp/badindex.obj"
printf 'this is not a mesh\n' > "$tmp/garbage.obj"
printf 'ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement tristrips 1\nproperty list int int vertex_indices\nend_header\n' > "$tmp/truncated.ply"
: > "$tmp/empty.obj"
printf '{"projection": {"type": "matrix", "clip_from_eye": [0,0,0,0, 0,0,0,0, 0,0,0,0, 0,0,0,0], "layout": "row-major", "vectors": "column"}, "view": {"eye": [0, 1, 3], "target": [0, 0, 0]}}' > "$tmp/singular.json"
ply_header='ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n'
printf "${ply_header}element tristrips 1\nproperty list int int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 4294967296\n" > "$tmp/bigindex.ply"
printf "${ply_header}element tristrips 1\nproperty list int int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n268435456 0 1 2\n" > "$tmp/biglist.ply"
printf "${ply_header}element tristrips 5000000000\nproperty list int int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n" > "$tmp/bigcount.ply"
printf "${ply_header}element junk 18446744073709551615\nelement tristrips 1\nproperty list int int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n" > "$tmp/noprops.ply"
printf "${ply_header}element tristrips 1\nproperty list int float vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 nan\n" > "$tmp/nanindex.ply"

expect_usage_error "no such file"            check --camera "$tmp/missing.json"
expect_usage_error "not valid JSON"          check --camera "$tmp/truncated.json"
expect_usage_error "projection.near"         check --camera "$tmp/near0.json"
expect_usage_error "projection.near"         check --camera "$tmp/nearneg.json"
expect_usage_error "projection.far"          check --camera "$tmp/fareq.json"
expect_usage_error "projection.far"          check --camera "$tmp/farlt.json"
expect_usage_error "fovy_deg"                check --camera "$tmp/fov0.json"
expect_usage_error "camera file .*fov.*1e400|fovy_deg" check --camera "$tmp/fovinf.json"
expect_usage_error "image.width"             check --camera "$tmp/width0.json"
expect_usage_error "image.width"             check --camera "$tmp/widthhuge.json"
expect_usage_error "convention"              check --camera "$tmp/convention.json"
expect_usage_error "unknown key 'lens'"      check --camera "$tmp/unknownkey.json"
expect_usage_error "projection.right"        check --camera "$tmp/frustum.json"
expect_usage_error "view.target"             check --camera "$tmp/degenerate.json"
expect_usage_error "view.up"                 check --camera "$tmp/upparallel.json"
expect_usage_error "width"                   check --width 0
expect_usage_error "height"                  check --height -5
expect_usage_error "width"                   check --width 20000
expect_usage_error "width"                   check --width abc
expect_usage_error "more than .* pixels"     check --width 8193 --height 4096
expect_usage_error "unknown convention"      check --convention opengl2
expect_usage_error "unknown depth format"    check --depth-format unorm8
expect_usage_error "unknown built-in scene"  check --scene builtin:nothing
expect_usage_error "parameter 'm'"           check --scene "builtin:terrain?m=3"
expect_usage_error "'n' must be"             check --scene "builtin:terrain?n=1"
expect_usage_error "'n' must be"             check --scene "builtin:terrain?n=abc"
expect_usage_error "no such file"            check --scene "$tmp/missing.obj"
expect_usage_error "out of range|cannot load" check --scene "$tmp/badindex.obj"
expect_usage_error "cannot load"             check --scene "$tmp/garbage.obj"
expect_usage_error "cannot load"             check --scene "$tmp/empty.obj"
expect_usage_error "ends early|malformed"    check --scene "$tmp/truncated.ply"
expect_usage_error "out of range"            check --scene "$tmp/bigindex.ply"
expect_usage_error "more than the file"      check --scene "$tmp/biglist.ply"
expect_usage_error "more than the file"      check --scene "$tmp/bigcount.ply"
expect_usage_error "no properties"           check --scene "$tmp/noprops.ply"
expect_usage_error "whole number|non-number" check --scene "$tmp/nanindex.ply"
expect_usage_error "not a regular file"      check --scene /dev/zero
expect_usage_error "directory"               check --scene "$tmp"
expect_usage_error "not a directory"         check --out "$tmp/good.json"
expect_usage_error "extraneous|not expected|unknown|following argument" check --frobnicate
expect_usage_error "subcommand"              
expect_usage_error "subcommand|not expected|extraneous|following argument" fly

# The other commands.
expect_usage_error "camera.*required|--camera"  matrices
expect_usage_error "no such file"            matrices --camera "$tmp/missing.json"
expect_usage_error "singular"                matrices --camera "$tmp/singular.json"
expect_usage_error "not a number"            precision --camera "$tmp/good.json" --at 1,abc
expect_usage_error "outside the camera"      precision --camera "$tmp/good.json" --at 0.01
expect_usage_error "unknown depth quantity"  unproject --camera "$tmp/good.json" --pixel 1,1 --depth 0.5 --quantity z
expect_usage_error "whole numbers"           unproject --camera "$tmp/good.json" --pixel 1.5,2
expect_usage_error "--space"                 unproject --camera "$tmp/good.json" --pixel 1,1 --space clip

echo "cli_bad_input: $passed passed, $failures failed"
[[ $failures -eq 0 ]]
