#!/usr/bin/env bash
# The long random-scene campaign of docs/campaigns.md: `rastercheck campaign` over many
# random scenes on the given backends, then its summary copied, with the command and the
# date, to RESULTS_DIR/campaign-s<SEED>-n<COUNT>.md. Interrupt it at any time; running it
# again continues.
# Usage: scripts/campaign.sh [BACKENDS] [COUNT] [SEED] [extra rastercheck campaign options]
#   BACKENDS  comma-separated SPECs (default gl:egl:llvmpipe,gl:egl:softpipe, plus
#             gl:egl:zink where it starts)
#   COUNT     scenes (default 2000);  SEED  (default 20261201)
# RASTERCHECK names the binary (default: build/release/app/rastercheck, built if missing);
# the campaign folder is out/campaign-s<SEED>-n<COUNT> unless CAMPAIGN_OUT names another.
# RESULTS_DIR is where the summary copy goes (default: out/, beside the campaign folder);
# RESULTS_DIR=docs/results replaces the campaign summary docs/accuracy.md cites (do that
# only for a full campaign of the current code, and remove the summary it replaces).
# Exit code: the campaign's (0 no failure, 1 failures, 2 bad input, 3 a backend could not run).
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
exe=${RASTERCHECK:-}
if [[ -z $exe ]]; then
  exe=$(bash "$root/scripts/build.sh")/app/rastercheck
fi
default_backends=gl:egl:llvmpipe,gl:egl:softpipe
probe=$(mktemp -d)
if "$exe" render "$root/fixtures/scenes/coverage/triangle_fan.json" --backend gl:egl:zink \
  --out "$probe/zink" >/dev/null 2>&1; then
  default_backends+=,gl:egl:zink
fi
rm -rf "$probe"
backends=${1:-$default_backends}
count=${2:-2000}
seed=${3:-20261201}
shift $(($# < 3 ? $# : 3))
out=${CAMPAIGN_OUT:-$root/out/campaign-s$seed-n$count}
status=0
"$exe" campaign --seed "$seed" --count "$count" --backends "$backends" --out "$out" "$@" ||
  status=$?
if [[ $status -eq 2 || ! -f $out/summary.md ]]; then exit "$status"; fi
results=${RESULTS_DIR:-$root/out}
mkdir -p "$results"
name=campaign-s$seed-n$count
{
  echo "<!-- Written by scripts/campaign.sh on $(date -u +%Y-%m-%d); do not edit by hand. -->"
  echo
  echo "Command: \`scripts/campaign.sh $backends $count $seed $*\` (campaign folder not"
  echo "kept in the repository; its reproducers are under groups/ there)."
  echo
  sed -e "s|$out/|CAMPAIGN/|g" -e "s|$out|CAMPAIGN|g" "$out/summary.md"
} >"$results/$name.md.tmp"
mv "$results/$name.md.tmp" "$results/$name.md"
echo "wrote $results/$name.md"
exit "$status"
