#!/bin/sh
# brdfprof on a lent GPU machine, in two halves, so that the machine with the GPU only measures:
#
#   scripts/gpu-check.sh prepare DIR          here (network, compilers): builds brdfprof, copies it stripped to
#                                             DIR/brdfprof, runs the compile-only targets (NVIDIA sm_90, which
#                                             an H200 is, and the default AMD families) into DIR/targets.json,
#                                             and downloads the Vulkan loader's package into DIR/debs
#   scripts/gpu-check.sh measure DIR [DEVICE] on the GPU machine (no registry, nothing built): devices, a profile
#                                             of the thesis models at 1920x1080 with 8 and 64 lights, a short
#                                             sweep (accuracy against the f64 reference on this device, and
#                                             time), the hard-case stability catalogue, the driver's own
#                                             statistics, and the cost table joining the measured ns/eval with
#                                             the modelled cycles/eval of DIR/targets.json, with their rank
#                                             correlation (DIR/compare.md); DIR/summary.md lists every step
#   scripts/gpu-check.sh all DIR [DEVICE]     both, on one machine (how it is tried on lavapipe)
#
# DEVICE: index or name substring from `brdfprof devices` (default: the first discrete or integrated GPU).
# GPU_CHECK_SIZE=WxH overrides the profile's 1920x1080 (on lavapipe: a CPU device at 1080p with 64 lights takes
# minutes per round). BRDFPROF=path uses that binary for `prepare` (default target/release/brdfprof, built if
# missing). DIR must travel to the GPU machine (the device tool's `carry`): `prepare` checks it stays under
# 64 MiB. Every step runs under its own time limit and the next one runs whatever it returned; measure's
# limits add up to 530 s, inside one 10-minute command. Exit status: that of the first step that failed (2:
# could not measure; 124: over its time limit), else 0. Never part of CI.
set -u

