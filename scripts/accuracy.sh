#!/usr/bin/env bash
# Regenerates docs/accuracy.md: runs the catalog against the four GL backends (each
# compared with the reference), softpipe and zink against llvmpipe, and the reference and
# the four backends on the `oit` fixtures against ref:abuffer (exact transparency), then
# tabulates the three runs with `rastercheck accuracy`, puts who the page is for after its
# title, and ends it with a list of docs/results/ (findings.md and the kept campaign and
# mutation summaries).
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

# Who the page is for, after its title (`rastercheck accuracy` writes everything else).
audience() {
  echo "For anyone choosing a Mesa driver or judging a change to one: how far each driver is"
  echo "from the reference (and softpipe and zink from llvmpipe) on the fixture catalog, which"
  echo "differences are known and why, and where the random-scene campaigns stand."
}
{
  head -n 1 docs/accuracy.md
  echo
  audience
  tail -n +2 docs/accuracy.md
} >docs/accuracy.md.tmp
mv docs/accuracy.md.tmp docs/accuracy.md

# docs/results/ keeps findings.md and the latest full campaign and mutation summaries
# (scripts/campaign.sh and scripts/mutations.sh with RESULTS_DIR=docs/results write them);
# the document lists them and says what each is.
results_section() {
  echo
  echo "## Random-scene campaigns and the mutation study"
  echo
  echo "How they are run, what a group and its signature are, and how the mutation study"
  echo "counts a fault as caught: [campaigns.md](campaigns.md)."
  echo
  local f name any=0
  if [[ -f docs/results/findings.md ]]; then
    echo "- [results/findings.md](results/findings.md): every driver difference the campaigns"
    echo "  found, with its cause, reduced fixture, expectations entry and the command that"
    echo "  shows it, and the apparent differences that were gaps in the harness"
  fi
  for f in docs/results/campaign-*.md docs/results/mutations-*.md; do
    [[ -f $f ]] || continue
    any=1
    name=${f#docs/results/}
    if [[ $name =~ ^(campaign|mutations)-s([0-9]+)-n([0-9]+)\.md$ ]]; then
      if [[ ${BASH_REMATCH[1]} == campaign ]]; then
        echo "- [${f#docs/}](${f#docs/}):"
        echo "  the latest full campaign (${BASH_REMATCH[3]} scenes, seed ${BASH_REMATCH[2]}): pass, warn"
        echo "  and fail per backend, the failures grouped by signature, and the known difference"
        echo "  covering each group"
      else
        echo "- [${f#docs/}](${f#docs/}):"
        echo "  the latest mutation study (${BASH_REMATCH[3]} scenes, seed ${BASH_REMATCH[2]}): per backend"
        echo "  and fault, how often the fault is caught in its class where it changes a pixel"
        echo "  beyond its allowance"
      fi
    else
      echo "- [${f#docs/}](${f#docs/})"
    fi
  done
  if [[ $any -eq 0 ]]; then
    echo "- no campaign or mutation summary kept (scripts/campaign.sh and scripts/mutations.sh"
    echo "  with RESULTS_DIR=docs/results write one)"
  fi
}
results_section >>docs/accuracy.md
