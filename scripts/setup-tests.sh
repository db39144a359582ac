#!/bin/sh
# What only brdfprof's own tests need beside scripts/setup.sh's (`make test` runs both): Chromium (the HTML report is
# tested in it, headless), npm (Debian's nodejs), and from the npm registry Microsoft's SARIF Multitool into
# .tools/sarif (about 100 MB; the tests validate `check --sarif` with it). A user's CI that only runs brdfprof
# needs none of it. apt-get runs as root, or through sudo; nothing else needs root.
set -eu

root=$(cd "$(dirname "$0")/.." && pwd)
missing=""
[ -e /usr/bin/chromium ] || missing="$missing chromium"
command -v npm >/dev/null 2>&1 || missing="$missing npm"
as_root=""
[ "$(id -u)" = 0 ] || as_root="sudo"
if [ -n "$missing" ]; then
    if command -v apt-get >/dev/null 2>&1 && { [ -z "$as_root" ] || command -v sudo >/dev/null 2>&1; }; then
        echo "brdfprof test setup: installing$missing${as_root:+ (apt-get through sudo)}" >&2
        $as_root env DEBIAN_FRONTEND=noninteractive apt-get update -qq
        # shellcheck disable=SC2086
        $as_root env DEBIAN_FRONTEND=noninteractive apt-get install -y -qq $missing >/dev/null
    else
        echo "brdfprof test setup: missing system packages:$missing (install them as root: apt-get install$missing)" >&2
        exit 1
    fi
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
echo "brdfprof test setup: test tools present" >&2
