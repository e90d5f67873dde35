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
grep -q "^lens configurations: 5 consistent of 5 (lens check and clean map; false positives: 0)" "$tmp/table.txt"
! grep -q "MISSED\|MISNAMED\|FALSE POSITIVE" "$tmp/table.txt"
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
# The lens part (suite.h): 5 lens cameras on builtin:default, each clean and with every mistake of
# the lens family injected; none a false positive, every applicable mistake detected and named.
lens = r["lens"]
assert lens["passed"] is True and lens["false_positives"] == 0 and lens["missed_faults"] == 0 and lens["misnamed_faults"] == 0, lens["detection"]
models = sorted({c["model"] for c in lens["configurations"]})
assert models == ["double_sphere", "equirectangular", "opencv", "opencv rational", "opencv_fisheye"], models
for c in lens["configurations"]:
    assert c["clean"]["check_consistent"] and c["clean"]["map_consistent"], c["label"]
    assert c["camera"]["lens"]["model"] == c["model"].split(" ")[0], c["camera"]
    for name, m in c["mistakes"].items():
        assert m["result"] in ("detected", "not applicable", "-"), (c["label"], name, m)
        assert m["named"] == (m["result"] == "detected"), (c["label"], name, m)
names = {row["name"] for row in lens["detection"].values()}
family = {"distortion-ignored", "undistorted-new-k", "coefficient-order", "tangential-swapped", "distortion-signs-flipped",
          "fisheye-model", "y-flip", "x-flip", "half-pixel", "cx-cy-swapped", "distance-as-eye-z", "eye-z-as-distance"}
assert names == family, names ^ family
for key, row in lens["detection"].items():
    assert row["detected"] == row["applicable"] == row["named"] and row["applicable"] > 0, (key, row)
assert sum(row["applicable"] for row in lens["detection"].values()) >= 50, lens["detection"]
html = open(f"{tmp}/suite.html").read()
assert "<h2>Lens cameras</h2>" in html
assert "<h1>zcheck suite: PASSED</h1>" in html and "http" not in html.replace("charset", "")
PY
# --filter narrows the matrix; a filter matching nothing is a usage error.
"$zcheck" suite --quick --models "$models" --filter "pinhole" > "$tmp/pinhole.txt"
grep -q "configurations x 21 faults" "$tmp/pinhole.txt"
grep -q "^lens configurations: 0 consistent of 0" "$tmp/pinhole.txt"
# ... and applies to the lens part: its labels name the lens model.
"$zcheck" suite --quick --models "$models" --filter "opencv_fisheye" > "$tmp/fisheye.txt"
grep -q "^lens configurations: 1 consistent of 1 " "$tmp/fisheye.txt"
grep -q "^fisheye-model  *equisolid  *1 / 1  *0  *1 / 1" "$tmp/fisheye.txt"
grep -q "verdict    PASSED" "$tmp/fisheye.txt"
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
