#!/usr/bin/env bash
# End-to-end benchmark: `fiveaxis run` against LinuxCNC's stand-alone
# RS274/NGC interpreter `rs274` on the same generated 5-axis program.
#
#   bench/run.sh
#
# Builds fiveaxis in release, installs rs274 (Debian: linuxcnc-uspace) and
# hyperfine when missing, generates the programs into bench/out/ with
# bench/gen.py (seeded), checks that both tools run every block, then
# measures wall time (200,000 blocks) and peak resident memory (200,000
# and 2,000,000 blocks). Writes bench/out/summary.md and prints it.
#
# Exits 2 when a tool is missing or does not run the whole program, and
# 1 when a goal is missed: `fiveaxis run` less than MIN_RATIO times as
# fast as rs274 in wall time or MIN_CPU_RATIO times in CPU time (user +
# system) on the random program; `fiveaxis check` less than
# MIN_CHECK_SMOOTH times as fast as rs274 on the smooth 5-axis program
# (bench/gen.py --smooth) or MIN_CHECK times on the random one; TCPC
# type 2 below MIN_TCPC of plain G1; the Python package (when it is
# installed in the python3 on PATH) below MIN_PY_ROWS rows per second;
# peak RSS on the 2M-block program at MAX_RSS_MB (decimal megabytes), or
# `check` or `view` peaking at MAX_CHECK_RSS_MB / MAX_VIEW_RSS_MB or a
# page reaching MAX_PAGE_MB. All can be overridden from the environment,
# e.g. `MIN_RATIO=2 bench/run.sh`; BENCH_NO_HYPERFINE=1 times with best
# of 5 runs instead of hyperfine.
set -euo pipefail
cd "$(dirname "$0")/.."

MIN_RATIO=${MIN_RATIO:-12}
MIN_CPU_RATIO=${MIN_CPU_RATIO:-8}
MIN_CHECK_SMOOTH=${MIN_CHECK_SMOOTH:-30}
MIN_CHECK=${MIN_CHECK:-10}
MIN_PY_ROWS=${MIN_PY_ROWS:-3000000}
MIN_TCPC=${MIN_TCPC:-0.8}
MAX_COMP=${MAX_COMP:-2}
MIN_LOOP=${MIN_LOOP:-10}
MAX_RSS_MB=${MAX_RSS_MB:-50}
MAX_CHECK_RSS_MB=${MAX_CHECK_RSS_MB:-50}
MAX_VIEW_RSS_MB=${MAX_VIEW_RSS_MB:-400}
MAX_PAGE_MB=${MAX_PAGE_MB:-120}
SEED=${SEED:-5}
SMALL=200000
LARGE=2000000
OUT=bench/out
FIVEAXIS=target/release/fiveaxis

log() { printf '== %s\n' "$*" >&2; }
die() { printf 'bench: %s\n' "$*" >&2; exit 2; }

apt_updated=0
apt_install() {
  if [ "$apt_updated" = 0 ]; then
    apt-get update -qq
    apt_updated=1
  fi
  DEBIAN_FRONTEND=noninteractive apt-get install -y -qq "$@" >/dev/null
}

# --- tools -----------------------------------------------------------------
log "building fiveaxis (release)"
cargo build --release -p fiveaxis-cli --locked

if ! command -v rs274 >/dev/null 2>&1; then
  log "installing rs274 (linuxcnc-uspace)"
  apt_install linuxcnc-uspace
fi
command -v rs274 >/dev/null 2>&1 || die "rs274 is still missing after installing linuxcnc-uspace"
if [ ! -x /usr/bin/time ]; then
  log "installing GNU time"
  apt_install time
fi
if ! command -v hyperfine >/dev/null 2>&1; then
  log "installing hyperfine"
  apt_install hyperfine || true
fi
HAVE_HYPERFINE=0
command -v hyperfine >/dev/null 2>&1 && HAVE_HYPERFINE=1
# BENCH_NO_HYPERFINE=1 forces the best-of-5 fallback.
[ "${BENCH_NO_HYPERFINE:-0}" = 1 ] && HAVE_HYPERFINE=0

