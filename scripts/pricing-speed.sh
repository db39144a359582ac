#!/bin/sh
# How long pricing takes on the compile-only targets (issue 60's budget: every default target for the 4
# presets <= 30 s cold and <= 3 s warm on 2 cores, <= 0.3 s per model-target cold as models are added).
# Runs `inspect --no-callgrind` on every prefix's default families (33 targets) with an empty kernel cache, then
# again with it warm, then with the microkernels, the table and the presets (16 models when measured for
# docs/targets.md, 17 since loop-16) on nvidia:all and radv:all (12 targets) cold; prints each wall time.
# Time it on a quiet machine: a build or test run beside it doubles the figures.
# Usage: sh scripts/pricing-speed.sh [BRDFPROF]   (default ./target/release/brdfprof)
set -eu
root=$(cd "$(dirname "$0")/.." && pwd)
cd "$root"
bin=${1:-./target/release/brdfprof}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT INT TERM
all="--device radv:all --device nvidia:all --device intel:all --device adreno:all --device mali:all --device anv:all --device nak:all"
run() { # LABEL CACHE ARGS...
    label=$1 cache=$2
    shift 2
    t0=$(date +%s.%N)
    BRDFPROF_CACHE_DIR=$cache "$bin" inspect --no-callgrind "$@" --json "$work/out.json" --markdown "$work/out.md" \
        >"$work/log" 2>&1 || { cat "$work/log"; exit 1; }
    t1=$(date +%s.%N)
    targets=$(python3 -c 'import json,sys; print(sum(1 for r in json.load(open(sys.argv[1]))["reports"] if r.get("cost")))' "$work/out.json")
    rows=$(python3 -c 'import json,sys; print(sum(len(r["cost"]["rows"]) for r in json.load(open(sys.argv[1]))["reports"] if r.get("cost")))' "$work/out.json")
    python3 -c 'import sys; t=float(sys.argv[2])-float(sys.argv[1]); print("%s: %.1f s wall, %s targets, %s kernel-targets (%.2f s each)" % (sys.argv[3], t, sys.argv[4], sys.argv[5], t/int(sys.argv[5])))' "$t0" "$t1" "$label" "$targets" "$rows"
}
mkdir "$work/a" "$work/b"
# shellcheck disable=SC2086
run "33 targets, the 4 presets, cold" "$work/a" $all
# shellcheck disable=SC2086
run "33 targets, the 4 presets, warm" "$work/a" $all
models=""
for f in tests/fixtures/brdf/micro/*.brdf tests/fixtures/brdf/table/lookup-64.brdf; do models="$models --model $f"; done
# shellcheck disable=SC2086
run "12 targets (nvidia:all, radv:all), $(echo $models | wc -w | awk '{ print $1 / 2 + 4 }') models, cold" "$work/b" --device nvidia:all --device radv:all $models \
    --model blinn --model cook-torrance --model burley
