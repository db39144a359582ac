#!/bin/sh
# `make mesa` (which `make test` and `make baseline` run; `make setup` and `make run` do not, ~20 min on 2 cores):
# builds Mesa's Vulkan drivers that brdfprof runs on Mesa's noop drm-shims, once per machine (docs/targets/mesa-noop.md,
# "Mesa's drivers on noop devices"), from Debian's source packages; nothing in them is patched, the options
# below are the whole recipe:
# - the installed Mesa's own source package (Debian 12: 22.3.6): Turnip (Adreno 6xx), PanVK (Mali Bifrost)
#   and ANV (Intel), linked as .tools/mesa;
# - bookworm-backports' Mesa (25.0.7): Turnip (Adreno 7xx) and PanVK (Mali Valhall), linked as .tools/mesa25.
#   Its meson (>= 1.1) comes from PyPI into the build's own folder; its ANV is not built: Mesa 25's Intel
#   driver needs libclc and LLVM's SPIR-V translator (docs/targets/mesa-noop.md).
# Each build lives outside the checkout, in $BRDFPROF_MESA_CACHE (default ~/.cache/brdfprof), keyed on the
# source version and the options; a second run finds the key and does nothing.
# BRDFPROF_MESA_VENDORS (`make mesa VENDORS=...`, `make mesa-adreno`, ...) builds only what those target
# families load: adreno and mali need Mesa 22.3 and 25.0, anv 22.3, nak NVK (default: all four). `--key` prints
# the cache key of what they need (for a CI cache, docs/ci.md) and builds nothing.
# Each build is linked into the per-user data directory's tools folder (brdfprof finds it there from any binary,
# `cargo install` or `make install` ones included) and into the checkout's .tools.
set -eu

root=$(cd "$(dirname "$0")/.." && pwd)
cache=${BRDFPROF_MESA_CACHE:-${XDG_CACHE_HOME:-$HOME/.cache}/brdfprof}
data=${XDG_DATA_HOME:-$HOME/.local/share}/brdfprof/tools
vendors=${BRDFPROF_MESA_VENDORS:-adreno mali anv nak}
for v in $vendors; do
    case "$v" in adreno|mali|anv|nak) ;; *) echo "brdfprof mesa: unknown vendor '$v' in VENDORS: give adreno, mali, anv or nak" >&2; exit 2 ;; esac
done
wants() { for v in $vendors; do for w in "$@"; do [ "$v" = "$w" ] && return 0; done; done; return 1; }
key_only=false
[ "${1:-}" = "--key" ] && key_only=true
# link NAME BUILD: the build as the tools folder NAME, in the data directory and in the checkout.
link() {
    mkdir -p "$data" "$root/.tools"
    ln -sfn "$2" "$data/$1"
    ln -sfn "$2" "$root/.tools/$1"
}
options="-Dbuildtype=release -Dvulkan-drivers=freedreno,panfrost,intel -Dgallium-drivers= -Dtools=drm-shim,intel \
-Dplatforms= -Dglx=disabled -Degl=disabled -Dgbm=disabled -Dopengl=false -Dgles1=disabled -Dgles2=disabled \
-Dllvm=disabled -Dshared-glapi=disabled -Dvalgrind=disabled -Dlibunwind=disabled -Dzstd=enabled -Dvideo-codecs="
# Mesa 25 has no shared-glapi option, and its ANV is not built (above).
options25="-Dbuildtype=release -Dvulkan-drivers=freedreno,panfrost -Dgallium-drivers= -Dtools=drm-shim \
-Dplatforms= -Dglx=disabled -Degl=disabled -Dgbm=disabled -Dopengl=false -Dgles1=disabled -Dgles2=disabled \
-Dllvm=disabled -Dvalgrind=disabled -Dlibunwind=disabled -Dzstd=enabled -Dvideo-codecs="
# What brdfprof loads: each `Shim` of src/targets/ (adreno.rs, mali.rs, anv.rs) names these files; a test ties them.
shim_products="src/freedreno/vulkan/libvulkan_freedreno.so src/freedreno/vulkan/freedreno_devenv_icd.x86_64.json
src/freedreno/drm-shim/libfreedreno_noop_drm_shim.so src/panfrost/vulkan/libvulkan_panfrost.so
src/panfrost/vulkan/panfrost_devenv_icd.x86_64.json src/panfrost/drm-shim/libpanfrost_noop_drm_shim.so"
products="$shim_products
src/intel/vulkan/libvulkan_intel.so src/intel/vulkan/intel_devenv_icd.x86_64.json src/intel/tools/libintel_noop_drm_shim.so"
products25="$shim_products"
meson_pypi="meson==1.12.1"

