#!/usr/bin/env bash
# Isolation check of issue 37's kind: renders the same fixtures twice, in the inputs' order
# and in a shuffled one, through `rastercheck run` (long-lived workers: each render follows
# different earlier ones), and requires every frame to have the same bits both times
# (frame.json `frame_digest`: colour, depth, ids, stencil, samples).
#
#   scripts/same-bits.sh INPUT BACKENDS [SEED]
#
# INPUT: a fixture file or folder (as `run` takes it); BACKENDS: comma-separated specs;
# SEED: the shuffle's (default 1). RASTERCHECK names the binary (default: build/release's,
# built if missing); the two runs go to OUT (default a new temporary folder, kept).
# Prints one line per frame whose bits differ, then a summary. Exit 0 when every frame
# matched, 1 when one differed or was missing, 2 when a run could not be made.
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
input=${1:?usage: same-bits.sh INPUT BACKENDS [SEED]}
backends=${2:?usage: same-bits.sh INPUT BACKENDS [SEED]}
seed=${3:-1}
exe=${RASTERCHECK:-}
if [[ -z $exe ]]; then
  exe=$(bash "$root/scripts/build.sh")/app/rastercheck
fi
out=${OUT:-$(mktemp -d /tmp/rc-same-bits.XXXXXX)}
mkdir -p "$out"

# A run's exit code says how the comparisons went (1: a pair failed), not whether it ran.
run() {
  local status=0
  "$exe" run "$input" --backends "$backends" --keep-frames --out "$@" >/dev/null || status=$?
  if [[ $status -ge 2 ]]; then
    echo "same-bits: rastercheck run exited $status ($*)" >&2
    exit 2
  fi
}

run "$out/first"
python3 - "$out/first/report.json" "$seed" >"$out/shuffled.txt" <<'EOF'
import json, random, sys
names = []
for r in json.load(open(sys.argv[1]))["results"]:
    if r["fixture"] not in names:
        names.append(r["fixture"])
random.Random(int(sys.argv[2])).shuffle(names)
print("\n".join(names))
EOF
run "$out/shuffled" --caselist "$out/shuffled.txt"

python3 - "$out/first" "$out/shuffled" <<'EOF'
import glob, json, os, sys
first, second = sys.argv[1], sys.argv[2]
compared = differ = missing = 0
for path in sorted(glob.glob(os.path.join(first, "frames", "*", "*", "frame.json"))):
    rel = os.path.relpath(path, first)
    other = os.path.join(second, rel)
    a = json.load(open(path))
    if not os.path.exists(other):
        print(f"missing in the shuffled run: {rel}")
        missing += 1
        continue
    b = json.load(open(other))
    compared += 1
    if a.get("frame_digest") != b.get("frame_digest") or "frame_digest" not in a:
        print(f"differs: {a.get('fixture')} on {a.get('backend')}: "
              f"{a.get('frame_digest')} / {b.get('frame_digest')}")
        differ += 1
print(f"same-bits: {compared} frames compared, {differ} differ, {missing} missing "
      f"(runs in {os.path.dirname(first)})")
sys.exit(1 if differ or missing or compared == 0 else 0)
EOF
