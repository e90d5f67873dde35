#!/usr/bin/env bash
# The dataset report as a person reads it: `zcheck dataset report` run from another folder than
# the results file, the page opened in a real browser (Debian's Chromium, headless), its DOM and a
# screenshot checked: a picture of the true depth beside each failing frame's map, a legend for
# the coverage classes, the histogram coloured by verdict (an inconsistent frame red even where
# nothing was compared), named frames said once ("consistent if", not "consistent if consistent
# if"), no "pictures unavailable"; summary.json's verdict a verdict.
#   tests/report_html_chromium.sh ZCHECK   (skipped, exit 77, without chromium)
set -euo pipefail
zcheck=$(realpath "$1")
browser=$(command -v chromium || true)
if [[ -z $browser ]]; then
    echo "report_html_chromium: skipped: no chromium (apt-get install chromium)"
    exit 77
fi
tmp=$(mktemp -d)
browser_pid=""
cleanup() {
    [[ -n $browser_pid ]] && kill "$browser_pid" 2> /dev/null || true
    rm -rf "$tmp"
}
trap cleanup EXIT
mkdir -p "$tmp/data" "$tmp/elsewhere"
cd "$tmp/data"
# Four frames of the default scene from four eyes, each map exported with its sidecar (its camera).
for k in 0 1 2 3; do
    x=$(python3 -c "print(4 + $k)")
    cat > "cam$k.json" << JSON
{"convention": "opengl", "image": {"width": 160, "height": 120},
 "projection": {"type": "perspective", "fovy_deg": 50, "near": 0.1, "far": 100},
 "view": {"eye": [$x, 4, 9], "target": [0, 0.5, 0], "up": [0, 1, 0]}}
JSON
    "$zcheck" export --camera "cam$k.json" --quantity eye-z -o "f$k.exr" > /dev/null
done
oiiotool f1.exr --flip -o f1.exr                       # frame 1: upside down
"$zcheck" export --camera cam0.json --quantity eye-z -o f3.exr > /dev/null   # frame 3: another frame's camera
for k in 0 1 2 3; do
    echo "{\"frame\": \"f$k\", \"depth\": \"f$k.exr\", \"camera\": \"cam$k.json\", \"quantity\": \"eye-z\"}"
done > manifest.jsonl
set +e
"$zcheck" dataset verify manifest.jsonl --scene builtin:default --diagnose -o results.jsonl > verify.txt
status=$?
set -e
[[ $status -eq 1 ]]
grep -q "frames     4 recorded: 2 consistent, 2 inconsistent" verify.txt
# The report made from another folder: the records' paths resolve from the results file's folder.
cd "$tmp/elsewhere"
set +e
"$zcheck" dataset report "$tmp/data/results.jsonl" --out report > report.txt 2> report.err
status=$?
set -e
[[ $status -eq 1 ]]
if grep -q "no pictures" report.err; then
    echo "report_html_chromium: FAIL: pictures unavailable: $(cat report.err)"
    exit 1
fi
python3 - report/summary.json << 'PY'
import json, sys
s = json.load(open(sys.argv[1]))
assert s["verdict"] == "INCONSISTENT" and s["inconsistent"] == 2, s
PY
# The browser: the DOM as it renders it, and a screenshot.
page="file://$tmp/elsewhere/report/report.html"
timeout 120 "$browser" --headless --no-sandbox --disable-gpu --hide-scrollbars --dump-dom "$page" > dom.html 2> browser.log &
browser_pid=$!
wait "$browser_pid"
browser_pid=""
timeout 120 "$browser" --headless --no-sandbox --disable-gpu --hide-scrollbars --window-size=1300,2600 \
    --screenshot="$tmp/elsewhere/shot.png" "$page" >> browser.log 2>&1 &
browser_pid=$!
wait "$browser_pid"
browser_pid=""
test -s shot.png
oiiotool shot.png --ch R,G,B -d uint8 -o shot.ppm
python3 - dom.html shot.ppm << 'PY'
import re, sys
dom = open(sys.argv[1], encoding="utf-8").read()
assert "consistent if consistent if" not in dom, "the explanation said twice"
assert "pictures unavailable" not in dom
assert dom.count("<figure class=\"truth\">") == 2, "a truth picture beside each failing frame's map"
assert dom.count("<figure class=\"map\">") == 2
legend = re.findall(r"<div class=\"legend\">(.*?)</div>", dom)
assert len(legend) == 2 and all(name in legend[0] for name in ("agree", "depth-error", "map-only", "ray-only", "both-miss")), legend[:1]
assert "y-flip" in dom and "another-frame-camera" in dom, "both failing frames named"
bars = re.findall(r"<rect class=\"(consistent|inconsistent)\"[^>]*height=\"(\d+)\"", dom)
assert sum(int(h) for c, h in bars if c == "inconsistent") > 0 and sum(int(h) for c, h in bars if c == "consistent") > 0, bars
# The screenshot: the histogram's two verdict colours and the legend's swatches are on screen.
data = open(sys.argv[2], "rb").read()
header = re.match(rb"P6\s+(\d+)\s+(\d+)\s+255\s", data)
w, h = int(header.group(1)), int(header.group(2))
pixels = data[header.end():]
seen = set(pixels[i:i + 3] for i in range(0, len(pixels) - 2, 3 * 7))
for name, rgb in {"inconsistent bar": (0xc0, 0x39, 0x2b), "consistent bar": (0x1e, 0x84, 0x49),
                  "agree (legend and pictures)": (70, 160, 70), "depth error": (230, 30, 30)}.items():
    assert bytes(rgb) in seen, f"no {name} colour on screen"
print(f"report_html_chromium: {w}x{h} screenshot; DOM and picture checked")
PY
echo "report_html_chromium: 1 passed, 0 failed"
