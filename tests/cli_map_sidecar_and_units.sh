#!/usr/bin/env bash
# verify and unproject with maps as zcheck's own export describes them: the sidecar supplies the
# camera and the quantity; a conflicting --camera is refused naming both. Values a quantity cannot
# hold are counted and named, never dropped. verify's report speaks of the map, in its units.
set -euo pipefail
source "$(dirname "$0")/lib.sh"
zcheck=$1
examples=$2
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
cd "$tmp"

# Regression: verify --sidecar ignored the camera in zcheck's own export sidecar and used the
# scene's default camera, so a correct map was reported INCONSISTENT. (The camera: the example's
# with its eye moved, so that it is not the scene's own.)
python3 -c "
import json; c = json.load(open('$examples/perspective.json')); c['view']['eye'] = [2.0, 2.9, 5.1]
json.dump(c, open('moved.json', 'w'))"
"$zcheck" export --backend raster --camera moved.json --quantity eye-z -o seen.exr > /dev/null
"$zcheck" verify --depth-map seen.exr --sidecar seen.exr.json > seen.txt
grep -q "verdict    CONSISTENT" seen.txt
grep -q "channel 'Z' (eye-z)" seen.txt  # the quantity came from the sidecar too
grep -q "perspective, 640x480" seen.txt
# Without the sidecar the scene's camera is not the map's: rejected.
set +e
"$zcheck" verify --depth-map seen.exr --quantity eye-z > /dev/null
status=$?
set -e
[[ $status -eq 1 ]]
# The same camera given twice is fine; another one is refused, naming both files.
"$zcheck" verify --depth-map seen.exr --sidecar seen.exr.json --camera moved.json | grep -q "verdict    CONSISTENT"
expect_error 2 "--camera '.*orthographic.json' and the camera in sidecar 'seen.exr.json' .* differ in the pose or the projection" \
    verify --depth-map seen.exr --sidecar seen.exr.json --camera "$examples/orthographic.json"
# A window map: another depth range is another camera for it (not for an eye-z map).
"$zcheck" export --backend raster --camera moved.json --quantity window -o window.exr > /dev/null
python3 -c "
import json; c = json.load(open('moved.json')); c['projection']['far'] = 50
json.dump(c, open('far50.json', 'w'))"
expect_error 2 "differ in the depth mapping" verify --depth-map window.exr --sidecar window.exr.json --camera far50.json
"$zcheck" verify --depth-map seen.exr --sidecar seen.exr.json --camera far50.json | grep -q "verdict    CONSISTENT"
# A sidecar listing several depth channels names them when neither --quantity nor --channel says.
"$zcheck" export --backend raster --camera moved.json --quantity eye-z,distance -o both.exr > /dev/null
expect_error 2 "lists several depth channels — Z \\(eye-z\\), distance \\(distance\\): give --channel or --quantity" \
    verify --depth-map both.exr --sidecar both.exr.json
"$zcheck" verify --depth-map both.exr --sidecar both.exr.json --channel distance | grep -q "channel 'distance' (distance)"
# unproject takes the camera from the sidecar as well.
"$zcheck" unproject --depth-map seen.exr --sidecar seen.exr.json -o cloud.ply > cloud.json
python3 -c "
import json; r = json.load(open('cloud.json'))
assert r['quantity'] == 'eye-z' and r['points'] > 1000 and r['out_of_range'] == 0, r"
expect_error 2 "unproject needs --camera FILE" unproject --depth-map seen.exr --quantity eye-z -o cloud2.ply
# A dataset manifest line's "sidecar" does the same.
printf '{"frame": "a", "depth": "seen.exr", "sidecar": "seen.exr.json"}\n' > manifest.jsonl
"$zcheck" dataset verify manifest.jsonl -o results.jsonl > /dev/null
python3 -c "
import json; r = json.loads(open('results.jsonl').readline())
assert r['consistent'] and r['depth_map']['quantity'] == 'eye-z', r"
printf '{"frame": "a", "depth": "seen.exr", "sidecar": "seen.exr.json", "camera": "%s"}\n' "$examples/orthographic.json" > clash.jsonl
set +e
"$zcheck" dataset verify clash.jsonl -o clash.jsonl.results > /dev/null 2>&1
set -e
python3 -c "
import json; r = json.loads(open('clash.jsonl.results').readline())
assert not r['consistent'] and 'differ in' in r['error'], r"

