#!/usr/bin/env bash
# Weft against the peer solvers on the shared reference workload (scripts/peers/README.md,
# assets/scenes/reference.toml): N×N 1 m cloth of 1 kg, top edge pinned, stretch + shear at
# α = 0, dt = 1/60, 10 substeps × 1 iteration, no bending, no collisions.
#
# Builds Weft's example (release) `crates/weft-solver/examples/reference_workload.rs`, then
# runs it and every peer whose venv exists (Taichi coloured GS, Newton/Warp XPBD, pypbd) REPS
# times, interleaved so that load on this shared machine hits all of them alike. Each run
# prints "ms/frame=MEAN (median MEDIAN)"; the table shows the median over runs of those
# medians, the best run, and each peer's time divided by Weft's at the same thread count
# (Taichi/Weft > 1: Weft is faster). Single-thread runs are pinned to one CPU (Taichi pins
# itself; Weft through taskset) because cross-CPU wake-ups dominate otherwise on this VM.
#
# Weft runs on the widest kernel path the CPU has, or on the one WEFT_SIMD forces
# (avx512|avx2|neon|scalar, passed through); the table names the path that ran.
#
# Prerequisite for the peers: bash scripts/peers/setup.sh   (venvs under /tmp/peers)
# Usage: scripts/compare_peers.sh            (env: N=128 REPS=5 THREADS="1 2" FRAMES=30
#                                            PEERS_DIR=scripts/peers PEERS_ROOT=/tmp/peers)
set -euo pipefail
repo="$(cd "$(dirname "$0")/.." && pwd)"
peers="${PEERS_DIR:-$repo/scripts/peers}"
venvs="${PEERS_ROOT:-/tmp/peers}"
N="${N:-128}"
REPS="${REPS:-5}"
THREADS="${THREADS:-1 2}"
FRAMES="${FRAMES:-30}"

echo "# building Weft's reference_workload example (release)" >&2
exe="$(cd "$repo" && cargo build --release -p weft-solver --example reference_workload \
  --message-format=json-render-diagnostics | python3 -c '
import json, sys
for line in sys.stdin:
    m = json.loads(line)
    if m.get("reason") == "compiler-artifact" and m["target"]["name"] == "reference_workload":
        exe = m.get("executable")
print(exe)')"
[ -x "$exe" ] || { echo "compare_peers: the example was not built ($exe)" >&2; exit 1; }

pin() {  # pin() THREADS CMD...: one CPU when single-threaded
  if [ "$1" = 1 ] && command -v taskset > /dev/null; then
    shift
    taskset -c "$(python3 -c 'import os; print(min(os.sched_getaffinity(0)))')" "$@"
  else
    shift
    "$@"
  fi
}

# peer name -> command (THREADS substituted); a peer whose interpreter is missing is skipped.
declare -A cmd
order=()
add() { order+=("$1"); cmd[$1]="$2"; }
add weft "pin @T $exe --n $N --frames $FRAMES --threads @T"
if [ -x "$venvs/venv-taichi/bin/python" ]; then
  add taichi "$venvs/venv-taichi/bin/python $peers/taichi_cloth.py --n $N --frames $FRAMES --threads @T --quiet"
else
  echo "# no $venvs/venv-taichi: run bash $peers/setup.sh first for the Taichi figures" >&2
fi
if [ -x "$venvs/venv-pbd/bin/python" ]; then
  add pypbd "$venvs/venv-pbd/bin/python $peers/pbd_cloth.py --n $N --frames $FRAMES --threads @T --quiet"
fi
if [ -x "$venvs/venv-newton/bin/python" ]; then
  add newton "$venvs/venv-newton/bin/python $peers/warp_cloth.py --n $N --frames $FRAMES --quiet"
fi

declare -A runs
weft_path=""
uptime >&2
for rep in $(seq 1 "$REPS"); do
  for t in $THREADS; do
    for p in "${order[@]}"; do
      # Newton/Warp has no thread setting: run it once per repetition, as "1".
      [ "$p" = newton ] && [ "$t" != 1 ] && continue
      line="$(eval "${cmd[$p]//@T/$t}" 2>&1 | grep -E 'ms/frame=' | head -1 || true)"
      med="$(sed -nE 's/.*\(median ([0-9.]+)\).*/\1/p' <<< "$line")"
      if [ -z "$med" ]; then
        echo "# $p threads=$t run $rep: no ms/frame line" >&2
        continue
      fi
      [ "$p" = weft ] && weft_path="$(sed -nE 's/.* simd=([a-z0-9]+) .*/\1/p' <<< "$line")"
      echo "# run $rep $p threads=$t: median $med ms/frame" >&2
      runs["$p|$t"]="${runs["$p|$t"]:-} $med"
    done
  done
done

stat() {  # stat median|min VALUES...
  python3 -c 'import statistics, sys
v = [float(x) for x in sys.argv[2:]]
x = statistics.median(v) if sys.argv[1] == "median" else min(v)
print("%.3f" % x)' "$@"
}
ratio() { python3 -c 'import sys; print(f"{float(sys.argv[1]) / float(sys.argv[2]):.2f}")' "$1" "$2"; }

echo
echo "Reference workload, N = $N ($((N * N)) particles, $((2 * N * (N - 1) + 2 * (N - 1) * (N - 1))) constraints), 10 substeps × 1 iteration, $FRAMES frames per run, $REPS runs"
echo
echo "Weft's kernel path: ${weft_path:-unknown} (WEFT_SIMD=${WEFT_SIMD:-unset}); CPU: $(sed -nE 's/^model name\s*:\s*//p' /proc/cpuinfo | head -1)"
echo
echo "| solver | threads | runs | median ms/frame | best run | this / Weft |"
echo "|---|---|---|---|---|---|"
declare -A medians
for t in $THREADS; do
  for p in "${order[@]}"; do
    vals="${runs["$p|$t"]:-}"
    [ -n "$vals" ] || continue
    # shellcheck disable=SC2086
    med="$(stat median $vals)"; best="$(stat min $vals)"
    medians["$p|$t"]="$med"
    rel="–"
    w="${medians["weft|$t"]:-}"
    [ -n "$w" ] && rel="$(ratio "$med" "$w")"
    echo "| $p | $t | $(wc -w <<< "$vals") | $med | $best | $rel |"
  done
done
echo
for t in $THREADS; do
  w="${medians["weft|$t"]:-}"; ti="${medians["taichi|$t"]:-}"
  if [ -n "$w" ] && [ -n "$ti" ]; then
    echo "Taichi/Weft, $t thread(s): $(ratio "$ti" "$w")  (Taichi $ti ms/frame, Weft $w ms/frame)"
  else
    missing=Taichi
    [ -n "$w" ] || missing=Weft
    echo "Taichi/Weft, $t thread(s): – (no $missing figure)"
  fi
done
uptime >&2
