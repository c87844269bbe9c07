#!/usr/bin/env bash
# The scaling benchmarks: `lambert solve` on the scenes of gen_scale.py (ebox_* electronics
# enclosures, room_* gridded and troom_* triangulated obstructed rooms, 1k to 100k patches);
# wall time, peak memory and the exchange's `links` report of each run, one line per run.
# Usage: validation/scenes/bench_scale.sh [OUT_DIR] [SCENE ...]   (release build first)
#   SCENE: a .toml path or a stem in validation/scenes/scale/ (ebox_10k); default: all of them,
#   smallest first. Env: LAMBERT=path picks the binary; ARGS="--exchange hierarchical
#   --tolerance 1e-3" adds options to every run; TIMEOUT=seconds (default 900) stops a run, and
#   the larger scenes of the same family are then skipped.
set -euo pipefail
cd "$(dirname "$0")/../.."
B=${LAMBERT:-target/release/lambert}
OUT=${1:-/tmp/lambert-scale}
shift || true
TIMEOUT=${TIMEOUT:-900}
mkdir -p "$OUT"
[ -f validation/scenes/scale/troom_100k.toml ] || python3 validation/scenes/gen_scale.py
SCENES=("$@")
if [ ${#SCENES[@]} -eq 0 ]; then
  for n in 1k 2k 5k 10k 20k 50k 100k; do SCENES+=("ebox_$n" "room_$n" "troom_$n"); done
fi
declare -A TIMED_OUT=()
echo "# $B solve ${ARGS:-}  (timeout ${TIMEOUT} s)"
for s in "${SCENES[@]}"; do
  case $s in *.toml) path=$s ;; *) path=validation/scenes/scale/$s.toml ;; esac
  name=$(basename "$path" .toml)
  family=${name%_*}
  if [ -n "${TIMED_OUT[$family]:-}" ]; then
    printf '%-12s skipped (a smaller %s run timed out)\n' "$name" "$family"; continue
  fi
  err=$OUT/$name.err
  rc=0
  # time wraps timeout, so a stopped run leaves no orphan and its peak RSS is still counted.
  /usr/bin/time -v timeout "$TIMEOUT" "$B" solve "$path" ${ARGS:-} -o "$OUT/$name.csv" 2> "$err" || rc=$?
  if [ "$rc" -eq 124 ]; then
    TIMED_OUT[$family]=1
    printf '%-12s timed out after %s s, see %s\n' "$name" "$TIMEOUT" "$err"; continue
  elif [ "$rc" -ne 0 ]; then
    printf '%-12s failed (exit %s), see %s\n' "$name" "$rc" "$err"; continue
  fi
  wall=$(grep "Elapsed (wall" "$err" | awk '{print $NF}')
  rss=$(grep "Maximum resident" "$err" | awk '{print $NF}')
  patches=$(grep -oE '[0-9]+ (patches|unknowns)' "$err" | head -n 1 | awk '{print $1}' || true)
  secs=$(echo "$wall" | awk -F: '{s = 0; for (i = 1; i <= NF; i++) s = s * 60 + $i; print s}')
  links=$(grep -i 'links' "$err" | grep -v '^[[:space:]]*Command being timed' | sed 's/^lambert: //' | paste -sd ';' - || true)
  printf '%-12s %7s patches  wall %9.2f s  peak RSS %7.0f MB  %s\n' "$name" "${patches:-?}" "$secs" \
    "$(echo "$rss / 1024" | bc)" "$links"
done
