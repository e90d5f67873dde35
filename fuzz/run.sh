#!/usr/bin/env bash
# Builds the libFuzzer harnesses with clang (ASan + UBSan) into ./build-fuzz and runs each
# for SECONDS (default 60) on a copy of its seed corpus (fuzz/corpus/NAME), two at a time.
# Usage: fuzz/run.sh [SECONDS] [HARNESS...]   (harnesses: ply obj stl gltf camera camera_import depth_map)
# Exit status 0 only if no harness found a crash, a hang (> 10 s on one input), a leak or an
# out-of-memory (> 2 GiB); findings are kept in build-fuzz/findings/NAME/.
set -euo pipefail
cd "$(dirname "$0")/.."
seconds=${1:-60}
shift || true
harnesses=("$@")
((${#harnesses[@]})) || harnesses=(ply obj stl gltf camera camera_import depth_map)

command -v clang++ > /dev/null || {
    echo "installing clang (libFuzzer)"
    sudo=""; [[ $(id -u) -eq 0 ]] || sudo=sudo
    $sudo apt-get update -qq && DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends clang
}
cmake -S . -B build-fuzz -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DZCHECK_FUZZ=ON \
      -DCMAKE_CXX_COMPILER=clang++ > /dev/null
cmake --build build-fuzz --parallel "$(nproc)" --target $(printf 'fuzz_%s ' "${harnesses[@]}")

run_one() {
    local name=$1 work=build-fuzz/work/$1 findings=build-fuzz/findings/$1
    rm -rf "$work" "$findings" && mkdir -p "$work" "$findings"
    cp fuzz/corpus/"$name"/* "$work"/ 2> /dev/null || true
    # -timeout: one input over 10 s is a hang; -rss_limit_mb: memory over 2 GiB is a finding.
    if ASAN_OPTIONS=detect_leaks=1:allocator_may_return_null=1:intercept_tls_get_addr=0 UBSAN_OPTIONS=halt_on_error=1:print_stacktrace=1 \
        build-fuzz/fuzz/fuzz_"$name" "$work" -max_total_time="$seconds" -timeout=10 -rss_limit_mb=2048 \
        -max_len=262144 -artifact_prefix="$findings"/ -print_final_stats=1 > build-fuzz/fuzz_"$name".log 2>&1; then
        echo "fuzz_$name: $(grep -E '^stat::number_of_executed_units' build-fuzz/fuzz_"$name".log | awk '{print $2}') executions in ${seconds} s, 0 findings"
    else
        echo "fuzz_$name: FINDING (see build-fuzz/fuzz_$name.log and $findings)"
        tail -30 build-fuzz/fuzz_"$name".log
        return 1
    fi
}

status=0
pids=()
for name in "${harnesses[@]}"; do
    run_one "$name" &
    pids+=($!)
    if ((${#pids[@]} == $(nproc))); then
        wait "${pids[0]}" || status=1
        pids=("${pids[@]:1}")
    fi
done
for pid in "${pids[@]}"; do wait "$pid" || status=1; done
exit $status
