#!/usr/bin/env bash
# Whole-process timing on one 1080p pair, in one run: `rastercheck compare` (reads both
# frame folders, compares every pixel, writes report.json/junit.xml/report.html and the
# pair's images) against `idiff` comparing the same pair's colour PNGs alone. The pair is
# the catalog teapot at 1920x1080 rendered with the reference and with llvmpipe.
#
#   bench/compare/compare_vs_idiff.sh [BUILD_DIR] [ROUNDS]     (default build/release, 7)
#
# RC_COMPARE_ARGS adds arguments to every `rastercheck compare`, e.g. "--flip" to time it
# with LDR-FLIP (opt-in). RC_BASELINE=EXE times another build's `compare`
# (e.g. main's) in the same rounds. Each command's CPU time (user + sys) is printed too.
# RC_EXR_COMPRESSION=LIST re-encodes the two frame.exr files with oiiotool before timing,
# one measurement per entry ("asis" keeps what `render` wrote), e.g. "asis zip none".
# Rounds alternate the commands, each round starting with the next one, so that all see the
# same machine load and none is always first; the medians
# and minimums are printed. Wall-clock seconds.
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)
build=${1:-$root/build/release}
rounds=${2:-7}
compressions=${RC_EXR_COMPRESSION:-asis}
read -r -a compare_args <<<"${RC_COMPARE_ARGS:-}"
exe=$build/app/rastercheck
[[ -x $exe ]] || { echo "no $exe: build first (scripts/build.sh)" >&2; exit 2; }
command -v idiff >/dev/null || { echo "idiff not found (openimageio-tools)" >&2; exit 2; }

work=$(mktemp -d /tmp/rc-compare-vs-idiff.XXXXXX)
trap 'rm -rf "$work"' EXIT
python3 - "$root/fixtures/scenes/shading/teapot.json" "$work/teapot_1080p.json" <<'PY'
import json, os, sys
src, dst = sys.argv[1], sys.argv[2]
scene = json.load(open(src))
scene["name"] = "bench/teapot_1080p"
scene["image"] = {"width": 1920, "height": 1080}
base = os.path.dirname(os.path.abspath(src))
for obj in scene["objects"]:  # keep relative mesh and texture paths working
    if "file" in obj["mesh"] and not os.path.isabs(obj["mesh"]["file"]):
        obj["mesh"]["file"] = os.path.join(base, obj["mesh"]["file"])
for mat in scene.get("materials", {}).values():
    if "texture" in mat and not os.path.isabs(mat["texture"]):
        mat["texture"] = os.path.join(base, mat["texture"])
json.dump(scene, open(dst, "w"))
PY
"$exe" render "$work/teapot_1080p.json" --backend ref --out "$work/asis/ref" >/dev/null
"$exe" render "$work/teapot_1080p.json" --backend gl:egl:llvmpipe --out "$work/asis/gl" >/dev/null

seconds() {  # "wall cpu" seconds of a command, output discarded, exit status ignored
  /usr/bin/time -o "$work/time.txt" -f "%e %U %S" "$@" >/dev/null 2>&1 || true
  tail -1 "$work/time.txt" | awk '{printf "%s %.3f\n", $1, $2 + $3}'
}
stats() {  # median and minimum wall time, median CPU time of "wall cpu" arguments
  printf '%s\n' "$@" | awk '{print $1}' | sort -g |
    awk '{v[NR]=$1} END {printf "median %.3f s, min %.3f s", v[int((NR+1)/2)], v[1]}'
  printf '%s\n' "$@" | awk '{print $2}' | sort -g |
    awk '{v[NR]=$1} END {printf ", CPU median %.3f s", v[int((NR+1)/2)]}'
}

for comp in $compressions; do
  dir=$work/$comp
  if [[ $comp != asis ]]; then
    for side in ref gl; do
      mkdir -p "$dir/$side"
      cp "$work/asis/$side/frame.json" "$work/asis/$side/color.png" "$dir/$side/"
      oiiotool "$work/asis/$side/frame.exr" --compression "$comp" -o "$dir/$side/frame.exr"
    done
  fi
  exr_size=$(du -k "$dir/ref/frame.exr" | cut -f1)
  compare_times=()
  baseline_times=()
  idiff_times=()
  # Each round starts with another command (the first of a round measured ~0.15 s slower
  # than the same binary second: an order effect, not a difference of the programs).
  run_one() {
    case $1 in
      compare) compare_times+=("$(seconds "$exe" compare "$dir/ref" "$dir/gl" --out "$work/report-$comp" "${compare_args[@]}")") ;;
      baseline)
        if [[ -n ${RC_BASELINE:-} ]]; then
          baseline_times+=("$(seconds "$RC_BASELINE" compare "$dir/ref" "$dir/gl" --out "$work/baseline-$comp")")
        fi ;;
      idiff) idiff_times+=("$(seconds idiff "$dir/ref/color.png" "$dir/gl/color.png")") ;;
    esac
  }
  order=(compare baseline idiff)
  for ((i = 0; i < rounds; ++i)); do
    for ((k = 0; k < 3; ++k)); do run_one "${order[(i + k) % 3]}"; done
  done
  echo "frame.exr $comp (${exr_size} KiB), $rounds rounds:"
  echo "  rastercheck compare ${RC_COMPARE_ARGS:-}: $(stats "${compare_times[@]}")"
  [[ -z ${RC_BASELINE:-} ]] || echo "  $RC_BASELINE compare: $(stats "${baseline_times[@]}")"
  echo "  idiff (PNGs only):   $(stats "${idiff_times[@]}")"
done
