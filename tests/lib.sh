# Shared by the shell tests (sourced; they run with set -euo pipefail and set $zcheck).

# expect_error STATUS PATTERN ARGS...: `zcheck ARGS` must exit with STATUS and print exactly
# one line on stderr that matches the extended regex PATTERN. Each status is checked on its
# own: nothing here runs in a pipe.
expect_error() {
    local want=$1 pattern=$2
    shift 2
    local stderr status
    set +e
    stderr=$("$zcheck" "$@" 2>&1 > /dev/null)
    status=$?
    set -e
    if [[ $status -ne $want ]]; then
        echo "FAIL: zcheck $* exited $status, expected $want; stderr: $stderr"
        exit 1
    fi
    if [[ $(printf '%s\n' "$stderr" | wc -l) -ne 1 ]]; then
        echo "FAIL: zcheck $* printed $(printf '%s\n' "$stderr" | wc -l) lines on stderr, expected 1: $stderr"
        exit 1
    fi
    if ! grep -qE -- "$pattern" <<< "$stderr"; then
        echo "FAIL: zcheck $*: message does not match /$pattern/: $stderr"
        exit 1
    fi
}
