#!/usr/bin/env bash
# `fiveaxis view` on large programs: the page size, the time `view` takes
# and its peak memory, and, in headless Chromium (viewer/test/measure.mjs),
# the time to the path drawn, to the whole page read, a slider seek, a
# frame while orbiting and a frame at rest.
#
#   bench/view.sh [REPEATS]
#
# Programs (bench/gen.py, seeded): a smooth G43.5 finishing raster
# (`--finish`) and random `G1 X Y Z A C` blocks (`--ends-only`), 200,000
# and 2,000,000 blocks each. Needs what the browser tests need (node,
# `npm ci` in viewer/, Chromium). Each page is opened REPEATS times
# (default 3), in turn, and the median is printed.
set -euo pipefail
cd "$(dirname "$0")/.."
REPEATS=${1:-3}
OUT=bench/out/view
mkdir -p "$OUT"
cargo build --release -p fiveaxis-cli --locked >&2
FIVEAXIS=$PWD/target/release/fiveaxis

pages=()
for spec in "finish 200000" "finish 2000000" "random 200000" "random 2000000"; do
  set -- $spec
  kind=$1 blocks=$2
  prog=$OUT/$kind-$blocks.nc
  page=$OUT/$kind-$blocks.html
  if [ "$kind" = finish ]; then
    [ -f "$prog" ] || python3 bench/gen.py "$blocks" "$prog" --finish
    opts=()
  else
    [ -f "$prog" ] || python3 bench/gen.py "$blocks" "$prog"
    opts=(--ends-only)
  fi
  /usr/bin/time -f "%e %M" -o "$OUT/$kind-$blocks.time" \
    "$FIVEAXIS" view "$prog" "${opts[@]}" -o "$page" 2>/dev/null || true
  pages+=("$page")
done

: >"$OUT/measure.jsonl"
for r in $(seq "$REPEATS"); do
  (cd viewer && node test/measure.mjs "${pages[@]/#/../}") >>"$OUT/measure.jsonl"
done

python3 - "$OUT" "${pages[@]}" <<'PY'
import json, statistics, sys
out, pages = sys.argv[1], sys.argv[2:]
runs = [json.loads(l) for l in open(f"{out}/measure.jsonl") if l.startswith("{")]
print("| program | view | page | path drawn | whole page | seek | frame orbiting | frame at rest |")
print("|---|---:|---:|---:|---:|---:|---:|---:|")
for page in pages:
    rs = [r for r in runs if r["file"].endswith(page.split("/")[-1])]
    if not rs:
        continue
    med = lambda k: statistics.median(r[k] for r in rs)
    secs, kb = open(page.replace(".html", ".time")).read().split()
    name = page.split("/")[-1].replace(".html", "")
    print(f"| {name} | {float(secs):.1f} s, {int(kb) // 1000} MB | {rs[0]['megabytes']} MB | "
          f"{med('interactiveMs') / 1000:.1f} s | {med('openMs') / 1000:.1f} s | {med('seekMs'):.0f} ms | "
          f"{med('orbitMs'):.0f} ms | {med('restMs'):.0f} ms ({rs[0]['restVertices']:,} of {rs[0]['vertices']:,} vertices) |")
PY