# --- programs --------------------------------------------------------------
mkdir -p "$OUT"
SMALL_PROG=$OUT/prog200k.nc
LARGE_PROG=$OUT/prog2M.nc
TCPC_PROG=$OUT/tcpc200k.nc
SMOOTH_PROG=$OUT/smooth200k.nc
generate() { # blocks file [gen.py options]
  local stamp="$2.stamp" want
  want="seed=$SEED blocks=$1 ${3:-} gen=$(sha256sum bench/gen.py | cut -c1-16)"
  if [ -f "$2" ] && [ -f "$stamp" ] && [ "$(cat "$stamp")" = "$want" ]; then
    return
  fi
  log "generating $2 ($1 blocks)"
  python3 bench/gen.py "$1" "$2" --seed "$SEED" ${3:-}
  printf '%s\n' "$want" >"$stamp"
}
generate "$SMALL" "$SMALL_PROG"
generate "$LARGE" "$LARGE_PROG"
generate "$SMALL" "$TCPC_PROG" --tcpc
generate "$SMALL" "$SMOOTH_PROG" --smooth
for kind in plain cutter comp3d; do
  generate "$SMALL" "$OUT/contour-$kind.nc" "--contour $kind"
done
printf '[tools]\n1 = { length = 0.0, radius = 5.0 }\n' >"$OUT/offsets.toml"
# The same loop in both languages: custom macro B WHILE (fiveaxis) and an
# O-word while (rs274), computing and moving each iteration.
LOOP_PROG=$OUT/loop200k.nc
LOOP_NGC=$OUT/loop200k.ngc
printf '%s\n' '#100=0' "WHILE [#100 LT $SMALL] DO1" 'G1 X[#100 MOD 100] Y[#100/1000] F1000.' \
  '#100=#100+1' 'END1' 'M30' >"$LOOP_PROG"
printf '%s\n' '#100=0' "o1 while [#100 LT $SMALL]" 'G1 X[#100 MOD 100] Y[#100/1000] F1000.' \
  '#100=[#100+1]' 'o1 endwhile' 'M2' >"$LOOP_NGC"

# --- both tools run every block -------------------------------------------
log "checking that both tools run all $SMALL blocks"
rows=$("$FIVEAXIS" run "$SMALL_PROG" | grep -c ',linear,') \
  || die "fiveaxis run failed on $SMALL_PROG (or printed no linear row)"
[ "$rows" = "$SMALL" ] || die "fiveaxis printed $rows linear rows, expected $SMALL"

RS_OUT=$OUT/rs274-200k.txt
rs_status=0
rs274 -g "$SMALL_PROG" >"$RS_OUT" 2>"$OUT/rs274-200k.err" || rs_status=$?
[ "$rs_status" = 0 ] || die "rs274 exited with $rs_status: $(tail -n 3 "$OUT/rs274-200k.err")"
feeds=$(grep -c 'STRAIGHT_FEED(' "$RS_OUT" || true)
[ "$feeds" = "$SMALL" ] || die "rs274 executed $feeds feed moves, expected $SMALL"
grep -q 'PROGRAM_END()' "$RS_OUT" || die "rs274 did not reach M30"
# rs274 prints X Y Z A B C: the last move's A and C must be the program's.
last_block=$(grep '^G1 ' "$SMALL_PROG" | tail -n 1)
last_feed=$(grep 'STRAIGHT_FEED(' "$RS_OUT" | tail -n 1)
awk -v block="$last_block" -v feed="$last_feed" 'BEGIN {
  n = split(block, w, " ")
  for (i = 1; i <= n; i++) v[substr(w[i], 1, 1)] = substr(w[i], 2) + 0
  sub(/.*STRAIGHT_FEED\(/, "", feed); sub(/\).*/, "", feed)
  split(feed, f, ", *")
  d = (f[4] - v["A"]) ^ 2 + (f[6] - v["C"]) ^ 2 + (f[1] - v["X"]) ^ 2
  if (d > 1e-6) { printf "rs274 last move %s does not match block %s\n", feed, block; exit 1 }
}' || die "rs274 does not carry the A and C values"

