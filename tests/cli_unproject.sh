#!/usr/bin/env bash
# zcheck unproject end to end: rays through hand-computed points, points from every
# quantity, whole depth maps to PLY with misses skipped, and bad input.
set -euo pipefail
source "$(dirname "$0")/lib.sh"
zcheck=$1
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

# Camera at the origin looking down world −z, fovy 90°, 2×2 pixels: the centre of pixel
# (0,0) (top-left) sits at NDC (−½, ½), so its ray runs along (−½, ½, −1) in world space;
# in eye space that is (−½, ½, −1) for opengl (looks down −Z) and (−½, ½, +1) for direct3d.
for convention in opengl direct3d; do
    printf '{"convention": "%s", "image": {"width": 2, "height": 2}, "projection": {"type": "perspective", "fovy_deg": 90, "near": 0.5, "far": 10}, "view": {"eye": [0, 0, 0], "target": [0, 0, -1], "up": [0, 1, 0]}}' \
        "$convention" > "$tmp/$convention.json"
    printf '{"convention": "%s", "image": {"width": 3, "height": 3}, "projection": {"type": "perspective", "fovy_deg": 90, "near": 0.5, "far": 10}, "view": {"eye": [0, 0, 0], "target": [0, 0, -1], "up": [0, 1, 0]}}' \
        "$convention" > "$tmp/$convention-3.json"
    "$zcheck" unproject --camera "$tmp/$convention.json" --pixel 0,0 > "$tmp/corner.json"
    "$zcheck" unproject --camera "$tmp/$convention.json" --pixel 1,1 > "$tmp/corner2.json"
    "$zcheck" unproject --camera "$tmp/$convention-3.json" --pixel 1,1 > "$tmp/centre.json"
    "$zcheck" unproject --camera "$tmp/$convention.json" --pixel 0,0 --depth 2 --quantity eye-z > "$tmp/eyez.json"
    "$zcheck" unproject --camera "$tmp/$convention.json" --pixel 0,0 --depth 2.449489742783178 --quantity distance > "$tmp/distance.json"
    # window depth of eye-z 2 (n = 0.5, f = 10): f(z − n)/(z(f − n)), the same in [−1,1] and [0,1] conventions
    "$zcheck" unproject --camera "$tmp/$convention.json" --pixel 0,0 --depth 0.7894736842105263 --quantity window > "$tmp/window.json"
    python3 - "$tmp" "$convention" <<'PY'
import json, math, sys
tmp, convention = sys.argv[1], sys.argv[2]
def load(name): return json.load(open(f"{tmp}/{name}.json"))
def close(a, b, tol=1e-9): return all(abs(x - y) <= tol for x, y in zip(a, b))
def unit(v): n = math.sqrt(sum(x * x for x in v)); return [x / n for x in v]
eye_z_sign = -1 if convention == "opengl" else 1
corner = load("corner")["ray"]
assert close(corner["world"]["direction"], unit([-0.5, 0.5, -1])), corner
assert close(corner["eye"]["direction"], unit([-0.5, 0.5, eye_z_sign])), corner
assert close(corner["world"]["origin"], [0, 0, 0]), corner
assert abs(corner["world"]["t_near"] - 0.5 * math.sqrt(1.5)) < 1e-9, corner
corner2 = load("corner2")["ray"]
assert close(corner2["world"]["direction"], unit([0.5, -0.5, -1])), corner2
centre = load("centre")["ray"]
assert close(centre["world"]["direction"], [0, 0, -1]), centre
assert close(centre["eye"]["direction"], [0, 0, eye_z_sign]), centre
for name in ("eyez", "distance", "window"):
    point = load(name)["point"]
    assert close(point["world"], [-1, 1, -2], 1e-6), (name, point)
    assert abs(point["eye_z"] - 2) < 1e-6, (name, point)
PY
done

