# The Blender tests' common part, sourced after `set -euo pipefail` with `test_name` and
# `default_timeout_s` set: the Blender executable (BLENDER, default blender; none: the test is
# skipped, exit 77), the zcheck module's path (PYTHONPATH, else build/python beside $zcheck), a
# temporary folder $tmp (removed unless a check failed or KEEP is set), the pass/fail tally, and
# run_blender, which runs a script in Blender headless and stops it by its pid if it overruns.
blender=${BLENDER:-blender}
timeout_s=${BLENDER_TIMEOUT:-$default_timeout_s}
if ! command -v "$blender" > /dev/null; then
    echo "$test_name: skipped: no Blender ('$blender') on this machine"
    exit 77
fi
export PYTHONPATH=${PYTHONPATH:-$(cd "$(dirname "$zcheck")/../python" && pwd)}

tmp=$(mktemp -d)
blender_pid=
passed=0
failed=0
cleanup() {
    if [[ -n $blender_pid ]] && kill -0 "$blender_pid" 2> /dev/null; then
        kill "$blender_pid" 2> /dev/null || true
    fi
    if [[ $failed -eq 0 && -z ${KEEP:-} ]]; then rm -rf "$tmp"; else echo "$test_name: renders, logs and results kept in $tmp"; fi
}
trap cleanup EXIT

pass() { echo "ok    $1"; passed=$((passed + 1)); }
fail() { echo "FAIL  $*"; failed=$((failed + 1)); }
finish() {
    echo "$test_name: $passed passed, $failed failed"
    exit $((failed > 0 ? 1 : 0))
}

# run_blender SCRIPT ARGS...: Blender in the background running SCRIPT with ARGS, its output in
# $tmp/blender.log, stopped by its pid after $timeout_s seconds (a failed check, and the end of
# the test); the script's own lines ("<script name>: ...") echoed. Sets $blender_status.
# TMPDIR: the folder Blender makes for itself (and leaves behind when stopped) goes with ours.
run_blender() {
    local script=$1
    shift
    TMPDIR=$tmp "$blender" -b --factory-startup --python-exit-code 1 -P "$script" -- "$@" > "$tmp/blender.log" 2>&1 &
    blender_pid=$!
    local waited=0
    while kill -0 "$blender_pid" 2> /dev/null && [[ $waited -lt $timeout_s ]]; do
        sleep 1
        waited=$((waited + 1))
    done
    if kill -0 "$blender_pid" 2> /dev/null; then
        kill "$blender_pid"
        sleep 5
        kill -9 "$blender_pid" 2> /dev/null || true
        tail -n 20 "$tmp/blender.log"
        fail "Blender rendered within ${timeout_s} s (stopped: pid $blender_pid)"
        blender_pid=
        finish
    fi
    set +e
    wait "$blender_pid"
    blender_status=$?
    set -e
    blender_pid=
    grep "^$(basename "$script" .py): " "$tmp/blender.log" | sed 's/^/      /' || true
}
