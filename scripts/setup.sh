#!/bin/sh
# Installs the system packages brdfprof needs (Debian 12 names): the Vulkan loader, lavapipe (Mesa's CPU
# Vulkan driver), the Khronos validation layer, glslang, SPIRV-Tools, vulkaninfo and valgrind.
# As root with apt-get it installs what is missing; otherwise it says exactly what to install and fails.
set -eu

missing=""
have_lib() { (ldconfig -p 2>/dev/null || /sbin/ldconfig -p 2>/dev/null) | grep -q "$1"; }
have_file() { for f in "$@"; do [ -e "$f" ] && return 0; done; return 1; }

have_lib 'libvulkan.so.1' || missing="$missing libvulkan1"
have_file /usr/share/vulkan/icd.d/lvp_icd.*.json /usr/share/vulkan/icd.d/lvp_icd.json || missing="$missing mesa-vulkan-drivers"
have_file /usr/share/vulkan/explicit_layer.d/VkLayer_khronos_validation.json || missing="$missing vulkan-validationlayers"
command -v glslangValidator >/dev/null 2>&1 || missing="$missing glslang-tools"
{ command -v spirv-opt && command -v spirv-val; } >/dev/null 2>&1 || missing="$missing spirv-tools"
command -v vulkaninfo >/dev/null 2>&1 || missing="$missing vulkan-tools"
command -v valgrind >/dev/null 2>&1 || missing="$missing valgrind"

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
        echo "   glslang, SPIRV-Tools, vulkan-tools and valgrind from your package manager)" >&2
        exit 1
    fi
fi
command -v cargo >/dev/null 2>&1 || { echo "brdfprof setup: cargo not found; install Rust (https://rustup.rs)" >&2; exit 1; }
echo "brdfprof setup: system packages present" >&2