# A whole depth map: the ray route's window depth from `check --out`, misses at the clear value.
"$zcheck" check --scene builtin:default --width 160 --height 120 --out "$tmp/out" > /dev/null
python3 - "$tmp" <<'PY'
import json, sys
tmp = sys.argv[1]
report = json.load(open(f"{tmp}/out/report.json"))
json.dump(report["camera"], open(f"{tmp}/camera.json", "w"))
p = report["pixels"]
open(f"{tmp}/expected", "w").write(str(p["both_hit"] + p["ray_only"]))
PY
"$zcheck" unproject --camera "$tmp/camera.json" --depth-map "$tmp/out/ray_depth.exr" --quantity window -o "$tmp/cloud.ply" > "$tmp/summary.json"
"$zcheck" unproject --camera "$tmp/camera.json" --depth-map "$tmp/out/ray_depth.exr" --quantity window -o "$tmp/cloud-ascii.ply" --ascii --space eye --stride 2 > /dev/null
python3 - "$tmp" <<'PY'
import json, struct, sys
tmp = sys.argv[1]
expected = int(open(f"{tmp}/expected").read())
summary = json.load(open(f"{tmp}/summary.json"))
assert summary["points"] == expected, (summary, expected)
assert summary["points"] + summary["misses"] == 160 * 120
data = open(f"{tmp}/cloud.ply", "rb").read()
header, body = data.split(b"end_header\n", 1)
assert b"format binary_little_endian 1.0" in header and f"element vertex {expected}".encode() in header
assert len(body) == 12 * expected
xyz = struct.unpack(f"<{3 * expected}f", body)
assert all(abs(v) < 1e3 for v in xyz)
text = open(f"{tmp}/cloud-ascii.ply").read()
head, rows = text.split("end_header\n", 1)
count = int([l for l in head.splitlines() if l.startswith("element vertex")][0].split()[2])
assert count == len(rows.splitlines()) and 0 < count < expected
PY

# regression: an eye-z or distance value needs no near and far, yet an OpenCV calibration without
# them was refused. Pixel (0, 0) of fx = fy = 500, cx = 319.5, cy = 239.5: the ray (−0.639, −0.479, 1)
# (the top-left pixel's centre is 0 in OpenCV's coordinates), so eye-z 2.5 and distance 2.5 / |ray|.
cat > "$tmp/calibration.yml" << 'YML'
%YAML:1.0
---
image_width: 640
image_height: 480
camera_matrix: !!opencv-matrix
   rows: 3
   cols: 3
   dt: d
   data: [ 500., 0., 319.5, 0., 500., 239.5, 0., 0., 1. ]
YML
"$zcheck" unproject --camera "$tmp/calibration.yml" --pixel 0,0 --depth 2.5 --quantity eye-z > "$tmp/eyez_point.json"
"$zcheck" unproject --camera "$tmp/calibration.yml" --pixel 0,0 --depth 2.5 --quantity distance > "$tmp/distance_point.json"
python3 - "$tmp/eyez_point.json" "$tmp/distance_point.json" << 'PY'
import json, math, sys
eyez, distance = (json.load(open(p))["point"] for p in sys.argv[1:3])
ray = (-319.5 / 500, -239.5 / 500, 1.0)
norm = math.sqrt(sum(c * c for c in ray))
assert all(abs(a - 2.5 * c) < 1e-9 for a, c in zip(eyez["eye"], ray)), eyez
assert abs(eyez["distance"] - 2.5 * norm) < 1e-9, eyez
assert abs(distance["eye_z"] - 2.5 / norm) < 1e-9 and abs(distance["distance"] - 2.5) < 1e-9, distance
PY
# Window depth does depend on them: still refused.
expect_error 2 "has no near and far in its file" unproject --camera "$tmp/calibration.yml" --pixel 0,0 --depth 0.5 --quantity window

# Bad input: exit 2 with a message, and an existing output survives.
echo precious > "$tmp/keep.ply"
expect_error 2 "cannot read depth map" unproject --camera "$tmp/camera.json" --depth-map "$tmp/missing.exr" -o "$tmp/keep.ply"
grep -q precious "$tmp/keep.ply"
expect_error 2 "160x120 but the camera" unproject --camera "$tmp/opengl.json" --depth-map "$tmp/out/ray_depth.exr" -o "$tmp/x.ply"
expect_error 2 "outside" unproject --camera "$tmp/opengl.json" --pixel 2,0
expect_error 2 "unknown depth quantity" unproject --camera "$tmp/opengl.json" --pixel 0,0 --depth 1 --quantity depth
expect_error 2 "needs --pixel" unproject --camera "$tmp/opengl.json"
oiiotool "$tmp/out/ray_depth.exr" -d uint16 -o "$tmp/depth16.png"
expect_error 2 "give --scale" unproject --camera "$tmp/camera.json" --depth-map "$tmp/depth16.png" -o "$tmp/x.ply"
echo "cli_unproject: 1 passed, 0 failed"