as_root() {
    [ "$(id -u)" = 0 ] && command -v apt-get >/dev/null 2>&1 || {
        echo "brdfprof mesa: the Mesa noop drivers are not built in $1; run make mesa as root (it needs apt-get)" >&2; exit 1; }
}

# The build tools of both builds, from Debian.
tools() {
    export DEBIAN_FRONTEND=noninteractive
    echo "brdfprof mesa: installing Mesa's build tools (meson, ninja, mako, yaml, bison, flex, libdrm, expat, zlib, zstd)" >&2
    apt-get install -y -qq dpkg-dev meson ninja-build python3-mako python3-yaml python3-packaging python3-pip xz-utils bison flex \
        libdrm-dev libexpat1-dev zlib1g-dev libzstd-dev pkg-config >/dev/null
}

# build NAME KEY DIR OPTIONS PRODUCTS MESON SRCDIR: meson + ninja of the products, the source tree removed after.
build() {
    b_name=$1 b_key=$2 b_dir=$3 b_opts=$4 b_prods=$5 b_meson=$6 b_src=$7
    echo "brdfprof mesa: building $b_name (once per machine; ninja's [N/M] is the progress)" >&2
    # meson must run on Debian's python3, the one with python3-mako.
    # shellcheck disable=SC2086
    PATH=/usr/bin:$PATH $b_meson setup "$b_dir/build" "$b_src" $b_opts >"$b_dir/meson-setup.log" 2>&1 || {
        tail -n 30 "$b_dir/meson-setup.log" >&2; echo "brdfprof mesa: meson setup failed (log: $b_dir/meson-setup.log)" >&2; exit 1; }
    PATH=/usr/bin:$PATH nice -n 10 ninja -C "$b_dir/build" $(for p in $b_prods; do printf '%s ' "$p"; done)
    for p in $b_prods; do [ -e "$b_dir/build/$p" ] || { echo "brdfprof mesa: the Mesa build did not produce $p" >&2; exit 1; }; done
    # The source tree is not needed once built; the build directory holds what brdfprof loads.
    rm -rf "$b_src" "$b_dir"/mesa_*
    printf '%s\n' "$b_key" > "$b_dir/.key"
}

# built KEY DIR PRODUCTS
built() {
    [ "$(cat "$2/.key" 2>/dev/null)" = "$1" ] || return 1
    for p in $3; do [ -e "$2/build/$p" ] || return 1; done
}

version=$(dpkg-query -W -f='${Version}' mesa-vulkan-drivers 2>/dev/null) || {
    echo "brdfprof mesa: mesa-vulkan-drivers is not installed; run make setup as root first" >&2; exit 1; }
key="$version $(printf '%s' "$options" | sha256sum | cut -c1-16)"
dir="$cache/mesa-noop-$(printf '%s' "$key" | tr ' +:~' '----')"

if ! $key_only && wants adreno mali anv && ! built "$key" "$dir" "$products"; then
    as_root "$dir"
    export DEBIAN_FRONTEND=noninteractive
    # Debian's deb-src entry beside the deb one: the source package of the installed Mesa.
    src_list=/etc/apt/sources.list.d/brdfprof-deb-src.sources
    if ! apt-get source --print-uris "mesa=$version" >/dev/null 2>&1; then
        codename=$(. /etc/os-release && echo "$VERSION_CODENAME")
        printf 'Types: deb-src\nURIs: http://deb.debian.org/debian\nSuites: %s %s-updates\nComponents: main\nSigned-By: /usr/share/keyrings/debian-archive-keyring.gpg\n\nTypes: deb-src\nURIs: http://deb.debian.org/debian-security\nSuites: %s-security\nComponents: main\nSigned-By: /usr/share/keyrings/debian-archive-keyring.gpg\n' \
            "$codename" "$codename" "$codename" > "$src_list"
        apt-get update -qq
    fi
    tools
    rm -rf "$dir"
    mkdir -p "$dir"
    echo "brdfprof mesa: fetching Debian's source package mesa=$version into $dir" >&2
    (cd "$dir" && apt-get source -qq "mesa=$version" >/dev/null)
    srcdir=$(find "$dir" -mindepth 1 -maxdepth 1 -type d -name 'mesa-*' | head -n 1)
    [ -n "$srcdir" ] || { echo "brdfprof mesa: apt-get source mesa=$version unpacked nothing in $dir" >&2; exit 1; }
    build "Turnip, PanVK, ANV and their noop shims from Mesa $version (about 1000 steps, ~8 min on 2 cores)" "$key" "$dir" "$options" "$products" meson "$srcdir"
