#!/bin/sh
# brdfprof on a machine with a real GPU (NVIDIA's driver, RADV, ANV, any Vulkan driver), in under 8 minutes:
#   devices, a profile of the thesis models at 1920x1080 with 8 and 64 lights, a short sweep (with ACO's cost
#   for RDNA 2 beside it), inspect with the driver's own statistics (VK_KHR_pipeline_executable_properties),
#   the cost table across this GPU and the compile-only AMD targets, every JSON under OUTDIR.
#
# Usage: scripts/gpu-check.sh OUTDIR [DEVICE]
#   DEVICE: index or name substring from `brdfprof devices` (default: the first discrete or integrated GPU).
#   BRDFPROF=path/to/brdfprof uses that binary (default: target/release/brdfprof, built if missing).
#   GPU_CHECK_SIZE=WxH overrides the profile's 1920x1080 (only to try the script on lavapipe: a CPU device at
#   1080p with 64 lights takes minutes per round).
# The time limits add up to 480 s (8 minutes); the budgets make it about 5.
# Exit status: that of the first command that failed (2: could not measure; 124: over its time limit), else
# 0. Never part of CI.
set -eu

if [ $# -lt 1 ] || [ $# -gt 2 ]; then
    echo "usage: $0 OUTDIR [DEVICE]" >&2
    exit 2
fi
OUT=$1
DEVICE=${2:-}
SIZE=${GPU_CHECK_SIZE:-1920x1080}
cd "$(dirname "$0")/.."
BIN=${BRDFPROF:-target/release/brdfprof}
if [ ! -x "$BIN" ]; then
    cargo build --release --locked
fi
mkdir -p "$OUT"
LOG="$OUT/gpu-check.log"
: > "$LOG"

# run NAME SECONDS ARGS...: one brdfprof command with a time limit, its output in OUT/NAME.txt, its wall time
# in the log.
run() {
    name=$1
    limit=$2
    shift 2
    echo "== $name: $BIN $*" | tee -a "$LOG"
    start=$(date +%s)
    status=0
    timeout "$limit" "$BIN" "$@" > "$OUT/$name.txt" 2> "$OUT/$name.err" || status=$?
    echo "   exit $status after $(( $(date +%s) - start )) s" | tee -a "$LOG"
    if [ "$status" -ne 0 ]; then
        tail -20 "$OUT/$name.err" >&2
        exit "$status"
    fi
}

set --
if [ -n "$DEVICE" ]; then
    set -- --device "$DEVICE"
fi

run devices 10 devices
cat "$OUT/devices.txt"
run targets 10 devices --targets
if grep -q '(default)' "$OUT/devices.txt" && grep '(default)' "$OUT/devices.txt" | grep -q '| cpu '; then
    [ -n "$DEVICE" ] || echo "note: the default device is a CPU device (no GPU driver found); pass DEVICE to choose one" | tee -a "$LOG"
fi
# The thesis models, 8 and 64 lights interleaved in the same rounds: 150 s at most.
run profile 170 profile "$@" --size "$SIZE" --lights 8,64 --budget 150 --json "$OUT/profile.json"
# A short sweep: the default 61 specs at 256x256 (the accuracy part runs on this device too), and ACO's
# RDNA 2 cost of the same specs beside it (seconds, no GPU needed).
run sweep 140 sweep "$@" --budget 120 --out "$OUT" --cost-device radv:navi21
# The driver's own statistics of this device (registers, instructions, spills where the driver reports them).
run inspect 90 inspect "$@" --profile "$OUT/profile.json" --json "$OUT/inspect.json" --markdown "$OUT/inspect.md"
# ACO's estimate for the default AMD families (compile-only, no AMD GPU needed), and the cost table of this
# device (measured ns/eval, driver statistics) beside them.
run inspect-radv 40 inspect --device radv:all --no-callgrind --json "$OUT/inspect-radv.json" --markdown "$OUT/inspect-radv.md"
# inspect.json joins the table where it has a cost per evaluation (callgrind on lavapipe, ACO on RADV).
own=""
if grep -q -e '"callgrind/ir-per-eval"' -e 'Inverse Throughput' "$OUT/inspect.json"; then
    own="$OUT/inspect.json"
fi
# shellcheck disable=SC2086 # $own is one path or nothing
run compare 20 compare "$OUT/profile.json" $own "$OUT/inspect-radv.json" \
    --json "$OUT/compare.json" --markdown "$OUT/compare.md" --chart "$OUT/compare.png"
echo "done: $(ls "$OUT" | tr '\n' ' ')" | tee -a "$LOG"
