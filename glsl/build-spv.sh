#!/bin/sh
# Compiles every kernel in glsl/kernels.txt into spv/ with glslang. Output is deterministic for a given glslang.
set -eu
cd "$(dirname "$0")/.."
mkdir -p spv
list="${TMPDIR:-/tmp}/brdfprof-kernels.$$"
trap 'rm -f "$list"' EXIT
trap 'exit 130' INT TERM
grep -v -e '^#' -e '^[[:space:]]*$' glsl/kernels.txt > "$list"
while read -r name source defines; do
    flags=""
    for d in $defines; do flags="$flags -D$d"; done
    # shellcheck disable=SC2086
    if ! out=$(glslangValidator -V --target-env vulkan1.1 $flags -o "spv/$name.spv" "glsl/$source" 2>&1); then
        echo "$out" >&2
        exit 1
    fi
    spirv-val --target-env vulkan1.1 "spv/$name.spv"
    echo "spv/$name.spv"
done < "$list"
