#!/usr/bin/env bash
# Blender's panoramic cameras end to end: Cycles renders a closed room through one camera of each
# panoramic type Blender 3.4 has (render_panoramic.py: equirectangular, fisheye equidistant,
# equisolid and lens polynomial, mirror ball, equiangular cubemap face; shifted, sensor fits,
# non-square pixels); zcheck.blender writes each camera, and `zcheck verify` of each Z pass as a
# distance (Cycles's Z pass for panoramic cameras) must say CONSISTENT, the pixels outside a
# fisheye's circle or the mirror ball's disc (1e10, declared the miss value) counted as misses; so
# must `zcheck dataset verify` of write_cameras's manifest. Two wrong cameras must be
# INCONSISTENT: the equidistant fisheye's fov 3 % wider, the equisolid fisheye read as equidistant.
#
#   PYTHONPATH=build/python bash tests/blender/test_blender_panoramic.sh build/cli/zcheck
#
# Blender runs headless and is stopped by its pid after BLENDER_TIMEOUT seconds (default 300).
# BLENDER names the executable (default: blender); without one the test is skipped (exit 77).
set -euo pipefail
zcheck=$1
here=$(cd "$(dirname "$0")" && pwd)
test_name=test_blender_panoramic
default_timeout_s=300
source "$here/harness.sh"
out=$tmp/out

run_blender "$here/render_panoramic.py" "$out"
if [[ $blender_status -ne 0 || ! -s $out/manifest.jsonl || ! -s $out/frames.txt ]]; then
    tail -n 30 "$tmp/blender.log"
    fail "Blender rendered the six panoramic cameras and zcheck.blender wrote them (exit status $blender_status)"
    finish
fi
pass "Blender rendered the six panoramic cameras and zcheck.blender wrote them"

# verify CAMERA FRAME: `zcheck verify` of frame FRAME's Z pass as distances, its report in
# $tmp/verify_NAME.txt, its exit status in $verify_status and its verdict line in $verdict.
verify() {
    local frame report
    frame=$(printf '%04d' "$2")
    report=$tmp/verify_$(basename "$1" .json).txt
    set +e
    "$zcheck" verify --scene "$out/scene.obj" --camera "$1" --depth-map "$out/depth_$frame.exr" \
        --channel ViewLayer.Depth.Z --quantity distance --miss '>=1e9' > "$report" 2>&1
    verify_status=$?
    set -e
    verdict=$(grep -E "^verdict" "$report" || echo "verdict    (none)")
}

while read -r frame name; do
    verify "$out/$name.json" "$frame"
    if [[ $verify_status -eq 0 && $verdict == *CONSISTENT* && $verdict != *INCONSISTENT* ]]; then
        pass "$name: zcheck verify of Cycles's Z pass as distance: $verdict"
    else
        sed 's/^/      /' "$tmp/verify_$name.txt" | head -40
        fail "$name: zcheck verify of Cycles's Z pass as distance: $verdict (exit $verify_status)"
    fi
done < "$out/frames.txt"

# The fisheyes' black pixels: outside the circle the renders hold 1e10 (the declared miss) and
# zcheck's lens has no ray; in a closed room no other pixel misses, so verify's "both miss" must be
# exactly the count of Cycles's formulas (outside.txt, computed apart from zcheck), and not zero.
while read -r name expected; do
    both=$(grep -E "^ *both miss" "$tmp/verify_$name.txt" | awk '{print $3}' || true)
    if [[ $expected -gt 0 && $both == "$expected" ]]; then
        pass "$name: the $both pixels outside the field (Z = 1e10) are misses on both sides, not errors"
    else
        grep -iE "miss|outside" "$tmp/verify_$name.txt" | sed 's/^/      /' || true
        fail "$name: both-miss pixels '$both', expected $expected from Cycles's formulas"
    fi
done < "$out/outside.txt"

for wrong in wrong_fov:2 wrong_model:3; do
    verify "$out/${wrong%%:*}.json" "${wrong##*:}"
    if [[ $verify_status -ne 0 && $verdict == *INCONSISTENT* ]]; then
        pass "${wrong%%:*}: zcheck verify rejects the wrong camera: $verdict"
    else
        fail "${wrong%%:*}: zcheck verify rejects the wrong camera: $verdict (exit $verify_status)"
    fi
done

set +e
"$zcheck" dataset verify "$out/manifest.jsonl" --scene "$out/scene.obj" -o "$tmp/results" > "$tmp/dataset.txt" 2>&1
dataset_status=$?
set -e
if [[ $dataset_status -eq 0 ]]; then
    pass "zcheck dataset verify of write_cameras's manifest (quantity distance for panoramic cameras): every frame consistent"
else
    tail -n 20 "$tmp/dataset.txt" | sed 's/^/      /'
    fail "zcheck dataset verify of write_cameras's manifest (exit $dataset_status)"
fi

refusal=$(cat "$out/refusal.txt")
if [[ $refusal == *"'equidistant'"* && $refusal == *fisheye_fov* ]]; then
    pass "camera_from_object refuses fisheye_fov 400 deg by name: $refusal"
else
    fail "camera_from_object refuses fisheye_fov 400 deg by name: $refusal"
fi
finish