fi
if ! $key_only && wants adreno mali anv; then
    link mesa "$dir/build"
    echo "brdfprof mesa: Mesa noop drivers present ($key) in $dir" >&2
fi

# bookworm-backports' Mesa, pinned (docs/targets/mesa-noop.md's figures are this build's): its source package's upstream
# tarball, checked against the SHA-256 of Debian's signed Sources index (apt-get source --print-uris); Debian's
# packaging of it (the .dsc, its patches) is not needed for a build of these drivers. Best effort: without it
# the Mesa 22.3 targets work and brdfprof names the 25.0 ones as not built.
version25="25.0.7-2~bpo12+1"
key25="$version25 $(printf '%s %s' "$options25" "$meson_pypi" | sha256sum | cut -c1-16)"
dir25="$cache/mesa-noop-$(printf '%s' "$key25" | tr ' +:~' '----')"

# backports_source DIR: bookworm-backports' Mesa source in DIR (its upstream tarball, checked against Debian's signed
# index; meson from PyPI in DIR/meson); prints the source folder. Needs root and apt-get.
backports_source() {
    s_dir=$1
    [ "$(id -u)" = 0 ] && command -v apt-get >/dev/null 2>&1 || {
        echo "brdfprof mesa: bookworm-backports' Mesa is not built in $s_dir; run make mesa as root (it needs apt-get)" >&2; return 1; }
    suite="$(. /etc/os-release && echo "${VERSION_CODENAME:-}")-backports"
    list=/etc/apt/sources.list.d/brdfprof-deb-src-backports.sources
    if ! LC_ALL=C apt-get source --print-uris "mesa=$version25" >/dev/null 2>&1; then
        # A deb-src entry for backports: source indexes only, nothing installed comes from it.
        printf 'Types: deb-src\nURIs: http://deb.debian.org/debian\nSuites: %s\nComponents: main\nSigned-By: /usr/share/keyrings/debian-archive-keyring.gpg\n' "$suite" > "$list"
        LC_ALL=C apt-get update -qq >&2 || { rm -f "$list"; echo "brdfprof mesa: apt-get update failed with $suite's deb-src entry (removed)" >&2; return 1; }
    fi
    uris=$(LC_ALL=C apt-get source --print-uris -qq "mesa=$version25" 2>&1) || { echo "brdfprof mesa: no mesa=$version25 source package in $suite: $uris" >&2; return 1; }
    tools
    rm -rf "$s_dir"
    mkdir -p "$s_dir" || return 1
    line=$(printf '%s\n' "$uris" | grep "\.orig\.tar\.[a-z0-9]*' " | grep -v "\.asc'" | head -n 1)
    tarball=$(printf '%s' "$line" | cut -d' ' -f2)
    sum=$(printf '%s' "$line" | sed -n 's/.*SHA256:\([0-9a-f]*\).*/\1/p')
    [ -n "$tarball" ] && [ -n "$sum" ] || { echo "brdfprof mesa: no upstream tarball for mesa=$version25 in apt's index" >&2; return 1; }
    echo "brdfprof mesa: fetching $tarball (Debian's mesa $version25 source package, $suite) into $s_dir" >&2
    # --download-only fetches and checks each file it can; only the tarball is needed (see above).
    (cd "$s_dir" && LC_ALL=C apt-get source --download-only -qq "mesa=$version25" >/dev/null 2>&1) || true
    echo "$sum  $s_dir/$tarball" | sha256sum -c --quiet - >&2 || { echo "brdfprof mesa: $tarball is missing or does not match Debian's index" >&2; return 1; }
    tar -xf "$s_dir/$tarball" -C "$s_dir" || return 1
    s_src=$(find "$s_dir" -mindepth 1 -maxdepth 1 -type d -name 'mesa-*' | head -n 1)
    [ -n "$s_src" ] || { echo "brdfprof mesa: $tarball unpacked no mesa-* folder" >&2; return 1; }
    # Mesa 25 needs meson >= 1.1 (Debian 12 has 1.0.1): PyPI's, pinned, in the build's own folder.
    python3 -m pip install --quiet --disable-pip-version-check --root-user-action=ignore --no-deps --target "$s_dir/meson" "$meson_pypi" >&2 || return 1
    printf '%s\n' "$s_src"
}

