#!/usr/bin/env bash
# `zcheck check` end to end through the executable: exit status, the summary, --json and
# the files --out writes.
set -euo pipefail
source "$(dirname "$0")/lib.sh"
zcheck=$1
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

"$zcheck" check > "$tmp/summary.txt"
grep -q "verdict    CONSISTENT" "$tmp/summary.txt"
grep -q "both hit" "$tmp/summary.txt"

"$zcheck" check --scene "builtin:terrain?n=50" --convention vulkan --reversed-z --json > "$tmp/report.json"
python3 - "$tmp/report.json" <<'PY'
import json, sys
r = json.load(open(sys.argv[1]))
assert r["consistent"] is True, r
p = r["pixels"]
assert p["both_hit"] + p["both_miss"] + p["ray_only"] + p["raster_only"] == p["total"] == 640 * 480, p
assert r["camera"]["convention"] == "vulkan" and r["camera"]["depth"]["reversed"] is True
PY

# An existing output file survives a run that fails before writing.
mkdir -p "$tmp/out"
echo "precious" > "$tmp/out/report.json"
set +e
"$zcheck" check --camera "$tmp/missing.json" --out "$tmp/out" 2>/dev/null
status=$?
set -e
[[ $status -eq 2 ]]
grep -q precious "$tmp/out/report.json"

"$zcheck" check --width 97 --height 61 --out "$tmp/out" > /dev/null
for f in ray_depth.exr raster_depth.exr error_heatmap.png coverage_classes.png report.json; do
    [[ -s "$tmp/out/$f" ]] || { echo "missing $f"; exit 1; }
done
python3 -c "import json,sys; r=json.load(open('$tmp/out/report.json')); assert r['pixels']['total'] == 97*61"
# No temporaries left behind.
[[ -z "$(find "$tmp/out" -name '.*tmp*')" ]]
if command -v oiiotool > /dev/null; then
    oiiotool --info "$tmp/out/ray_depth.exr" | grep -Eq '97 x +61'
fi
echo "cli_check_outputs: 1 passed, 0 failed"
