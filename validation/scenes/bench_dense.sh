#!/usr/bin/env bash
# The lean dense path's benchmarks (validation/solve.md): wall time, CPU time and peak memory of
# each run, from a release build. Usage: validation/scenes/bench_dense.sh [OUT_DIR]
set -euo pipefail
cd "$(dirname "$0")/../.."
B=target/release/lambert
OUT=${1:-/tmp/lambert-bench}
mkdir -p "$OUT"
[ -f validation/scenes/triangle_box_surfaces.toml ] || python3 validation/scenes/gen_triangle_box.py
run() {
  local name=$1; shift
  /usr/bin/time -v "$B" "$@" 2> "$OUT/$name.err" > "$OUT/$name.out" || { echo "$name: exit $?"; return; }
  local wall rss user sys
  wall=$(grep "Elapsed (wall" "$OUT/$name.err" | awk '{print $NF}')
  rss=$(grep "Maximum resident" "$OUT/$name.err" | awk '{print $NF}')
  user=$(grep "User time" "$OUT/$name.err" | awk '{print $NF}')
  sys=$(grep "System time" "$OUT/$name.err" | awk '{print $NF}')
  printf '%-28s wall %8s  user+sys %7.1f s  peak RSS %7.0f MB\n' "$name" "$wall" "$(echo "$user + $sys" | bc)" "$(echo "$rss / 1024" | bc)"
}
run room_solve solve validation/scenes/room_8472.toml --quiet
run room_vf_patches_closure viewfactors validation/scenes/room_8472.toml --tolerance 1e-4 --patches --enforce closure --quiet -o "$OUT/room_vf.csv"
run cube50_solve solve validation/scenes/cube_furnace_50.toml --quiet
run cube50_vf_patches viewfactors validation/scenes/cube_furnace_50.toml --patches --quiet -o /dev/null
run tribox_glb viewfactors validation/scenes/triangle_box_model.toml --quiet -o /dev/null
run tribox_surfaces viewfactors validation/scenes/triangle_box_surfaces.toml --quiet -o /dev/null
