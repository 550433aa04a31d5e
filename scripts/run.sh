#!/usr/bin/env bash
# The README's main job: installs what is missing and builds (scripts/build.sh), then runs
# the whole fixture catalog through `rastercheck run` against Mesa's llvmpipe, softpipe and
# zink over lavapipe (EGL) and prints where report.html is. Extra arguments go to `rastercheck run`, e.g.
# `scripts/run.sh --jobs 4` or `scripts/run.sh fixtures/scenes/shading`.
# Exit code: rastercheck's (0 pass or warn, 1 a comparison failed, 2 bad input, 3 a backend
# could not run).
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
build=$(bash "$root/scripts/build.sh")
out=${RASTERCHECK_OUT:-$root/out/catalog}
backends=${RASTERCHECK_BACKENDS:-gl:egl:llvmpipe,gl:egl:softpipe,gl:egl:zink}
paths=()
options=()
for arg in "$@"; do
  if [[ ${#options[@]} -eq 0 && $arg != -* ]]; then paths+=("$arg"); else options+=("$arg"); fi
done
[[ ${#paths[@]} -gt 0 ]] || paths=("$root/fixtures/scenes")
status=0
"$build/app/rastercheck" run "${paths[@]}" --backends "$backends" --out "$out" \
  ${options[@]+"${options[@]}"} || status=$?
if [[ -f "$out/report.html" && $status -ne 2 ]]; then
  echo "open: file://$out/report.html"
fi
exit $status
