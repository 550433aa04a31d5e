#!/usr/bin/env bash
# Fuzzes the fixture loader, mesh import and texture import for a bounded time with
# libFuzzer (the fuzz preset: clang, ASan, UBSan). fuzz_mesh runs the Assimp side of mesh
# import in its own process, not through the rastercheck-mesh-import child, so that its
# coverage counts (tests/fuzz/fuzz_entries.h). Seeds come from the catalog (fixtures,
# meshes, textures) and from every input kept in tests/fuzz/regressions; each target runs
# for SECONDS (default 60) and the figures go to stdout. A crash, a sanitizer report, a
# leak or an abort from fuzz_entries.h (an exception other than InputError, a message
# that is not one safe line) stops the script with exit 1 and leaves the input in
# build/fuzz/findings/<target>/: replay it with `build/fuzz/tests/fuzz/fuzz_<target> FILE`,
# fix the cause, and add the file to tests/fuzz/regressions/<target>/ (the regression
# test then replays it in every build).
# Usage: scripts/fuzz.sh [SECONDS] [TARGET...]   (targets: fixture mesh texture)
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
seconds=${1:-60}
shift || true
targets=("$@")
[[ ${#targets[@]} -gt 0 ]] || targets=(fixture mesh texture)

bash "$root/scripts/setup.sh"
build="$root/build/fuzz"
mkdir -p "$root/build"
if [[ ! -f "$build/build.ninja" ]]; then
  cmake --preset fuzz -S "$root" >"$root/build/configure-fuzz.log" 2>&1 || {
    cat "$root/build/configure-fuzz.log" >&2; exit 1; }
fi
cmake --build "$build" --parallel "$(nproc)" $(printf -- '--target fuzz_%s ' "${targets[@]}") >&2

work="$build/work"
rm -rf "$work"
mkdir -p "$work"

# Seeds: the catalog and the test data, in each target's input form (mesh and texture
# inputs start with a byte that picks the format: fuzz_entries.h).
seed_fixture() {
  local dir="$work/seeds/fixture"
  mkdir -p "$dir"
  find "$root/fixtures/scenes" "$root/tests/fixtures/data" -name '*.json' -size -64k \
    -exec cp -t "$dir" {} + 2>/dev/null || true
}
seed_prefixed() {  # seed_prefixed TARGET INDEX FILE
  local dir="$work/seeds/$1"
  mkdir -p "$dir"
  { printf "\\x$(printf %02x "$2")"; cat "$3"; } >"$dir/$(basename "$3").$2"
}
seed_mesh() {
  local exts=(obj ply stl off gltf glb 3ds dae fbx x md2 ase)
  for i in "${!exts[@]}"; do
    while IFS= read -r f; do seed_prefixed mesh "$i" "$f"; done < <(
      find "$root/tests/fixtures/data/meshes" /usr/share/assimp/models \
        -iname "*.${exts[$i]}" -size -24k 2>/dev/null | sort | head -n 6)
  done
}
seed_texture() {
  local exts=(png jpg bmp tga exr hdr tif gif ppm)
  local src="$root/fixtures/scenes/textures/checker.png"
  mkdir -p "$work/convert"
  for i in "${!exts[@]}"; do
    local f="$work/convert/checker.${exts[$i]}"
    if [[ ${exts[$i]} == png ]]; then cp "$src" "$f"; else oiiotool "$src" -o "$f" >/dev/null 2>&1 || continue; fi
    seed_prefixed texture "$i" "$f"
  done
}

# Leaks inside Assimp and OpenImageIO are theirs (sanitize.sh's policy, the same file):
# Assimp 5.2's glTF 1 importer leaks on a catalog seed, and OpenImageIO 2.4's PNG read
# callback leaks its error string when libpng longjmps past it. Without this the first
# such seed stops the target before it fuzzes at all (docs/reliability.md, "Fuzzing").
export LSAN_OPTIONS=${LSAN_OPTIONS:-suppressions=$root/scripts/lsan.supp:print_suppressions=0}

status=0
for t in "${targets[@]}"; do
  "seed_$t"
  corpus="$work/corpus/$t"
  findings="$build/findings/$t"
  mkdir -p "$corpus" "$findings"
  seeds=("$work/seeds/$t")
  [[ -d "$root/tests/fuzz/regressions/$t" ]] && seeds+=("$root/tests/fuzz/regressions/$t")
  log="$work/$t.log"
  : >"$log"
  echo "fuzz_$t: ${seconds} s, seeds: $(find "${seeds[@]}" -type f | wc -l) files" >&2
  # -rss_limit_mb: a fixture may legally allocate up to the loader's limits (64M texels).
  # A mesh finding is replayed the way rastercheck reads the file, through the importer
  # child (RC_FUZZ_MESH_THROUGH_CHILD): when that accepts it or refuses it in one safe line,
  # the problem was inside Assimp and the child contains it (a crash, an abort, an
  # allocation over the child's limit); the input is kept in findings/mesh/contained/ (keep
  # it in tests/fuzz/regressions/mesh-contained/, which FuzzRegressions replays through the
  # child) and fuzzing goes on for the time left. Anything else is a finding.
  end=$((SECONDS + seconds))
  contained=0
  while :; do
    left=$((end - SECONDS))
    ((left > 0)) || break
    marker="$work/$t.marker"
    touch "$marker"
    if "$build/tests/fuzz/fuzz_$t" "$corpus" "${seeds[@]}" -max_total_time="$left" \
        -rss_limit_mb=3072 -timeout=30 -max_len=65536 -artifact_prefix="$findings/" \
        -print_final_stats=1 >>"$log" 2>&1; then
      break
    fi
    found=()
    while IFS= read -r f; do found+=("$f"); done < <(find "$findings" -maxdepth 1 -type f -newer "$marker")
    real=1
    if [[ $t == mesh && ${#found[@]} -gt 0 ]]; then
      real=0
      for f in "${found[@]}"; do
        if [[ -e "$findings/contained/$(basename "$f")" ]]; then
          # The same input again: a seed (tests/fuzz/regressions/mesh) that stops the
          # in-process target; restarting would loop on it. Its place is mesh-contained/.
          echo "fuzz_mesh: $(basename "$f") stopped the target twice; move it from the seeds to tests/fuzz/regressions/mesh-contained/" >&2
          real=1
        elif RC_FUZZ_MESH_THROUGH_CHILD=1 "$build/tests/fuzz/fuzz_mesh" "$f" >>"$log" 2>&1; then
          mkdir -p "$findings/contained"
          mv "$f" "$findings/contained/"
          contained=$((contained + 1))
          echo "fuzz_mesh: $(basename "$f") is inside Assimp and contained by the importer child (one-line refusal); fuzzing on" >&2
        else
          real=1
        fi
      done
    fi
    if ((real)); then
      status=1
      echo "fuzz_$t: FOUND A PROBLEM; input(s) in $findings; log $log" >&2
      grep -E 'ERROR|SUMMARY|abort|message is not' "$log" | tail -n 5 >&2 || true
      break
    fi
  done
  runs=$(grep -oE 'stat::number_of_executed_units: *[0-9]+' "$log" | grep -oE '[0-9]+$' |
    awk '{s += $1} END {print s + 0}')
  cov=$(grep -oE 'cov: [0-9]+' "$log" | tail -n 1 | grep -oE '[0-9]+' || echo 0)
  ft=$(grep -oE 'ft: [0-9]+' "$log" | tail -n 1 | grep -oE '[0-9]+' || echo 0)
  units=$(find "$corpus" -type f | wc -l)
  echo "fuzz_$t: $runs executions in ${seconds} s, coverage $cov edges ($ft features), corpus $units inputs, $contained contained inside Assimp"
done
exit $status
