#!/usr/bin/env bash
# Bit-identity check for reference speed work: renders every catalog fixture with two
# builds' `rastercheck render --backend SPEC` and byte-compares frame.exr and color.png.
#
#   bench/reference/catalog_bytes.sh OLD_RASTERCHECK NEW_RASTERCHECK [FIXTURE_DIR...]
#
# Fixture folders default to fixtures/scenes. RC_SPECS lists the backend specs (default
# "ref ref:painter ref:abuffer ref:subpixel=4"). Prints one line per difference and a
# summary; exits 1 when any file differs or a render fails on one side only.
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)
old=${1:?usage: catalog_bytes.sh OLD_RASTERCHECK NEW_RASTERCHECK [FIXTURE_DIR...]}
new=${2:?usage: catalog_bytes.sh OLD_RASTERCHECK NEW_RASTERCHECK [FIXTURE_DIR...]}
shift 2
dirs=("$@")
((${#dirs[@]})) || dirs=("$root/fixtures/scenes")
read -r -a specs <<<"${RC_SPECS:-ref ref:painter ref:abuffer ref:subpixel=4}"

work=$(mktemp -d /tmp/rc-catalog-bytes.XXXXXX)
trap 'rm -rf "$work"' EXIT
frames=0
files=0
differ=0
while IFS= read -r fixture; do
  # Scene files only (the catalog also holds expectation lists and the like).
  grep -q '"rastercheck-scene/1"' "$fixture" || continue
  for spec in "${specs[@]}"; do
    tag=$(printf '%s' "$fixture|$spec" | md5sum | cut -c1-12)
    set +e
    "$old" render "$fixture" --backend "$spec" --out "$work/old-$tag" >/dev/null 2>&1
    old_rc=$?
    "$new" render "$fixture" --backend "$spec" --out "$work/new-$tag" >/dev/null 2>&1
    new_rc=$?
    set -e
    if ((old_rc != new_rc)); then
      echo "EXIT $old_rc vs $new_rc: $fixture $spec"
      differ=$((differ + 1))
      continue
    fi
    ((old_rc == 0)) || continue
    frames=$((frames + 1))
    for f in frame.exr color.png; do
      files=$((files + 1))
      if ! cmp -s "$work/old-$tag/$f" "$work/new-$tag/$f"; then
        echo "DIFFERS: $fixture $spec $f"
        differ=$((differ + 1))
      fi
    done
    rm -rf "$work/old-$tag" "$work/new-$tag"
  done
done < <(find "${dirs[@]}" -name '*.json' | sort)
echo "$frames frames, $files files compared, $differ differences"
((differ == 0))
