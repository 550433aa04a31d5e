#!/usr/bin/env bash
# The README's main job: installs what is missing, builds, renders the fixture catalog
# with the reference and prints where the frames are. (The comparison against llvmpipe
# and softpipe is added by `rastercheck run` once the comparator lands.)
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
build=$(bash "$root/scripts/build.sh")
out=${RASTERCHECK_OUT:-$root/out/catalog}
status=0
while IFS= read -r f; do
  name=$(basename "$(dirname "$f")")__$(basename "$f" .json)
  "$build/app/rastercheck" render "$f" --backend ref --out "$out/$name" || status=$?
done < <(find "$root/fixtures/scenes" -name '*.json' | sort)
echo "frames: $out"
exit $status