backports_build() {
    src25=$(backports_source "$dir25") || return 1
    # Exported: ninja runs meson's own script again for generated files.
    export PYTHONPATH="$dir25/meson"
    build "Turnip and PanVK and their noop shims from Mesa $version25 (about 900 steps, ~12 min on 2 cores)" "$key25" "$dir25" "$options25" "$products25" \
        "python3 $dir25/meson/bin/meson" "$src25"
}

if ! $key_only && wants adreno mali && ! built "$key25" "$dir25" "$products25"; then
    # In a subshell: build's `exit` on failure ends it, not the setup.
    ( backports_build ) || echo "brdfprof mesa: warning: bookworm-backports' Mesa $version25 was not built; adreno:a730/a740/a750 and mali:g610 are unavailable (the other targets are not affected); make mesa tries again" >&2
fi
if ! $key_only && wants adreno mali && built "$key25" "$dir25" "$products25"; then
    link mesa25 "$dir25/build"
    echo "brdfprof mesa: Mesa noop drivers present ($key25) in $dir25" >&2
fi

# NVK (Mesa's Vulkan driver for NVIDIA GPUs; its compiler is NAK) from the same Mesa 25.0 source, in a build of its
# own (the one above keeps its key and its build). NAK and NIL are Rust: meson >= 1.3.2 with Rust (the PyPI meson
# above), bindgen >= 0.65 and cbindgen >= 0.25 (Debian 12 has 0.60 and 0.24: cargo-installed, pinned versions,
# into the cache), and Mesa's Rust subprojects, whose .wrap download URLs do not resolve here: cargo fetches the
# same crate versions, and each .crate goes into subprojects/packagecache/ under its wrap's source_filename,
# where meson checks the wrap's source_hash before building from it. Best effort, like the build above.
options_nvk="-Dbuildtype=release -Dvulkan-drivers=nouveau -Dgallium-drivers= -Dtools=drm-shim \
-Dplatforms= -Dglx=disabled -Degl=disabled -Dgbm=disabled -Dopengl=false -Dgles1=disabled -Dgles2=disabled \
-Dllvm=disabled -Dvalgrind=disabled -Dlibunwind=disabled -Dzstd=enabled -Dvideo-codecs="
# What brdfprof loads (src/targets/nak.rs names these files; a test ties them).
products_nvk="src/nouveau/vulkan/libvulkan_nouveau.so src/nouveau/vulkan/nouveau_devenv_icd.x86_64.json
src/nouveau/drm-shim/libnouveau_noop_drm_shim.so"
rust_tools="bindgen-cli@0.73.2 cbindgen@0.29.4"
keynvk="$version25 $(printf '%s %s %s' "$options_nvk" "$meson_pypi" "$rust_tools" | sha256sum | cut -c1-16)"
dirnvk="$cache/mesa-nvk-$(printf '%s' "$keynvk" | tr ' +:~' '----')"

