#!/bin/sh
# Installs what brdfprof needs to run (Debian 12 names): the Vulkan loader, lavapipe (Mesa's CPU Vulkan driver), the
# Khronos validation layer, glslang, SPIRV-Tools, spirv-cross (HLSL and WGSL models' SPIR-V back to GLSL,
# docs/hlsl.md), vulkaninfo and valgrind (inspect's callgrind counts); g++ (runs the kernels' C translation on the
# CPU); Intel's OpenCL compiler (ocloc/IGC) and PoCL (OpenCL on the CPU) for the intel: targets; and, from PyPI,
# NVIDIA's NVRTC and nvdisasm for the nvidia: targets (about 150 MB) and Slang's slangc (the HLSL front end for what
# glslang's cannot take; about 50 MB). What only brdfprof's own tests need (Chromium, npm and Microsoft's SARIF
# Multitool) is scripts/setup-tests.sh's, which `make test` runs.
# The PyPI wheels and the link to IGA's library go into the per-user data directory's tools folder
# ($XDG_DATA_HOME/brdfprof/tools, default ~/.local/share/brdfprof/tools), where brdfprof finds them from any binary
# (`make install`, `cargo install --path .`), and are linked into the checkout's .tools.
# System packages: as root with apt-get it installs what is missing; as another user it runs apt-get through sudo
# (the apt part alone; nothing else needs root, cargo least of all); otherwise it says exactly what to install.
# Mesa's noop drivers (adreno:, mali:, anv:, nak:) are not built here: `make mesa` (scripts/mesa-noop.sh).
set -eu

missing=""
have_lib() { (ldconfig -p 2>/dev/null || /sbin/ldconfig -p 2>/dev/null) | grep -q "$1"; }
have_file() { for f in "$@"; do [ -e "$f" ] && return 0; done; return 1; }

have_lib 'libvulkan.so.1' || missing="$missing libvulkan1"
have_file /usr/share/vulkan/icd.d/lvp_icd.*.json /usr/share/vulkan/icd.d/lvp_icd.json || missing="$missing mesa-vulkan-drivers"
have_file /usr/share/vulkan/explicit_layer.d/VkLayer_khronos_validation.json || missing="$missing vulkan-validationlayers"
command -v glslangValidator >/dev/null 2>&1 || missing="$missing glslang-tools"
{ command -v spirv-opt && command -v spirv-val; } >/dev/null 2>&1 || missing="$missing spirv-tools"
command -v spirv-cross >/dev/null 2>&1 || missing="$missing spirv-cross"
command -v vulkaninfo >/dev/null 2>&1 || missing="$missing vulkan-tools"
command -v valgrind >/dev/null 2>&1 || missing="$missing valgrind"
command -v g++ >/dev/null 2>&1 || missing="$missing g++"
command -v ocloc >/dev/null 2>&1 || missing="$missing intel-opencl-icd"
have_file /etc/OpenCL/vendors/pocl.icd || missing="$missing pocl-opencl-icd"
have_lib 'libOpenCL.so.1' || missing="$missing ocl-icd-libopencl1"

# apt-get as root, else through sudo (never the rest of the setup: it needs no root).
as_root=""
[ "$(id -u)" = 0 ] || as_root="sudo"
if [ -n "$missing" ]; then
    if command -v apt-get >/dev/null 2>&1 && { [ -z "$as_root" ] || command -v sudo >/dev/null 2>&1; }; then
        echo "brdfprof setup: installing$missing${as_root:+ (apt-get through sudo)}" >&2
        $as_root env DEBIAN_FRONTEND=noninteractive apt-get update -qq
        # shellcheck disable=SC2086
        $as_root env DEBIAN_FRONTEND=noninteractive apt-get install -y -qq $missing >/dev/null
    else
        echo "brdfprof setup: missing system packages:$missing" >&2
        echo "  install them as root on Debian/Ubuntu:  apt-get install$missing" >&2
        echo "  (other systems: the Vulkan loader, Mesa's lavapipe driver, the Khronos validation layer," >&2
        echo "   glslang, SPIRV-Tools, spirv-cross, vulkan-tools, valgrind, g++, Intel's compute runtime (ocloc), PoCL and" >&2
        echo "   the OpenCL ICD loader from your package manager)" >&2
        exit 1
    fi
fi
root=$(cd "$(dirname "$0")/.." && pwd)
data=${XDG_DATA_HOME:-$HOME/.local/share}/brdfprof/tools
mkdir -p "$data" "$root/.tools"
# place NAME: the data directory's folder NAME, where a real .tools/NAME of an older setup is moved (not fetched
# again), linked back as .tools/NAME.
place() {
    if [ -d "$root/.tools/$1" ] && [ ! -L "$root/.tools/$1" ]; then
        if [ -e "$data/$1" ]; then rm -rf "$root/.tools/$1"; else mv "$root/.tools/$1" "$data/$1"; fi
    fi
    ln -sfn "$data/$1" "$root/.tools/$1"
    printf '%s\n' "$data/$1"
}

# NVIDIA's compiler (no GPU or driver needed): the pinned wheels of scripts/nvidia-wheels.txt.
nv=$(place nvidia)
wheels=$(cat "$root/scripts/nvidia-wheels.txt")
if [ ! -f "$nv/nvidia/cu13/lib/libnvrtc.so.13" ] || [ ! -x "$nv/nvidia/cu13/bin/nvdisasm" ] || [ "$(cat "$nv/.wheels" 2>/dev/null)" != "$wheels" ]; then
    python3 -m pip --version >/dev/null 2>&1 || { echo "brdfprof setup: python3 -m pip not found; install python3-pip (needed for NVIDIA's NVRTC wheels)" >&2; exit 1; }
    echo "brdfprof setup: installing $wheels into $nv" >&2
    rm -rf "$nv"
    # shellcheck disable=SC2086
    python3 -m pip install --quiet --disable-pip-version-check --root-user-action=ignore --no-deps --target "$nv" $wheels
    echo "$wheels" > "$nv/.wheels"
fi
# Slang's compiler (slangc, the second HLSL front end for what glslang's cannot take): the pinned slangtorch wheel
# of scripts/slang-wheel.txt (it ships slangc and its libraries; no PyTorch is needed to run slangc).
sl=$(place slang)
slang_wheel=$(cat "$root/scripts/slang-wheel.txt")
if [ ! -x "$sl/slangtorch/bin/slangc" ] || [ "$(cat "$sl/.wheels" 2>/dev/null)" != "$slang_wheel" ]; then
    echo "brdfprof setup: installing $slang_wheel (slangc) into $sl" >&2
    rm -rf "$sl"
    python3 -m pip install --quiet --disable-pip-version-check --root-user-action=ignore --no-deps --target "$sl" "$slang_wheel"
    echo "$slang_wheel" > "$sl/.wheels"
fi
# ocloc disassembles only where it can dlopen libiga64.so; Debian ships libiga64.so.1 alone: a private link.
iga=$(ls /usr/lib/x86_64-linux-gnu/libiga64.so.1 /usr/lib/*/libiga64.so.1 2>/dev/null | head -n 1)
if [ -n "$iga" ]; then
    intel=$(place intel)
    mkdir -p "$intel"
    ln -sf "$iga" "$intel/libiga64.so"
fi
echo "brdfprof setup: system packages present" >&2
