#!/usr/bin/env bash
# The CAD benchmarks of validation/cad.md: each scene of gen_cad.py with `analytic`, `auto` and
# `mc-cosine`; wall time, peak memory, and the largest difference from the `analytic` run.
# Usage: validation/scenes/bench_cad.sh [OUT_DIR] [SCENE ...]   (release build first;
# LAMBERT=path picks the binary, METHODS="auto mc-cosine" the methods; VIEW3D=path also runs
# View3D on the box scenes, in the same script, and compares its factors with `analytic`)
set -euo pipefail
cd "$(dirname "$0")/../.."
B=${LAMBERT:-target/release/lambert}
OUT=${1:-/tmp/lambert-cad}
shift || true
mkdir -p "$OUT"
[ -f validation/scenes/cad/sphere_room.toml ] || python3 validation/scenes/gen_cad.py
SCENES=("$@")
METHODS=(${METHODS:-analytic auto mc-cosine})
[ ${#SCENES[@]} -gt 0 ] || SCENES=(box_500 box_500_block box_2k box_2k_block box_8k box_8k_block sphere_room)
run() {
  local scene=$1 method=$2 name="$1.$2"
  if ! /usr/bin/time -v "$B" viewfactors "validation/scenes/cad/$scene.toml" -m "$method" \
      -o "$OUT/$name.csv" 2> "$OUT/$name.err"; then
    echo "$name: failed, see $OUT/$name.err"; return
  fi
  local wall rss pairs cmp=""
  wall=$(grep "Elapsed (wall" "$OUT/$name.err" | awk '{print $NF}')
  rss=$(grep "Maximum resident" "$OUT/$name.err" | awk '{print $NF}')
  pairs=$(grep -o '[0-9.e+]* pairs/s' "$OUT/$name.err" | tail -n 1 || true)
  [ "$method" != analytic ] && [ -f "$OUT/$scene.analytic.csv" ] &&
    cmp=$(python3 validation/scenes/compare_vf.py "$OUT/$scene.analytic.csv" "$OUT/$name.csv")
  printf '%-16s %-10s wall %9s  peak RSS %6.0f MB  %-18s %s\n' "$scene" "$method" "$wall" \
    "$(echo "$rss / 1024" | bc)" "$pairs" "$cmp"
}
view3d() {
  local scene=$1 cmp=""
  [ -f "$OUT/$scene.vs3" ] || return 0
  # View3D writes View3D.log where it runs.
  if ! (cd "$OUT" && /usr/bin/time -v "$VIEW3D" "$scene.vs3" "$scene.vf" > "$scene.view3d.log" \
      2> "$scene.view3d.err"); then
    echo "$scene.View3D: failed, see $OUT/$scene.view3d.err"; return
  fi
  local wall rss
  wall=$(grep "Elapsed (wall" "$OUT/$scene.view3d.err" | awk '{print $NF}')
  rss=$(grep "Maximum resident" "$OUT/$scene.view3d.err" | awk '{print $NF}')
  [ -f "$OUT/$scene.analytic.csv" ] && cmp=$(python3 validation/scenes/compare_vf.py \
    "$OUT/$scene.analytic.csv" "$OUT/$scene.vf" "$OUT/${scene%_block}.names")
  printf '%-16s %-10s wall %9s  peak RSS %6.0f MB  %-18s %s\n' "$scene" "View3D" "$wall" \
    "$(echo "$rss / 1024" | bc)" "(1 core, eps 1e-4)" "$cmp"
}
[ -n "${VIEW3D:-}" ] && VIEW3D=$(realpath "$VIEW3D") && python3 validation/scenes/gen_cad.py --view3d "$OUT" > /dev/null
for s in "${SCENES[@]}"; do
  for m in "${METHODS[@]}"; do run "$s" "$m"; done
  if [ -n "${VIEW3D:-}" ]; then view3d "$s"; fi
done
