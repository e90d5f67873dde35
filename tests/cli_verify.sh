#!/usr/bin/env bash
# zcheck verify end to end, docs/verify.md's example: a map exported from the raster
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

# Eye-z values declared as window depth hold no window depth: refused (exit 2), and with
# --diagnose the refusal says what they are (regression: it said nothing more under --diagnose).
oiiotool render.exr --ch Z -o eyez_only.exr
expect_error 2 "holds no window depth .*is the quantity right\?$" verify --depth-map eyez_only.exr --quantity window
expect_error 2 "holds no window depth .*--diagnose: its values are consistent read as eye-z \(pass --quantity eye-z\)$" \
    verify --depth-map eyez_only.exr --quantity window --diagnose
expect_error 2 "--diagnose: its values are consistent read as distance" verify --depth-map render.exr --channel distance \
    --quantity ndc --diagnose

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

# Real renderers' files: a multi-layer EXR with the depth pass beside the colour (as Blender
# writes it) is read from its depth channel, which the report names.
oiiotool render.exr --ch "ViewLayer.Combined.R=window,ViewLayer.Combined.G=window,ViewLayer.Depth.Z=Z" -o layers.exr
"$zcheck" verify --depth-map layers.exr --quantity eye-z > layers.txt
grep -q "verdict    CONSISTENT" layers.txt
grep -q "channel 'ViewLayer.Depth.Z' (eye-z)" layers.txt
"$zcheck" verify --depth-map layers.exr --quantity eye-z --json | python3 -c "
import json, sys; d = json.load(sys.stdin)['depth_map']
assert d['channel'] == 'ViewLayer.Depth.Z' and d['miss'] is None and d['offset'] == 0, d"
# No channel named as depth: refused with the list; --channel names it.
oiiotool render.exr --ch "R=Z,G=Z,B=Z" -o rgb.exr
expect_error 2 "none of its 3 channels \\('R', 'G', 'B'\\) is named as depth" verify --depth-map rgb.exr --quantity eye-z
"$zcheck" verify --depth-map rgb.exr --channel G --quantity eye-z | grep -q "verdict    CONSISTENT"
expect_error 2 "it has no channel 'Depth'; its channels are 'R', 'G', 'B'" verify --depth-map rgb.exr --channel Depth --quantity eye-z
# --offset: a map stored as eye-z - 0.5 reads back with --offset 0.5 (and not without).
oiiotool render.exr --ch Z --subc 0.5 -o minus_half.exr
"$zcheck" verify --depth-map minus_half.exr --offset 0.5 --quantity eye-z | grep -q "verdict    CONSISTENT"
set +e
"$zcheck" verify --depth-map minus_half.exr --quantity eye-z > /dev/null
status=$?
set -e
[[ $status -eq 1 ]]
# --miss: a renderer that marks "no surface" as 1e10 is inconsistent read as depth, consistent
# with --miss '>=1e9'.
oiiotool render.exr --ch Z --clamp:max=1e10 -o far_misses.exr
set +e
"$zcheck" verify --depth-map far_misses.exr --quantity eye-z > far.txt
status=$?
set -e
[[ $status -eq 1 ]]
"$zcheck" verify --depth-map far_misses.exr --quantity eye-z --miss '>=1e9' | grep -q "verdict    CONSISTENT"
expect_error 2 "miss value 'abc' is neither a number" verify --depth-map render.exr --quantity eye-z --miss abc
# The same rule from a sidecar (other keys ignored); an option wins over the sidecar's key.
echo '{"miss": ">=1e9", "renderer": "another one"}' > far_misses.json
"$zcheck" verify --depth-map far_misses.exr --quantity eye-z --sidecar far_misses.json | grep -q "verdict    CONSISTENT"
echo '{"miss": 1e10}' > exact_miss.json
"$zcheck" verify --depth-map far_misses.exr --quantity eye-z --sidecar exact_miss.json | grep -q "verdict    CONSISTENT"
set +e
"$zcheck" verify --depth-map far_misses.exr --quantity eye-z --sidecar far_misses.json --miss 0 > /dev/null
status=$?
set -e
[[ $status -eq 1 ]]
echo '{"miss": true}' > bad_miss.json
expect_error 2 "sidecar 'bad_miss.json': \"miss\" must be a number or a string" verify --depth-map far_misses.exr --quantity eye-z --sidecar bad_miss.json
echo '{"scale": -3}' > bad_scale.json
expect_error 2 "\"scale\" must be a positive finite number" verify --depth-map far_misses.exr --quantity eye-z --sidecar bad_scale.json
echo '{"miss": 1, "miss": 2}' > twice.json
expect_error 2 "twice.json" verify --depth-map far_misses.exr --quantity eye-z --sidecar twice.json

