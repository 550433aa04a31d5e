#!/usr/bin/env bash
# Regenerates docs/accuracy.md: runs the catalog against the four GL backends (each
# compared with the reference), softpipe and zink against llvmpipe, and the reference and
# the four backends on the `oit` fixtures against ref:abuffer (exact transparency), then
# tabulates the three runs with `rastercheck accuracy`.
# Usage: scripts/accuracy.sh [--keep DIR]   (--keep: leave the three run folders in DIR)
# RASTERCHECK names the binary (default: build/release/app/rastercheck); BACKENDS the
# comma-separated backends to compare with the reference (default: the four below); DRIVERS
# the backends compared with llvmpipe directly (default: softpipe and zink).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
exe=${RASTERCHECK:-$root/build/release/app/rastercheck}
backends=${BACKENDS:-gl:egl:llvmpipe,gl:egl:softpipe,gl:egl:zink,gl:osmesa:llvmpipe}
drivers=${DRIVERS:-gl:egl:softpipe,gl:egl:zink}

if [[ ${1:-} == --keep ]]; then
  work=${2:?--keep needs a folder}
  mkdir -p "$work"
else
  work=$(mktemp -d)
  trap 'rm -rf "$work"' EXIT
fi

# `run` exits 1 when a comparison fails and 3 when a backend cannot run: both are results
# the document reports. Bad input (2) stops here.
run() {
  local code=0
  "$exe" run "$@" >/dev/null || code=$?
  if [[ $code -ne 0 && $code -ne 1 && $code -ne 3 ]]; then
    echo "accuracy.sh: rastercheck run $* exited $code" >&2
    exit "$code"
  fi
}

cd "$root"
rm -rf "$work/catalog" "$work/drivers" "$work/oit"
run fixtures/scenes --backends "$backends" --flip --out "$work/catalog"
run fixtures/scenes --backends "$drivers" --against gl:egl:llvmpipe --flip --out "$work/drivers"
run fixtures/scenes/transparency/oit_*.json --backends "ref,$backends" --against ref:abuffer \
  --no-variants --out "$work/oit"
"$exe" accuracy "$work/catalog" "$work/drivers" "$work/oit" \
  --expectations fixtures/expectations.json \
  --command "\`scripts/accuracy.sh\` (\`rastercheck run fixtures/scenes --backends $backends --flip\`, \`rastercheck run fixtures/scenes --backends $drivers --against gl:egl:llvmpipe --flip\` and \`rastercheck run fixtures/scenes/transparency/oit_*.json --backends ref,$backends --against ref:abuffer\`, then \`rastercheck accuracy\` on the three run folders)" \
  --out docs/accuracy.md

# The random-scene campaigns and mutation studies (scripts/campaign.sh, scripts/mutations.sh)
# write their results to docs/results/; the document lists them.
results_section() {
  echo
  echo "## Random-scene campaigns and the mutation study"
  echo
  echo "How they are run, what a group and its signature are, and how the mutation study"
  echo "counts a fault as caught: [campaigns.md](campaigns.md). Latest results:"
  echo
  local any=0 f
  for f in docs/results/findings.md docs/results/campaign-*.md docs/results/mutations-*.md; do
    [[ -f $f ]] || continue
    any=1
    echo "- [${f#docs/}](${f#docs/})"
  done
  [[ $any -eq 1 ]] || echo "- none yet (run scripts/campaign.sh and scripts/mutations.sh)"
}
results_section >>docs/accuracy.md