# Values a quantity cannot hold: a window map holding 2 in a block is inconsistent, and the report
# names them (count, first pixel, the rule); a map holding nothing else is refused.
oiiotool window.exr --ch window --fill:color=2 40x30+100+100 -o two.exr
set +e
"$zcheck" verify --depth-map two.exr --camera moved.json --quantity window > two.txt
status=$?
set -e
[[ $status -eq 1 ]]
grep -q "OUT OF RANGE (errors)" two.txt
grep -q "a window map holds values in \[0, 1\], the camera's depth range), e.g. 2 stored at (100, 100)" two.txt
"$zcheck" verify --depth-map two.exr --camera moved.json --quantity window --json > two.json || true
python3 -c "
import json; r = json.load(open('two.json'))
assert r['pixels']['out_of_range'] == 1200 and r['out_of_range']['first'] == {'col': 100, 'row': 100, 'stored': 2.0}, r['out_of_range']
assert not r['consistent']"
oiiotool window.exr --ch window --fill:color=2 640x480+0+0 -o all_two.exr
expect_error 2 "depth map 'all_two.exr': it holds no window depth — 307200 values lie outside \\[0, 1\\]" \
    verify --depth-map all_two.exr --camera moved.json --quantity window
# unproject: no point for them, and it says so (stderr and the JSON); nothing else: refused.
"$zcheck" unproject --depth-map two.exr --camera moved.json --quantity window -o two.ply > two_cloud.json 2> two_cloud.err
grep -q "warning: 1200 values of 'two.exr' lie outside what a window map holds" two_cloud.err
python3 -c "
import json; r = json.load(open('two_cloud.json')); assert r['out_of_range'] == 1200, r"
expect_error 2 "307200 values of 'all_two.exr' lie outside what a window map holds, \\[0, 1\\].*the rest are misses" \
    unproject --depth-map all_two.exr --camera moved.json --quantity window -o all_two.ply
[[ ! -e all_two.ply ]]

# The report in the map's units: a map 1 % too far has relative errors of 1 % and absolute ones of
# 1 % of the true eye-z (but at occlusion edges, where the map shows the surface behind: there
# the error is the gap between the surfaces); the per-pixel error map holds map - truth.
oiiotool seen.exr --ch Z --mulc 1.01 -o far1.exr
"$zcheck" verify --depth-map far1.exr --sidecar seen.exr.json --out far1 --json > far1.json || true
python3 - <<'EOF'
import json
r = json.load(open('far1.json'))
e = r['map_errors']
assert e['quantity'] == 'eye-z' and not e['eye_z_equivalent'], e
assert abs(e['median_rel'] - 0.01) < 1e-6 and abs(e['p99_rel'] - 0.01) < 1e-4 and e['max_rel'] >= 0.01, e
w = e['worst_pixel']
assert abs(e['max_abs'] - abs(w['map'] - w['true'])) < 1e-9 and e['compared'] > 100000, e
assert 'map_only' in r['pixels'] and 'raster_only' not in r['pixels'], r['pixels']
assert 'map_window_depth' in r['depth_error']['worst_pixel'] and 'raster' not in r['timings_ms'], r
EOF
[[ -s far1/map_error.exr ]]
oiiotool --dumpdata far1/map_error.exr > err.txt
oiiotool --dumpdata seen.exr > z.txt
python3 - <<'EOF'
import math, re
def pixels(path):  # oiiotool --dumpdata: "Pixel (x, y): v"
    return {(int(x), int(y)): float(v) for x, y, v in re.findall(r"Pixel \((\d+), (\d+)\): (\S+)", open(path).read())}
err, z = pixels('err.txt'), pixels('z.txt')
assert len(err) == len(z) == 640 * 480
compared = [p for p, e in err.items() if math.isfinite(e)]
assert len(compared) > 100000, len(compared)
# map - truth = 0.01 * truth (to 2 % of itself) where the map shows the truth's surface (the raster's eye-z is the
# truth's but for its slope credit), and nothing where nothing is seen
close = sum(abs(err[p] - 0.01 * z[p]) <= 2e-4 * z[p] for p in compared)
assert close > 0.99 * len(compared), close / len(compared)
assert all(math.isfinite(z[p]) for p in compared)
EOF
"$zcheck" verify --depth-map far1.exr --sidecar seen.exr.json > far1.txt || true
grep -q "map - truth (eye-z), in the map's units, over the" far1.txt
grep -q "map only" far1.txt
! grep -q "raster" far1.txt
# A window map reports eye-z equivalents beside its quanta.
"$zcheck" verify --depth-map window.exr --sidecar window.exr.json --json | python3 -c "
import json, sys; e = json.load(sys.stdin)['map_errors']
assert e['quantity'] == 'eye-z' and e['eye_z_equivalent'] and e['max_rel'] < 1e-3 and e['median_rel'] < 1e-5, e"
echo "cli_map_sidecar_and_units: all passed"
