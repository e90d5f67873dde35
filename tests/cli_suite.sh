#!/usr/bin/env bash
# zcheck suite --quick: every clean configuration consistent, every applicable fault
# detected, JSON and a self-contained HTML report written into --out, --json printing the same
# document.
set -euo pipefail
source "$(dirname "$0")/lib.sh"
zcheck=$1
models=$2
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
"$zcheck" suite --quick --models "$models" --out "$tmp/run" > "$tmp/table.txt"
grep -q "verdict    PASSED" "$tmp/table.txt"
"$zcheck" suite --quick --models "$models" --json > "$tmp/printed.json"
python3 - "$tmp" <<'PY'
import json, sys
tmp = sys.argv[1]
printed, written = json.load(open(f"{tmp}/printed.json")), json.load(open(f"{tmp}/run/suite.json"))
assert printed["detection"] == written["detection"] and printed["passed"] is True, (printed["detection"], written["detection"])
PY
mv "$tmp/run/suite.json" "$tmp/run/suite.html" "$tmp/"
python3 - "$tmp" <<'PY'
import json, sys
tmp = sys.argv[1]
r = json.load(open(f"{tmp}/suite.json"))
assert r["passed"] is True and r["false_positives"] == 0 and r["missed_faults"] == 0, r["detection"]
assert len(r["configurations"]) >= 10
assert len(r["detection"]) == 21 and "lens-shift-dropped" in r["detection"] and "principal-point-mirrored" in r["detection"] and "x-flip" in r["detection"] and "opencv-opengl-axes" in r["detection"] and "y-flip" in r["detection"]
for name, row in r["detection"].items():
    assert row["detected"] == row["applicable"], (name, row)
# Every fault is applicable somewhere even in the quick subset.
assert all(row["applicable"] > 0 for row in r["detection"].values()), r["detection"]
html = open(f"{tmp}/suite.html").read()
assert "<h1>zcheck suite: PASSED</h1>" in html and "http" not in html.replace("charset", "")
PY
# --filter narrows the matrix; a filter matching nothing is a usage error.
"$zcheck" suite --quick --models "$models" --filter "pinhole" > "$tmp/pinhole.txt"
grep -q "configurations x 21 faults" "$tmp/pinhole.txt"
set +e
"$zcheck" suite --quick --models "$models" --filter "no such configuration" > /dev/null 2>&1
status=$?
set -e
[[ $status -eq 2 ]]
# The old file options are gone: --json takes no value.
set +e
"$zcheck" suite --quick --models "$models" --json "$tmp/x.json" > /dev/null 2> "$tmp/err.txt"
status=$?
set -e
[[ $status -eq 2 ]]
echo "cli_suite: 1 passed, 0 failed"
