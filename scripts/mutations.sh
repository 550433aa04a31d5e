#!/usr/bin/env bash
# The long mutation study of docs/campaigns.md: `rastercheck campaign --mutations` injects
# each test-only GL fault (move_vertex, move_line_end, move_point, depth_bias, light_scale, texel_offset,
# drop_primitive, blend_factor, depth_func, stencil_op, blend_function, scissor_shift,
# lod_shift, lod_weight, shadow_shift, shadow_compare, shadow_bias) into
# every random scene and reports, per fault, the
# fraction caught in its class among the scenes where it changes a pixel beyond its
# allowance. The report is copied, with the command and the date, to
# RESULTS_DIR/mutations-s<SEED>-n<COUNT>.md. Interruptible and resumable like
# scripts/campaign.sh.
# Usage: scripts/mutations.sh [BACKENDS] [COUNT] [SEED] [extra rastercheck campaign options]
#   BACKENDS  comma-separated GL SPECs (default gl:egl:llvmpipe)
#   COUNT     scenes (default 500);  SEED  (default 20261202)
# RASTERCHECK names the binary; the study folder is out/mutations-s<SEED>-n<COUNT> unless
# CAMPAIGN_OUT names another. RESULTS_DIR is where the report copy goes (default: out/,
# beside the study folder); RESULTS_DIR=docs/results replaces the mutation summary
# docs/accuracy.md cites (remove the one it replaces). Exit code: 0 every counted fault
# caught, 1 some missed, 2 bad input, 3 a render failed.
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
exe=${RASTERCHECK:-}
if [[ -z $exe ]]; then
  exe=$(bash "$root/scripts/build.sh")/app/rastercheck
fi
backends=${1:-gl:egl:llvmpipe}
count=${2:-500}
seed=${3:-20261202}
shift $(($# < 3 ? $# : 3))
out=${CAMPAIGN_OUT:-$root/out/mutations-s$seed-n$count}
status=0
"$exe" campaign --mutations --seed "$seed" --count "$count" --backends "$backends" \
  --out "$out" "$@" || status=$?
if [[ $status -eq 2 || ! -f $out/mutations.md ]]; then exit "$status"; fi
results=${RESULTS_DIR:-$root/out}
mkdir -p "$results"
name=mutations-s$seed-n$count
{
  echo "<!-- Written by scripts/mutations.sh on $(date -u +%Y-%m-%d); do not edit by hand. -->"
  echo
  echo "Command: \`scripts/mutations.sh $backends $count $seed $*\`."
  echo
  sed -e "s|$out/|STUDY/|g" -e "s|$out|STUDY|g" "$out/mutations.md"
} >"$results/$name.md.tmp"
mv "$results/$name.md.tmp" "$results/$name.md"
echo "wrote $results/$name.md"
exit "$status"
