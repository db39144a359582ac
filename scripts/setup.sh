#!/bin/sh
# Installs what brdfprof needs (Debian 12 names): the Vulkan loader, lavapipe (Mesa's CPU Vulkan driver), the
# Khronos validation layer, glslang, SPIRV-Tools, spirv-cross (HLSL and WGSL models' SPIR-V back to GLSL,
# docs/hlsl.md), vulkaninfo and valgrind; g++ (runs the kernels' C translation
# on the CPU); Intel's OpenCL compiler (ocloc/IGC) and PoCL (OpenCL on the CPU) for the intel: targets; Chromium
# (the HTML report is tested in it, headless); npm (Debian's nodejs), and from the npm registry Microsoft's SARIF
# Multitool into .tools/sarif (about 100 MB; the tests validate `check --sarif` with it); and,
# from PyPI, NVIDIA's NVRTC and nvdisasm for the nvidia: targets, into .tools/nvidia (about 150 MB), and Slang's
# slangc (the HLSL front end for what glslang's cannot take) into .tools/slang (about 50 MB).
# As root with apt-get it installs what is missing; otherwise it says exactly what to install and fails.
# Mesa's noop drivers (adreno:, mali:, anv:) are not built here: `make mesa` (scripts/mesa-noop.sh), ~20 min once.
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
have_file /usr/bin/chromium || missing="$missing chromium"
command -v npm >/dev/null 2>&1 || missing="$missing npm"

if [ -n "$missing" ]; then
    if [ "$(id -u)" = 0 ] && command -v apt-get >/dev/null 2>&1; then
        echo "brdfprof setup: installing$missing" >&2
        export DEBIAN_FRONTEND=noninteractive
        apt-get update -qq
        # shellcheck disable=SC2086
        apt-get install -y -qq $missing >/dev/null
    else
        echo "brdfprof setup: missing system packages:$missing" >&2
        echo "  install them as root on Debian/Ubuntu:  apt-get install$missing" >&2
        echo "  (other systems: the Vulkan loader, Mesa's lavapipe driver, the Khronos validation layer," >&2
        echo "   glslang, SPIRV-Tools, spirv-cross, vulkan-tools, valgrind, g++, Intel's compute runtime (ocloc), PoCL, the" >&2
        echo "   OpenCL ICD loader, Chromium and npm from your package manager)" >&2
        exit 1
    fi
fi
command -v cargo >/dev/null 2>&1 || { echo "brdfprof setup: cargo not found; install Rust (https://rustup.rs)" >&2; exit 1; }

# NVIDIA's compiler (no GPU or driver needed): the pinned wheels of scripts/nvidia-wheels.txt, project-local.
root=$(cd "$(dirname "$0")/.." && pwd)
nv="$root/.tools/nvidia"
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
# of scripts/slang-wheel.txt (it ships slangc and its libraries; no PyTorch is needed to run slangc), project-local.
sl="$root/.tools/slang"
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
    mkdir -p "$root/.tools/intel"
    ln -sf "$iga" "$root/.tools/intel/libiga64.so"
fi
# Microsoft's SARIF Multitool validates `check --sarif` in the tests: the pinned npm package, project-local.
sarif="$root/.tools/sarif"
multitool=$(cat "$root/scripts/sarif-multitool.txt")
tool="$sarif/node_modules/@microsoft/sarif-multitool-linux/Sarif.Multitool"
if [ ! -x "$tool" ] || [ "$(cat "$sarif/.package" 2>/dev/null)" != "$multitool" ]; then
    echo "brdfprof setup: installing $multitool into $sarif" >&2
    rm -rf "$sarif"
    mkdir -p "$sarif"
    npm install --silent --no-audit --no-fund --prefix "$sarif" "$multitool" >/dev/null
    # npm may skip the package's install script, which only makes the binary executable.
    chmod u+x "$tool"
    echo "$multitool" > "$sarif/.package"
fi
echo "brdfprof setup: system packages present" >&2
