#!/bin/sh
# Builds Mesa's Turnip (Adreno), PanVK (Mali) and ANV (Intel) Vulkan drivers and their noop drm-shims from
# Debian's source package of the installed Mesa, once per machine (docs/targets.md, "Mesa's drivers on noop
# devices"). Nothing in it is patched: the source is Debian's, the options below are the whole recipe.
# The build lives outside the checkout, in $BRDFPROF_MESA_CACHE (default ~/.cache/brdfprof), keyed on the source
# version and the options; .tools/mesa in the checkout links to it. A second run finds the key and does nothing.
set -eu

root=$(cd "$(dirname "$0")/.." && pwd)
cache=${BRDFPROF_MESA_CACHE:-${XDG_CACHE_HOME:-$HOME/.cache}/brdfprof}
options="-Dbuildtype=release -Dvulkan-drivers=freedreno,panfrost,intel -Dgallium-drivers= -Dtools=drm-shim,intel \
-Dplatforms= -Dglx=disabled -Degl=disabled -Dgbm=disabled -Dopengl=false -Dgles1=disabled -Dgles2=disabled \
-Dllvm=disabled -Dshared-glapi=disabled -Dvalgrind=disabled -Dlibunwind=disabled -Dzstd=enabled -Dvideo-codecs="
# What brdfprof loads: each `Shim` of src/targets/ (adreno.rs, mali.rs, anv.rs) names these files; a test ties them.
products="src/freedreno/vulkan/libvulkan_freedreno.so src/freedreno/vulkan/freedreno_devenv_icd.x86_64.json
src/freedreno/drm-shim/libfreedreno_noop_drm_shim.so src/panfrost/vulkan/libvulkan_panfrost.so
src/panfrost/vulkan/panfrost_devenv_icd.x86_64.json src/panfrost/drm-shim/libpanfrost_noop_drm_shim.so
src/intel/vulkan/libvulkan_intel.so src/intel/vulkan/intel_devenv_icd.x86_64.json src/intel/tools/libintel_noop_drm_shim.so"

version=$(dpkg-query -W -f='${Version}' mesa-vulkan-drivers 2>/dev/null) || {
    echo "brdfprof setup: mesa-vulkan-drivers is not installed; run the first part of make setup as root" >&2; exit 1; }
key="$version $(printf '%s' "$options" | sha256sum | cut -c1-16)"
dir="$cache/mesa-noop-$(printf '%s' "$key" | tr ' +:~' '----')"

built() {
    [ "$(cat "$dir/.key" 2>/dev/null)" = "$key" ] || return 1
    for p in $products; do [ -e "$dir/build/$p" ] || return 1; done
}

if ! built; then
    [ "$(id -u)" = 0 ] && command -v apt-get >/dev/null 2>&1 || {
        echo "brdfprof setup: the Mesa noop drivers are not built in $dir; run make setup as root (it needs apt-get)" >&2; exit 1; }
    export DEBIAN_FRONTEND=noninteractive
    # Debian's deb-src entry beside the deb one: the source package of the installed Mesa.
    src_list=/etc/apt/sources.list.d/brdfprof-deb-src.sources
    if ! apt-get source --print-uris "mesa=$version" >/dev/null 2>&1; then
        codename=$(. /etc/os-release && echo "$VERSION_CODENAME")
        printf 'Types: deb-src\nURIs: http://deb.debian.org/debian\nSuites: %s %s-updates\nComponents: main\nSigned-By: /usr/share/keyrings/debian-archive-keyring.gpg\n\nTypes: deb-src\nURIs: http://deb.debian.org/debian-security\nSuites: %s-security\nComponents: main\nSigned-By: /usr/share/keyrings/debian-archive-keyring.gpg\n' \
            "$codename" "$codename" "$codename" > "$src_list"
        apt-get update -qq
    fi
    echo "brdfprof setup: installing Mesa's build tools (meson, ninja, mako, bison, flex, libdrm, expat, zlib, zstd)" >&2
    apt-get install -y -qq dpkg-dev meson ninja-build python3-mako bison flex libdrm-dev libexpat1-dev zlib1g-dev libzstd-dev pkg-config >/dev/null
    rm -rf "$dir"
    mkdir -p "$dir"
    echo "brdfprof setup: fetching Debian's source package mesa=$version into $dir" >&2
    (cd "$dir" && apt-get source -qq "mesa=$version" >/dev/null)
    srcdir=$(find "$dir" -mindepth 1 -maxdepth 1 -type d -name 'mesa-*' | head -n 1)
    [ -n "$srcdir" ] || { echo "brdfprof setup: apt-get source mesa=$version unpacked nothing in $dir" >&2; exit 1; }
    echo "brdfprof setup: building Turnip, PanVK, ANV and their noop shims (about 1000 steps, ~8 min on 2 cores, once per machine)" >&2
    # meson must run on Debian's python3, the one with python3-mako.
    # shellcheck disable=SC2086
    PATH=/usr/bin:$PATH meson setup "$dir/build" "$srcdir" $options >"$dir/meson-setup.log" 2>&1 || {
        tail -n 30 "$dir/meson-setup.log" >&2; echo "brdfprof setup: meson setup failed (log: $dir/meson-setup.log)" >&2; exit 1; }
    # ninja's own progress line ([N/974]) is the terminal's progress.
    PATH=/usr/bin:$PATH nice -n 10 ninja -C "$dir/build" $(for p in $products; do printf '%s ' "$p"; done)
    for p in $products; do [ -e "$dir/build/$p" ] || { echo "brdfprof setup: the Mesa build did not produce $p" >&2; exit 1; }; done
    # The source tree is not needed once built; the build directory holds what brdfprof loads.
    rm -rf "$srcdir" "$dir"/mesa_*
    printf '%s\n' "$key" > "$dir/.key"
fi
mkdir -p "$root/.tools"
ln -sfn "$dir/build" "$root/.tools/mesa"
echo "brdfprof setup: Mesa noop drivers present ($key) in $dir" >&2