log "checking that rs274 runs all $SMALL blocks of the smooth program and check finds nothing in it"
smooth_feeds=$(rs274 -g "$SMOOTH_PROG" 2>/dev/null | grep -c 'STRAIGHT_FEED(' || true)
[ "$smooth_feeds" = "$SMALL" ] || die "rs274 executed $smooth_feeds feed moves of the smooth program, expected $SMALL"
"$FIVEAXIS" check "$SMOOTH_PROG" --format json --fail-on never >"$OUT/check-smooth.json" \
  || die "fiveaxis check failed on $SMOOTH_PROG"
grep -q '"findings":\[\]' "$OUT/check-smooth.json" || die "fiveaxis check reports findings on the smooth program"

# --- wall time -------------------------------------------------------------
# Sets T_BEST and T_MEAN (seconds) for the command given.
time_cmd() { # name command...
  local name=$1
  shift
  if [ "$HAVE_HYPERFINE" = 1 ]; then
    hyperfine -N --style basic --warmup 2 --runs 10 --output null \
      --export-json "$OUT/hyperfine-$name.json" --command-name "$name" "$*" >&2
    read -r T_BEST T_MEAN < <(python3 -c '
import json, sys
r = json.load(open(sys.argv[1]))["results"][0]
print(r["min"], r["mean"])' "$OUT/hyperfine-$name.json")
  else
    "$@" >/dev/null 2>&1 # warm-up
    local times=() i start end
    for i in 1 2 3 4 5; do
      start=$(date +%s%N)
      "$@" >/dev/null
      end=$(date +%s%N)
      times+=("$(( end - start ))")
    done
    read -r T_BEST T_MEAN < <(printf '%s\n' "${times[@]}" \
      | awk 'NR == 1 || $1 < m { m = $1 } { s += $1 } END { printf "%.6f %.6f\n", m / 1e9, s / NR / 1e9 }')
    printf '%s: best %.3f s, mean %.3f s (5 runs)\n' "$name" "$T_BEST" "$T_MEAN" >&2
  fi
}

log "wall time, $SMALL blocks"
time_cmd fiveaxis "$FIVEAXIS" run "$SMALL_PROG"
FA_BEST=$T_BEST FA_MEAN=$T_MEAN
time_cmd rs274 rs274 -g "$SMALL_PROG"
RS_BEST=$T_BEST RS_MEAN=$T_MEAN
log "wall time, $SMALL TCPC type 2 blocks"
rows=$("$FIVEAXIS" run "$TCPC_PROG" | grep -c ',linear,') || die "fiveaxis run failed on $TCPC_PROG"
[ "$rows" = "$SMALL" ] || die "fiveaxis printed $rows linear TCPC rows, expected $SMALL"
time_cmd fiveaxis-tcpc "$FIVEAXIS" run "$TCPC_PROG"
TC_BEST=$T_BEST TC_MEAN=$T_MEAN
log "wall time, fiveaxis check on the $SMALL-block programs"
"$FIVEAXIS" check "$SMALL_PROG" --format json --fail-on never >"$OUT/check-200k.json" \
  || die "fiveaxis check failed on $SMALL_PROG"
grep -q "\"blocks\":$((SMALL + 4))," "$OUT/check-200k.json" || die "fiveaxis check did not run every block"
time_cmd fiveaxis-check "$FIVEAXIS" check "$SMALL_PROG" --format json --fail-on never
CK_BEST=$T_BEST CK_MEAN=$T_MEAN
time_cmd fiveaxis-check-tcpc "$FIVEAXIS" check "$TCPC_PROG" --format json --fail-on never
CKT_BEST=$T_BEST
time_cmd fiveaxis-check-smooth "$FIVEAXIS" check "$SMOOTH_PROG" --format json --fail-on never
CKS_BEST=$T_BEST
time_cmd rs274-smooth rs274 -g "$SMOOTH_PROG"
RSS_BEST=$T_BEST

# CPU time (user + system), best of 5: `run` uses a second thread to write.
cpu_best() { # command...
  local best="" i t
  for i in 1 2 3 4 5; do
    /usr/bin/time -o "$OUT/cpu.txt" -f '%U %S' "$@" >/dev/null 2>&1 || die "$* failed"
    t=$(awk '{ print $1 + $2 }' "$OUT/cpu.txt")
    if [ -z "$best" ] || awk -v a="$t" -v b="$best" 'BEGIN { exit !(a < b) }'; then best=$t; fi
  done
  printf '%s\n' "$best"
}
log "CPU time, $SMALL blocks"
FA_CPU=$(cpu_best "$FIVEAXIS" run "$SMALL_PROG")
RS_CPU=$(cpu_best rs274 -g "$SMALL_PROG")

# The Python package, when this python3 has it.
PY_ROWS=0
if python3 -c 'import fiveaxis' >/dev/null 2>&1; then
  log "the Python package: rows per second into numpy"
  PY_ROWS=$(python3 - "$SMALL_PROG" <<'PY'
import sys, time
import fiveaxis as fx
path = sys.argv[1]
rows = len(fx.run(path))
best = float("inf")
for _ in range(5):
    t = time.perf_counter()
    fx.run(path)
    best = min(best, time.perf_counter() - t)
print(int(rows / best))
PY
)
else
  log "the Python package is not installed in python3: its rows per second are not measured"
fi
log "wall time, $SMALL-block contours: plain, cutter compensation C, 3-D tool compensation"
for kind in plain cutter comp3d; do
  "$FIVEAXIS" run "$OUT/contour-$kind.nc" --machine mill-3axis --offsets "$OUT/offsets.toml" >/dev/null \
    || die "fiveaxis run failed on contour-$kind.nc"
  time_cmd "contour-$kind" "$FIVEAXIS" run "$OUT/contour-$kind.nc" --machine mill-3axis --offsets "$OUT/offsets.toml"
  eval "CONTOUR_${kind^^}=$T_BEST"
done

log "wall time, a $SMALL-iteration macro loop (custom macro B WHILE vs O-word while)"
loop_rows=$("$FIVEAXIS" run "$LOOP_PROG" | grep -c ',linear,') || die "fiveaxis run failed on $LOOP_PROG"
loop_feeds=$(rs274 -g "$LOOP_NGC" 2>/dev/null | grep -c 'STRAIGHT_FEED(' || true)
# rs274 also reports the first block, which does not move (X0 Y0 from
# X0 Y0); fiveaxis gives rows for moves only.
[ "$((loop_rows + 1))" = "$loop_feeds" ] || die "loop: fiveaxis moved $loop_rows times, rs274 $loop_feeds"
time_cmd fiveaxis-loop "$FIVEAXIS" run "$LOOP_PROG"
LOOP_FA=$T_BEST
time_cmd rs274-loop rs274 -g "$LOOP_NGC"
LOOP_RS=$T_BEST

# --- peak memory -----------------------------------------------------------
rss_kb() { # command... ; prints the maximum resident set size in kB
  local report
  report=$(/usr/bin/time -v "$@" 2>&1 >/dev/null) || die "$* failed: $(tail -n 3 <<<"$report")"
  awk -F': *' '/Maximum resident set size/ { print $2 }' <<<"$report"
}
log "peak resident memory"
FA_RSS_SMALL=$(rss_kb "$FIVEAXIS" run "$SMALL_PROG")
FA_RSS_LARGE=$(rss_kb "$FIVEAXIS" run "$LARGE_PROG")
RS_RSS_SMALL=$(rss_kb rs274 -g "$SMALL_PROG")
for v in "$FA_RSS_SMALL" "$FA_RSS_LARGE" "$RS_RSS_SMALL"; do
  [[ "$v" =~ ^[0-9]+$ ]] || die "could not read a peak RSS from /usr/bin/time -v"
done

# `check` and `view` on large inputs: peak memory, time and page size.
# Sets M_RSS (kB), M_SECONDS and M_PAGE (bytes, for view) for a command.
measure() { # page command...
  local page=$1 report start end
  shift
  start=$(date +%s%N)
  report=$(/usr/bin/time -v "$@" 2>&1 >/dev/null) || true
  end=$(date +%s%N)
  M_RSS=$(awk -F': *' '/Maximum resident set size/ { print $2 }' <<<"$report")
  [[ "$M_RSS" =~ ^[0-9]+$ ]] || die "$* failed: $(tail -n 3 <<<"$report")"
  M_SECONDS=$(awk -v n=$(( end - start )) 'BEGIN { printf "%.2f", n / 1e9 }')
  M_PAGE=0
  [ "$page" = - ] || M_PAGE=$(stat -c %s "$page")
}
SPLINES=$OUT/splines20k.ngc
generate 20000 "$SPLINES" --splines
"$FIVEAXIS" machines show trunnion-ac | sed 's/^control = "fanuc30i"/control = "linuxcnc"/' >"$OUT/trunnion-linuxcnc.toml"
MEM_ROWS=()
mem_row() { # label page command...
  local label=$1
  shift
  measure "$@"
  MEM_ROWS+=("$label|$M_RSS|$M_SECONDS|$M_PAGE")
}
log "peak memory of check and view on large inputs"
mem_row "check --format json, $SMALL random blocks" - "$FIVEAXIS" check "$SMALL_PROG" --format json --fail-on never
mem_row "check --format json, $LARGE random blocks" - "$FIVEAXIS" check "$LARGE_PROG" --format json --fail-on never
mem_row "check (text), $LARGE random blocks" - "$FIVEAXIS" check "$LARGE_PROG" --fail-on never
mem_row "check, 20000 G5 splines" - "$FIVEAXIS" check "$SPLINES" --machine "$OUT/trunnion-linuxcnc.toml" --fail-on never
mem_row "view --ends-only, $SMALL random blocks" "$OUT/view-200k.html" "$FIVEAXIS" view "$SMALL_PROG" --ends-only -o "$OUT/view-200k.html"
mem_row "view --ends-only, $LARGE random blocks" "$OUT/view-2M.html" "$FIVEAXIS" view "$LARGE_PROG" --ends-only -o "$OUT/view-2M.html"
mem_row "view, 20000 G5 splines" "$OUT/view-splines.html" "$FIVEAXIS" view "$SPLINES" --machine "$OUT/trunnion-linuxcnc.toml" -o "$OUT/view-splines.html"
MEM_TABLE=$(printf '%s\n' "${MEM_ROWS[@]}")

# --- summary ---------------------------------------------------------------
cpu=$(awk -F': *' '/^model name/ { print $2; exit }' /proc/cpuinfo)
rs_version=$(dpkg-query -W -f '${Version}' linuxcnc-uspace 2>/dev/null || echo unknown)
commit=$(git rev-parse --short HEAD 2>/dev/null || echo unknown)
dirty=$(git status --porcelain --untracked-files=no 2>/dev/null | head -c1)
[ -n "$dirty" ] && commit="$commit (with local changes)"
timer=$([ "$HAVE_HYPERFINE" = 1 ] && echo "hyperfine, 2 warm-ups + 10 runs" || echo "best of 5 after 1 warm-up")

python3 - "$OUT/summary.md" <<EOF
import sys
small, large = $SMALL, $LARGE
fa_best, fa_mean, rs_best, rs_mean = $FA_BEST, $FA_MEAN, $RS_BEST, $RS_MEAN
tc_best, tc_mean, min_tcpc = $TC_BEST, $TC_MEAN, float("$MIN_TCPC")
ck_best, ck_mean, ckt_best = $CK_BEST, $CK_MEAN, $CKT_BEST
ck_ratio = rs_best / ck_best
cks_best, rss_best = $CKS_BEST, $RSS_BEST
cks_ratio = rss_best / cks_best
min_check, min_check_smooth = float("$MIN_CHECK"), float("$MIN_CHECK_SMOOTH")
ok_check = ck_ratio >= min_check and cks_ratio >= min_check_smooth
fa_cpu, rs_cpu, min_cpu = float("$FA_CPU"), float("$RS_CPU"), float("$MIN_CPU_RATIO")
cpu_ratio = rs_cpu / fa_cpu
ok_cpu = cpu_ratio >= min_cpu
py_rows, min_py = int("$PY_ROWS"), float("$MIN_PY_ROWS")
ok_py = py_rows == 0 or py_rows >= min_py
c_plain, c_cutter, c_3d, max_comp = $CONTOUR_PLAIN, $CONTOUR_CUTTER, $CONTOUR_COMP3D, float("$MAX_COMP")
fa_rss_s, fa_rss_l, rs_rss_s = $FA_RSS_SMALL, $FA_RSS_LARGE, $RS_RSS_SMALL
loop_fa, loop_rs, min_loop = $LOOP_FA, $LOOP_RS, float("$MIN_LOOP")
max_check_mb, max_view_mb, max_page_mb = float("$MAX_CHECK_RSS_MB"), float("$MAX_VIEW_RSS_MB"), float("$MAX_PAGE_MB")
mem = [row.split("|") for row in '''$MEM_TABLE'''.strip().splitlines()]
loop_ratio = loop_rs / loop_fa
ok_loop = loop_ratio >= min_loop
min_ratio, max_rss_mb = float("$MIN_RATIO"), float("$MAX_RSS_MB")
fa_bps, rs_bps = small / fa_best, small / rs_best
ratio = fa_bps / rs_bps
mb = lambda kb: kb * 1024 / 1e6
ok_ratio = ratio >= min_ratio
ok_rss = mb(fa_rss_l) < max_rss_mb
tcpc_share = fa_best / tc_best
ok_tcpc = tcpc_share >= min_tcpc
comp_cost = max(c_cutter, c_3d) / c_plain
ok_comp = comp_cost <= max_comp
mem_rows, ok_mem = [], True
for label, rss, seconds, page in mem:
    rss_mb, page_mb = mb(int(rss)), int(page) / 1e6
    limit = max_view_mb if label.startswith("view") else max_check_mb
    ok = rss_mb < limit and page_mb < max_page_mb
    ok_mem = ok_mem and ok
    page_text = f"{page_mb:.1f} MB" if label.startswith("view") else ""
    mem_rows.append(f"| \`{label}\` | {rss_mb:.1f} MB | {float(seconds):.2f} s | {page_text} | {'PASS' if ok else 'FAIL'} |")
lines = [
    "# fiveaxis vs rs274",
    "",
    "| | |",
    "|---|---|",
    "| date | $(date -u '+%Y-%m-%d %H:%M UTC') |",
    "| CPU | $cpu ($(nproc) cores) |",
    "| fiveaxis | $commit, \`fiveaxis run\` CSV to /dev/null, machine trunnion-ac |",
    "| rs274 | linuxcnc-uspace $rs_version, \`rs274 -g\` to /dev/null |",
    "| program | bench/gen.py seed $SEED: G1 X Y Z A C moves |",
    "| timing | $timer; blocks/s from the best run |",
    "",
    "| measure | fiveaxis | rs274 | fiveaxis / rs274 |",
    "|---|---:|---:|---:|",
    f"| wall time, {small:,} blocks (best / mean) | {fa_best:.3f} s / {fa_mean:.3f} s | {rs_best:.3f} s / {rs_mean:.3f} s | |",
    f"| blocks per second | {fa_bps:,.0f} | {rs_bps:,.0f} | **{ratio:.2f}x** |",
    f"| peak RSS, {small:,} blocks | {mb(fa_rss_s):.1f} MB | {mb(rs_rss_s):.1f} MB | {fa_rss_s / rs_rss_s:.2f} |",
    f"| peak RSS, {large:,} blocks | {mb(fa_rss_l):.1f} MB | | |",
    f"| wall time, {small:,} TCPC type 2 blocks (best / mean) | {tc_best:.3f} s / {tc_mean:.3f} s | | {tcpc_share:.2f} of plain G1 |",
    f"| CPU time (user + system), {small:,} blocks (best of 5) | {fa_cpu:.3f} s | {rs_cpu:.3f} s | **{cpu_ratio:.2f}x** |",
    f"| \`fiveaxis check\`, {small:,} blocks (best / mean) | {ck_best:.3f} s / {ck_mean:.3f} s | | **{ck_ratio:.2f}x** rs274 |",
    f"| \`fiveaxis check\` on the smooth 5-axis program (\`--smooth\`), {small:,} blocks (best) | {cks_best:.3f} s | {rss_best:.3f} s | **{cks_ratio:.2f}x** |",
    f"| \`fiveaxis check\`, {small:,} TCPC type 2 blocks (best) | {ckt_best:.3f} s | | {rs_best / ckt_best:.2f}x rs274 |",
    f"| {small:,}-block contour: plain / cutter comp C / 3-D comp (best) | {c_plain:.3f} / {c_cutter:.3f} / {c_3d:.3f} s | | {c_cutter / c_plain:.2f}x / {c_3d / c_plain:.2f}x |",
    f"| {small:,}-iteration macro loop (custom macro B WHILE / O-word while), best | {loop_fa:.3f} s | {loop_rs:.3f} s | **{loop_ratio:.2f}x** |",
    "",
    f"- speed: fiveaxis/rs274 = {ratio:.2f}, required >= {min_ratio:g}: **{'PASS' if ok_ratio else 'FAIL'}**",
    f"- run CPU time: rs274/fiveaxis = {cpu_ratio:.2f}, required >= {min_cpu:g}: **{'PASS' if ok_cpu else 'FAIL'}**",
    f"- check: {cks_ratio:.2f}x rs274 on the smooth program, required >= {min_check_smooth:g};"
    f" {ck_ratio:.2f}x on the random one, required >= {min_check:g}: **{'PASS' if ok_check else 'FAIL'}**",
    (f"- Python: {py_rows / 1e6:.2f} M rows/s into numpy (one row per block), required >= {min_py / 1e6:g} M: **{'PASS' if ok_py else 'FAIL'}**"
     if py_rows else "- Python: not measured (the package is not installed in python3)"),
    f"- macro loop: fiveaxis/rs274 = {loop_ratio:.2f}, required >= {min_loop:g}: **{'PASS' if ok_loop else 'FAIL'}**",
    f"- memory: {mb(fa_rss_l):.1f} MB on {large:,} blocks, required < {max_rss_mb:g} MB: **{'PASS' if ok_rss else 'FAIL'}**",
    f"- TCPC type 2 throughput: {tcpc_share:.2f} of plain G1, required >= {min_tcpc:g}: **{'PASS' if ok_tcpc else 'FAIL'}**",
    f"- compensation cost: {comp_cost:.2f}x a plain contour, required <= {max_comp:g}: **{'PASS' if ok_comp else 'FAIL'}**",
    "",
    f"Peak memory (GNU time) of check and view on large inputs; required below {max_check_mb:g} MB for check,"
    f" {max_view_mb:g} MB for view, pages below {max_page_mb:g} MB:",
    "",
    "| command | peak RSS | wall time | page | |",
    "|---|---:|---:|---:|---|",
    *mem_rows,
]
text = "\n".join(lines) + "\n"
open(sys.argv[1], "w").write(text)
print(text, end="")
sys.exit(0 if ok_ratio and ok_cpu and ok_check and ok_py and ok_rss and ok_tcpc and ok_comp and ok_loop and ok_mem else 1)
EOF
