#!/usr/bin/env bash
# zcheck verify end to end, the README's worked example: a map exported from the raster
# route verifies (float EXR and millimetre PNG); a wrong one is rejected and diagnosed.
set -euo pipefail
source "$(dirname "$0")/lib.sh"
zcheck=$1
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
cd "$tmp"
"$zcheck" export --backend raster --quantity eye-z,distance,window -o render.exr > /dev/null
"$zcheck" export --backend raster --quantity eye-z --scale 1000 -o render_mm.png > /dev/null
"$zcheck" verify --depth-map render.exr --quantity eye-z > ok.txt
grep -q "verdict    CONSISTENT" ok.txt
"$zcheck" verify --depth-map render_mm.png --scale 1000 --quantity eye-z > ok_png.txt
grep -q "verdict    CONSISTENT" ok_png.txt

# The classic mistake: ray distance delivered as if it were eye-z.
oiiotool render.exr --ch distance -o distance.exr
set +e
"$zcheck" verify --depth-map distance.exr --quantity eye-z --diagnose --out out > wrong.txt
status=$?
set -e
[[ $status -eq 1 ]]
grep -q "verdict    INCONSISTENT" wrong.txt
grep -q "diagnosis  consistent if read as ray distance instead of eye-z" wrong.txt
for f in ray_depth.exr map_depth.exr error_heatmap.png coverage_classes.png report.json; do [[ -s "out/$f" ]]; done
python3 -c "
import json; r = json.load(open('out/report.json'))
assert r['consistent'] is False and r['depth_map']['quantity'] == 'eye-z'
assert any(h['consistent'] and h['hypothesis'] == 'distance-as-eye-z' for h in r['diagnosis'])"

# Bad input exits 2.
expect_error 2 "cannot read depth map" verify --depth-map missing.exr
expect_error 2 "scale" verify --depth-map render_mm.png --quantity eye-z
expect_error 2 "unknown" verify --depth-map render.exr --quantity depth
expect_error 2 "--width" verify --depth-map render.exr --width 3
expect_error 2 "depth-map" verify
echo "cli_verify: 1 passed, 0 failed"
