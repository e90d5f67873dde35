#!/usr/bin/env bash
# zcheck export end to end: one file per format, oiiotool accepts each, the sidecar says
# enough to reinterpret the file, a failed export keeps the old file, bad input exits 2.
set -euo pipefail
source "$(dirname "$0")/lib.sh"
zcheck=$1
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
cd "$tmp"

"$zcheck" export --scene builtin:default --quantity eye-z,distance,window,ndc,position-eye,position-world,normal,primitive-id \
    -o all.exr --preview preview.png > /dev/null
"$zcheck" export --backend raster --quantity eye-z -o depth.pfm > /dev/null
"$zcheck" export --backend ray --quantity distance -o distance.tif > /dev/null
"$zcheck" export --quantity eye-z --scale 1000 -o depth_mm.png > /dev/null
"$zcheck" export --quantity normal -o normal.pfm > /dev/null
for f in all.exr depth.pfm distance.tif depth_mm.png normal.pfm preview.png; do
    oiiotool --info "$f" > /dev/null || { echo "oiiotool rejects $f"; exit 1; }
    [[ "$f" == preview.png || -s "$f.json" ]] || { echo "no sidecar for $f"; exit 1; }
done
oiiotool --info -v all.exr | grep -q "id (uint)"

# Reinterpret the PNG from its sidecar alone: stored / scale = eye-z; the sidecar's camera
# unprojects it onto the same points as the float export of the same quantity.
python3 - <<'PY'
import json
side = json.load(open("depth_mm.png.json"))
assert side["format"] == "png" and side["scale"] == 1000, side
ch = side["channels"][0]
assert ch["quantity"] == "eye-z" and ch["miss_value"] == 0 and ch["type"] == "uint16", ch
assert side["width"] == 640 and side["height"] == 480
assert "top row" in side["orientation"]
json.dump(side["camera"], open("camera.json", "w"))
pfm = json.load(open("depth.pfm.json"))
assert "bottom to top" in pfm["orientation"] and pfm["backend"] == "raster"
allside = json.load(open("all.exr.json"))
names = [c["name"] for c in allside["channels"]]
assert names == ["Z", "distance", "window", "ndc", "P.X", "P.Y", "P.Z", "Pw.X", "Pw.Y", "Pw.Z", "N.X", "N.Y", "N.Z", "id"], names
miss = {c["name"]: c["miss_value"] for c in allside["channels"]}
assert miss["Z"] == "inf" and miss["P.X"] == "nan" and miss["id"] == 4294967295 and miss["window"] == 1.0, miss
for key in ("zcheck_version", "convention", "depth", "camera", "matrices", "scene", "pixel_centres"):
    assert key in allside, key
PY
"$zcheck" unproject --camera camera.json --depth-map depth_mm.png --scale 1000 --quantity eye-z -o from_png.ply > png.json
"$zcheck" export --quantity eye-z -o depth.exr > /dev/null
"$zcheck" unproject --camera camera.json --depth-map depth.exr --quantity eye-z -o from_exr.ply > exr.json
python3 - <<'PY'
import json
png, exr = json.load(open("png.json")), json.load(open("exr.json"))
assert png["points"] == exr["points"] > 100000, (png, exr)
PY

# A failed export (overflow) leaves the existing file as it was.
cp depth_mm.png before.png
set +e
out=$("$zcheck" export --quantity eye-z --scale 100000 -o depth_mm.png 2>&1 >/dev/null)
status=$?
set -e
[[ $status -eq 2 ]] && grep -q "largest scale that fits" <<<"$out"
cmp -s depth_mm.png before.png
[[ -z "$(find . -name '.*tmp*')" ]]

expect_error 2 "unknown format" export --quantity eye-z -o depth.jpg
expect_error 2 "unknown quantity" export --quantity depth -o x.exr
expect_error 2 "only as .exr" export --quantity eye-z,distance -o x.tif
expect_error 2 "PFM" export --quantity primitive-id -o x.pfm
expect_error 2 "scale" export --quantity eye-z -o x.png
expect_error 2 "backend" export --backend gpu -o x.exr
expect_error 2 "needs -o" export --quantity eye-z
echo "cli_export: 1 passed, 0 failed"
