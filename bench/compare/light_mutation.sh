#!/usr/bin/env bash
# The shading tolerance's sensitivity check (docs/tolerances.md): every catalog fixture
# with lights is rendered by each driver with every light's intensity x FACTOR and
# compared with the reference frame of the unmodified fixture. Prints one line per pair:
# status, shading status, compared pixels, pixels over warn and over fail, largest error.
#
#   bench/compare/light_mutation.sh [BUILD_DIR] [FACTOR] [BACKEND...]
#   (defaults: build/release, 1.01, gl:egl:llvmpipe gl:egl:softpipe)
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)
build=${1:-$root/build/release}
factor=${2:-1.01}
shift $(( $# > 2 ? 2 : $# ))
backends=("$@")
[[ ${#backends[@]} -gt 0 ]] || backends=(gl:egl:llvmpipe gl:egl:softpipe)
exe=$build/app/rastercheck
work=$(mktemp -d /tmp/rc-light-mutation.XXXXXX)
trap 'rm -rf "$work"' EXIT

python3 - "$root/fixtures/scenes" "$work/fixtures" "$factor" <<'PY'
import glob, json, os, sys
src, dst, factor = sys.argv[1], sys.argv[2], float(sys.argv[3])
os.makedirs(dst)
for path in sorted(glob.glob(os.path.join(src, "**", "*.json"), recursive=True)):
    scene = json.load(open(path))
    if scene.get("format") != "rastercheck-scene/1" or not scene.get("lights"):
        continue
    base = os.path.dirname(path)
    for light in scene["lights"]:
        light["intensity"] = light.get("intensity", 1.0) * factor
    for obj in scene["objects"]:
        if "file" in obj["mesh"] and not os.path.isabs(obj["mesh"]["file"]):
            obj["mesh"]["file"] = os.path.join(base, obj["mesh"]["file"])
    for mat in scene.get("materials", {}).values():
        if "texture" in mat and not os.path.isabs(mat["texture"]):
            mat["texture"] = os.path.join(base, mat["texture"])
    slug = scene["name"].replace("/", "__")
    json.dump(scene, open(os.path.join(dst, slug + ".json"), "w"))
    json.dump({"original": path}, open(os.path.join(dst, slug + ".source"), "w"))
PY

for mutated in "$work"/fixtures/*.json; do
  slug=$(basename "$mutated" .json)
  original=$(python3 -c "import json,sys;print(json.load(open(sys.argv[1]))['original'])" \
    "${mutated%.json}.source")
  "$exe" render "$original" --backend ref --out "$work/$slug/ref" >/dev/null
  for backend in "${backends[@]}"; do
    side=$work/$slug/${backend//:/_}
    "$exe" render "$mutated" --backend "$backend" --out "$side" >/dev/null
    "$exe" compare "$work/$slug/ref" "$side" --out "$side-report" >/dev/null || true
    python3 - "$side-report/report.json" "$slug" "$backend" <<'PY'
import json, sys
r = json.load(open(sys.argv[1]))["results"][0]
s = r["shading"]
print(f"{sys.argv[2]:42s} {sys.argv[3]:16s} {r['status']:5s} shading {s['status']:5s} "
      f"compared {s['compared']:6d} over warn {s['over_tolerance']:6d} "
      f"over fail {s['over_fail']:6d} max {s['max_abs']:.3f}")
PY
  done
done