usage() {
    echo "usage: $0 prepare DIR | measure DIR [DEVICE] | all DIR [DEVICE]" >&2
    exit 2
}
[ $# -ge 2 ] || usage
MODE=$1
OUT=$2
DEVICE=${3:-}
case $MODE in prepare | measure | all) ;; *) usage ;; esac
[ "$MODE" != prepare ] || [ $# -eq 2 ] || usage
[ $# -le 3 ] || usage
cd "$(dirname "$0")/.."
mkdir -p "$OUT"
OUT=$(cd "$OUT" && pwd)
LOG="$OUT/gpu-check.log"
FIRST_FAILURE=0
FINDING=0

# step NAME SECONDS COMMAND...: one command under a time limit, its output in OUT/NAME.txt and OUT/NAME.err,
# its exit status and wall time in the log and OUT/summary.md; a failure is reported and the next step runs.
# An exit status equal to $FINDING is the command's verdict on what it checked, reported but not a failure.
step() {
    name=$1
    limit=$2
    shift 2
    echo "== $name: $*" | tee -a "$LOG"
    start=$(date +%s)
    status=0
    timeout "$limit" "$@" > "$OUT/$name.txt" 2> "$OUT/$name.err" || status=$?
    took=$(( $(date +%s) - start ))
    echo "   exit $status after $took s" | tee -a "$LOG"
    echo "| $name | $status | $took | \`$*\` |" >> "$OUT/summary.md"
    if [ "$status" -eq "${FINDING:-0}" ] && [ "$status" -ne 0 ]; then
        echo "   (exit $status is a finding of the check, not a failure to run it: see $OUT/$name.txt)" | tee -a "$LOG"
    elif [ "$status" -ne 0 ]; then
        tail -20 "$OUT/$name.err" >&2
        [ "$FIRST_FAILURE" -ne 0 ] || FIRST_FAILURE=$status
    fi
    return 0
}

summary_header() {
    {
        echo "# brdfprof gpu-check ($1), $(date -u '+%Y-%m-%d %H:%M UTC') on $(uname -n)"
        echo
        echo "| step | exit | seconds | command |"
        echo "|---|---|---|---|"
    } >> "$OUT/summary.md"
}

prepare() {
    : > "$LOG"
    : > "$OUT/summary.md"
    summary_header prepare
    bin=${BRDFPROF:-target/release/brdfprof}
    [ -x "$bin" ] || step build 1800 cargo build --release --locked
    step strip 60 objcopy --strip-debug "$bin" "$OUT/brdfprof"
    # What no GPU is needed for: NVIDIA's compiler for the H200's sm_90 and ACO for the AMD families, from the
    # same binary (so the same kernels: `compare` checks their hashes).
    step targets 300 "$OUT/brdfprof" inspect --device nvidia:sm_90 --device radv:all --no-callgrind \
        --json "$OUT/targets.json" --markdown "$OUT/targets.md"
    # The measured-reference suite's throughput kernels (docs/measured.md), priced here and timed there, so that
    # a lent GPU measures exactly the ratios the suite models.
    rm -rf "$OUT/measured"
    mkdir -p "$OUT/measured"
    cp tests/fixtures/brdf/measured/*-t8.brdf tests/fixtures/brdf/measured/*-t16.brdf "$OUT/measured/"
    set --
    for f in "$OUT"/measured/*.brdf; do set -- "$@" --model "$f"; done
    step measured-targets 200 "$OUT/brdfprof" inspect --device nvidia:sm_90 --device radv:gfx1100 --no-callgrind \
        --lights 8 "$@" --json "$OUT/measured-targets.json" --markdown "$OUT/measured-targets.md"
    # The lent machine may have no Vulkan loader; it cannot reach a registry to fetch one.
    rm -rf "$OUT/debs"
    mkdir -p "$OUT/debs"
    step loader 120 sh -c "cd '$OUT/debs' && apt-get download libvulkan1"
    # The C library the binary needs: the lent machine's must be as new.
    glibc=$(objdump -T "$OUT/brdfprof" 2>/dev/null | grep -o 'GLIBC_[0-9.]*' | sort -V | tail -1)
    echo "$OUT/brdfprof needs ${glibc:-an unknown glibc} or newer" | tee -a "$LOG"
    size=$(du -sm "$OUT" | cut -f1)
    echo "prepared $OUT: ${size} MiB" | tee -a "$LOG"
    if [ "$size" -ge 64 ]; then
        echo "error: $OUT is ${size} MiB, over the 64 MiB a lent machine takes" | tee -a "$LOG" >&2
        [ "$FIRST_FAILURE" -ne 0 ] || FIRST_FAILURE=2
    fi
}

# Vulkan on a machine that has the NVIDIA driver but perhaps no loader: the carried package, unpacked under
# DIR (never over /), and NVIDIA's ICD file where the driver's installer left it outside the loader's paths.
bring_loader() {
    if ! ldconfig -p 2>/dev/null | grep -q 'libvulkan\.so\.1'; then
        for deb in "$OUT"/debs/*.deb; do
            [ -f "$deb" ] && dpkg -x "$deb" "$OUT/root"
        done
        if [ -d "$OUT/root" ]; then
            lib=$(dirname "$(find "$OUT/root" -name 'libvulkan.so.1' | head -1)")
            export LD_LIBRARY_PATH="$lib${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}"
            echo "Vulkan loader: carried, $lib" | tee -a "$LOG"
        else
            echo "Vulkan loader: none installed and none carried (run prepare where apt-get works)" | tee -a "$LOG"
        fi
    fi
    nvidia_icd=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
    if [ -z "${VK_DRIVER_FILES:-}" ] && [ -f "$nvidia_icd" ] \
        && ! ls /usr/share/vulkan/icd.d/nvidia* /etc/vulkan/icd.d/nvidia* > /dev/null 2>&1; then
        export VK_DRIVER_FILES="$nvidia_icd"
        echo "Vulkan driver: $nvidia_icd" | tee -a "$LOG"
    fi
}

measure() {
    [ "$MODE" = all ] || : > "$LOG"
    summary_header measure
    bin="$OUT/brdfprof"
    if [ ! -x "$bin" ]; then
        echo "error: $bin is missing: run \`$0 prepare $OUT\` first" >&2
        exit 2
    fi
    bring_loader
    size=${GPU_CHECK_SIZE:-1920x1080}
    set --
    [ -z "$DEVICE" ] || set -- --device "$DEVICE"
    step devices 20 "$bin" devices
    cat "$OUT/devices.txt"
    # The thesis models, 8 and 64 lights interleaved in the same rounds: 150 s at most.
    step profile 170 "$bin" profile "$@" --size "$size" --lights 8,64 --budget 150 --json "$OUT/profile.json"
    # The default 61 specs at 256x256: error against the exact f64 reference on this device, and time.
    step sweep 140 "$bin" sweep "$@" --budget 120 --out "$OUT/sweep"
    # NaN, Inf and negative values on the hard cases, on this device's driver: the thesis models in fp32 and
    # fp16 (the default catalogue, every D x Vis and Fresnel, takes over a minute on lavapipe).
    set -- "$@"
    for m in ggx blinn cook-torrance burley; do set -- "$@" --model "$m" --model "$m,precision=f16"; done
    # Exit 1 means some spec gave NaN, Inf or a negative value: a result (the fp16 models overflow on
    # lavapipe), reported, not a failed step.
    FINDING=1
    step stability 60 "$bin" stability "$@" --out "$OUT/stability"
    FINDING=0
    set --
    [ -z "$DEVICE" ] || set -- --device "$DEVICE"
    # The driver's own statistics (VK_KHR_pipeline_executable_properties, where the driver reports them).
    step inspect 50 "$bin" inspect "$@" --no-callgrind --profile "$OUT/profile.json" \
        --json "$OUT/inspect.json" --markdown "$OUT/inspect.md"
    # The measured-reference kernels timed on this GPU at 8 lights: each kind's -t16 less its -t8 is 64
    # operations, the ratios docs/measured.md compares with the rule's (measured-targets.json).
    set --
    [ -z "$DEVICE" ] || set -- --device "$DEVICE"
    for f in "$OUT"/measured/*.brdf; do [ -f "$f" ] && set -- "$@" --model "$f"; done
    step measured 70 "$bin" profile "$@" --size 1024x1024 --lights 8 --budget 60 --json "$OUT/measured.json"
    set --
    [ -z "$DEVICE" ] || set -- --device "$DEVICE"
    # Measured ns/eval beside the compile-only targets' modelled cycles/eval, and their rank correlation.
    set -- "$OUT/profile.json"
    [ -f "$OUT/targets.json" ] && set -- "$@" "$OUT/targets.json"
    step compare 20 "$bin" compare "$@" --json "$OUT/compare.json" --markdown "$OUT/compare.md" --chart "$OUT/compare.png"
}

case $MODE in
    prepare) prepare ;;
    measure) measure ;;
    all)
        prepare
        measure
        ;;
esac
echo "done ($FIRST_FAILURE): $(ls "$OUT" | tr '\n' ' ')" | tee -a "$LOG"
cat "$OUT/summary.md"
exit "$FIRST_FAILURE"