# Maps as pipelines and sensors deliver them (issue 36): each accepted with what its reading
# declares, rejected without it, and the diagnosis names the option.
# Half floats (an EXR HALF channel) carry their own step: no option needed.
oiiotool render.exr --ch Z -d half -o half.exr
"$zcheck" verify --depth-map half.exr --quantity eye-z | grep -q "verdict    CONSISTENT"
# Millimetre-rounded float metres: --quantum 0.001.
"$zcheck" export --backend raster --quantity eye-z -o z.pfm > /dev/null
python3 - <<'PY'
import struct
with open("z.pfm", "rb") as f:
    head = [f.readline() for _ in range(3)]
    data = f.read()
n = len(data) // 4
values = struct.unpack("<%df" % n, data) if float(head[2]) < 0 else struct.unpack(">%df" % n, data)
rounded = [round(v * 1000) / 1000 if v != float("inf") else v for v in values]
cycles = [1e10 if v == float("inf") else v for v in values]
for name, vals in (("mm.pfm", rounded), ("cycles.pfm", cycles)):
    with open(name, "wb") as f:
        f.write(head[0] + head[1] + b"-1.0\n" + struct.pack("<%df" % n, *vals))
PY
set +e
"$zcheck" verify --depth-map mm.pfm --quantity eye-z --diagnose > mm.txt
status=$?
set -e
[[ $status -eq 1 ]]
grep -q "the map's values lie on a 0.001 grid: consistent with --quantum 0.001" mm.txt
"$zcheck" verify --depth-map mm.pfm --quantity eye-z --quantum 0.001 > mm_ok.txt
grep -q "verdict    CONSISTENT" mm_ok.txt
grep -q "declared   values rounded to 0.001 (--quantum 0.001)" mm_ok.txt
# Cycles' 1e10 where nothing is hit: named, with the rule that reads it.
set +e
"$zcheck" verify --depth-map cycles.pfm --quantity eye-z --diagnose > cycles.txt
set -e
grep -q "pixels where nothing is hit: its miss value (pass --miss '>=1e9')" cycles.txt
"$zcheck" verify --depth-map cycles.pfm --quantity eye-z --miss '>=1e9' | grep -q "verdict    CONSISTENT"
# The same declarations from a sidecar, and --allow-holes counting the holes.
echo '{"quantum": 0.001, "allow_holes": true}' > declared.json
"$zcheck" verify --depth-map mm.pfm --quantity eye-z --sidecar declared.json --json | python3 -c "
import json, sys; d = json.load(sys.stdin)
assert d['consistent'] and d['depth_map']['declared'] == {'quantum': 0.001, 'rel_tolerance': 0, 'abs_tolerance': 0,
                                                           'noise_model': None, 'allow_holes': True}, d['depth_map']
assert d['tolerance']['declared']['quantum'] == 0.001 and d['pixels']['holes'] == 0"
echo '{"rel_tolerance": 2}' > bad_rel.json
expect_error 2 "sidecar 'bad_rel.json': \"rel_tolerance\" must be below 1" verify --depth-map mm.pfm --quantity eye-z --sidecar bad_rel.json
echo '{"allow_holes": "yes"}' > bad_holes.json
expect_error 2 "\"allow_holes\" must be true or false" verify --depth-map mm.pfm --quantity eye-z --sidecar bad_holes.json
expect_error 2 "--rel-tolerance" verify --depth-map mm.pfm --quantity eye-z --rel-tolerance 1.5
expect_error 2 "--quantum" verify --depth-map mm.pfm --quantity eye-z --quantum -1

# Bad input exits 2.
expect_error 2 "cannot read depth map" verify --depth-map missing.exr
expect_error 2 "scale" verify --depth-map render_mm.png --quantity eye-z
expect_error 2 "unknown" verify --depth-map render.exr --quantity depth
expect_error 2 "--width" verify --depth-map render.exr --width 3
expect_error 2 "depth-map" verify
echo "cli_verify: 1 passed, 0 failed"