# The crates of each wrap-file=... Rust subproject (rust_crates SRCDIR): cargo fetches them in a throwaway project.
rust_crates() {
    r_src=$1
    r_home="$dirnvk/cargo-home"
    mkdir -p "$r_src/subprojects/packagecache"
    for wrap in "$r_src"/subprojects/*.wrap; do
        url=$(sed -n 's/^source_url *= *//p' "$wrap")
        case "$url" in *crates.io/api/v1/crates/*/download) ;; *) continue ;; esac
        name=$(printf '%s' "$url" | sed 's|.*/crates/\([^/]*\)/\([^/]*\)/download|\1|')
        ver=$(printf '%s' "$url" | sed 's|.*/crates/\([^/]*\)/\([^/]*\)/download|\2|')
        file=$(sed -n 's/^source_filename *= *//p' "$wrap")
        proj="$dirnvk/fetch-$name"
        mkdir -p "$proj/src" && : > "$proj/src/lib.rs"
        printf '[package]\nname = "fetch-%s"\nversion = "0.0.0"\nedition = "2021"\n[dependencies]\n%s = "=%s"\n' "$name" "$name" "$ver" > "$proj/Cargo.toml"
        # Not every wrap is NVK's: one that cannot be fetched fails the build only if meson needs it.
        CARGO_HOME="$r_home" cargo fetch -q --manifest-path "$proj/Cargo.toml" || { echo "brdfprof mesa: cargo could not fetch crate $name $ver" >&2; continue; }
        crate=$(find "$r_home/registry/cache" -name "$name-$ver.crate" | head -n 1)
        [ -n "$crate" ] || { echo "brdfprof mesa: cargo fetched no $name-$ver.crate" >&2; continue; }
        cp "$crate" "$r_src/subprojects/packagecache/$file"
        echo "brdfprof mesa: Rust subproject $name $ver from cargo (meson checks its hash)" >&2
    done
}

nvk_build() {
    command -v cargo >/dev/null 2>&1 && command -v rustc >/dev/null 2>&1 || { echo "brdfprof mesa: NVK needs rustc and cargo" >&2; return 1; }
    srcnvk=$(backports_source "$dirnvk") || return 1
    export DEBIAN_FRONTEND=noninteractive
    apt-get install -y -qq libclang1-15 >/dev/null || return 1
    tools_dir="$cache/rust-tools"
    if ! "$tools_dir/bin/bindgen" --version >/dev/null 2>&1 || ! "$tools_dir/bin/cbindgen" --version >/dev/null 2>&1; then
        echo "brdfprof mesa: installing $rust_tools with cargo (once per machine, ~7 min on 2 cores)" >&2
        # shellcheck disable=SC2086
        cargo install -q --locked $rust_tools --root "$tools_dir" || return 1
    fi
    rust_crates "$srcnvk" || return 1
    # A native file names these tools: `build` puts /usr/bin first in PATH, where Debian's older ones may be.
    printf "[binaries]\nrust = ['%s']\nbindgen = '%s'\ncbindgen = '%s'\n" "$(command -v rustc)" "$tools_dir/bin/bindgen" "$tools_dir/bin/cbindgen" > "$dirnvk/tools.ini"
    export PYTHONPATH="$dirnvk/meson"
    build "NVK and its noop shim from Mesa $version25 (about 870 steps, ~12 min on 2 cores)" "$keynvk" "$dirnvk" "$options_nvk --native-file $dirnvk/tools.ini" "$products_nvk" \
        "python3 $dirnvk/meson/bin/meson" "$srcnvk"
    rm -rf "$dirnvk"/cargo-home "$dirnvk"/fetch-*
}

if ! $key_only && wants nak && ! built "$keynvk" "$dirnvk" "$products_nvk"; then
    ( nvk_build ) || echo "brdfprof mesa: warning: NVK from Mesa $version25 was not built; the nak: targets are unavailable (the other targets are not affected); make mesa tries again" >&2
fi
if ! $key_only && wants nak && built "$keynvk" "$dirnvk" "$products_nvk"; then
    link mesa25-nvk "$dirnvk/build"
    echo "brdfprof mesa: NVK noop driver present ($keynvk) in $dirnvk" >&2
fi

# The cache key of the builds the vendors need, one line (a CI cache of $BRDFPROF_MESA_CACHE keys on it).
if $key_only; then
    k=""
    wants adreno mali anv && k="$k $key"
    wants adreno mali && k="$k $key25"
    wants nak && k="$k $keynvk"
    printf 'brdfprof-mesa-%s\n' "$(printf '%s' "$k" | sha256sum | cut -c1-16)"
fi
