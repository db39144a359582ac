#!/bin/sh
# Where `make test` spends its time: builds the workspace's tests as `make test` does, runs each test binary the
# way cargo would (from its package's folder, one after another), with libtest's per-test wall times
# (`--report-time`; RUSTC_BOOTSTRAP=1 is set for the test processes only, so nothing is recompiled), and prints
# each binary's wall time, the total and the 20 slowest tests. Times are wall times with each binary's tests
# running in parallel on the machine's cores, so a test's time includes its neighbours' contention.
# Usage: sh scripts/test-times.sh [LOG]   (LOG keeps every binary's output; default a temporary file)
set -eu
root=$(cd "$(dirname "$0")/.." && pwd)
cd "$root"
log=${1:-$(mktemp)}
: > "$log"
# Built first on its own, so that a test that does not compile stops the script (its binary would otherwise be
# missing from the list below, and the run would look green).
cargo test --release --locked --workspace --no-run
list=$(cargo test --release --locked --workspace --no-run --message-format=json 2>/dev/null |
    python3 -c '
import json, sys
for line in sys.stdin:
    try:
        m = json.loads(line)
    except ValueError:
        continue
    if m.get("reason") == "compiler-artifact" and m.get("executable") and m["profile"].get("test"):
        print(m["target"]["name"], m["manifest_path"].rsplit("/", 1)[0], m["executable"])
')
start=$(date +%s)
status=0
echo "$list" | while read -r name dir exe; do
    t0=$(date +%s.%N)
    (cd "$dir" && RUSTC_BOOTSTRAP=1 "$exe" -Z unstable-options --report-time) >> "$log" 2>&1 || echo "FAILED binary $name" >> "$log"
    t1=$(date +%s.%N)
    awk -v a="$t0" -v b="$t1" -v n="$name" -v d="${dir#"$root"}" 'BEGIN { printf "%8.1f s  %s (%s)\n", b - a, n, d }'
done
end=$(date +%s)
echo "total: $((end - start)) s of tests (after the build)"
echo "the 20 slowest tests:"
sed -n 's/^test \(.*\) \.\.\. [a-zA-Z]* <\([0-9.]*\)s>$/\2 \1/p' "$log" | sort -rn | head -20 | awk '{ printf "%8.1f s  %s\n", $1, $2 }'
if grep -q '^FAILED binary\|^test result: FAILED' "$log"; then
    echo "some tests failed: $log" >&2
    status=1
fi
exit $status
