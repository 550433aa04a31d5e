#!/usr/bin/env bash
# Runs every benchmark program of one build in one go, each with JSON output, and prints
# Markdown tables: the reference against llvmpipe and softpipe on the same scenes as
# ratios, the GL stages and the harness overhead at 1920x1080, the frame files, and the
# comparator. GL drivers are chosen once per process, so bench_gl runs once per driver.
#
#   bench/run.sh [BUILD_DIR]        (default build/release; build it with the release preset)
#
# Environment: RC_BENCH_OUT (JSON folder, default BUILD_DIR/bench-results),
# RC_BENCH_REPETITIONS (default 3; the tables show medians), RC_BENCH_MIN_TIME (seconds
# per repetition, default 0.5), RC_BENCH_SPECS (default "gl:egl:llvmpipe gl:egl:softpipe").
# Timing on a shared machine is noisy: compare ratios from one run, not across runs.
set -euo pipefail

build=${1:-build/release}
out=${RC_BENCH_OUT:-$build/bench-results}
reps=${RC_BENCH_REPETITIONS:-3}
min_time=${RC_BENCH_MIN_TIME:-0.5}
specs=${RC_BENCH_SPECS:-gl:egl:llvmpipe gl:egl:softpipe}
mkdir -p "$out"

common=(--benchmark_repetitions="$reps" --benchmark_report_aggregates_only=true
        --benchmark_min_time="$min_time" --benchmark_out_format=json)

run() {  # run NAME PROGRAM [ARGS...]: PROGRAM's JSON goes to $out/NAME.json
  local name=$1 program=$2
  shift 2
  if [[ ! -x $program ]]; then
    echo "bench/run.sh: $program not built, skipped" >&2
    return
  fi
  echo "bench/run.sh: $name" >&2
  "$program" "$@" "${common[@]}" --benchmark_out="$out/$name.json" >/dev/null
}

run reference "$build/bench/reference/bench_reference"
gl_files=()
for spec in $specs; do
  name=gl_${spec//:/_}
  run "$name" "$build/bench/gl/bench_gl" --gl_spec="$spec"
  gl_files+=("$out/$name.json")
done
run frame_io "$build/bench/gl/bench_frame_io" \
  --benchmark_filter='WriteFrameDir|ReadFrameDir|Floor|ExrWrite/compression:0/|ExrRead/compression:0/|PngWrite/level:1/filter:8'
run compare "$build/bench/compare/bench_compare"

python3 - "$out" "${gl_files[@]}" <<'EOF'
import json, os, re, sys

out, gl_files = sys.argv[1], sys.argv[2:]

def load(path):
    if not os.path.exists(path):
        return None
    with open(path) as f:
        return json.load(f)

def medians(doc):
    """name (without /real_time, /min_time:, /repeats:) -> the median entry."""
    rows = {}
    for b in (doc or {}).get("benchmarks", []):
        if b.get("aggregate_name", "median") != "median":
            continue
        name = re.sub(r"/(real_time|min_time:[^/]*|repeats:[^/]*)", "", b["run_name"])
        name = name.replace("_median", "")
        rows[name] = b
    return rows

def ms(entry):
    scale = {"ns": 1e-6, "us": 1e-3, "ms": 1.0, "s": 1e3}[entry.get("time_unit", "ns")]
    return entry["real_time"] * scale

def fmt(v, digits=1):
    return "—" if v is None else f"{v:.{digits}f}"

ref = medians(load(os.path.join(out, "reference.json")))
gls = []
for path in gl_files:
    doc = load(path)
    if doc is None:
        continue
    spec = doc["context"].get("gl_spec", os.path.basename(path))
    gls.append((spec.split(":")[-1], doc["context"], medians(doc)))

print("## Reference against GL on the same scenes (1024x1024, wall ms per frame)\n")
print("Ratio = reference time / GL time (above 1: the GL driver is faster).\n")
head = ["scene", "ref", "ref + uncertainty"] + [d for d, _, _ in gls]
for d, _, _ in gls:
    head += [f"ref / {d}", f"ref+unc / {d}"]
print("| " + " | ".join(head) + " |")
print("|" + "---|" * len(head))
scenes = ["BM_SmallTriangles", "BM_SmallTriangleMesh", "BM_Layers/shading:0", "BM_Layers/shading:1",
          "BM_Layers/shading:2", "BM_Lines", "BM_ShadowMap"]
labels = {"BM_SmallTriangles": "100k 2-px triangles, flat", "BM_SmallTriangleMesh": "the same as one mesh",
          "BM_Layers/shading:0": "8 layers, flat",
          "BM_Layers/shading:1": "8 layers, gouraud", "BM_Layers/shading:2": "8 layers, phong",
          "BM_Lines": "20k segments and 20k points, gouraud",
          "BM_ShadowMap": "teapot on a floor through a 1024^2 shadow map (2 passes), phong"}
for scene in scenes:
    r0 = ref.get(scene + "/uncertainty:0")
    r1 = ref.get(scene + "/uncertainty:1")
    t0 = ms(r0) if r0 else None
    t1 = ms(r1) if r1 else None
    row = [labels[scene], fmt(t0), fmt(t1)]
    ratios = []
    for _, _, rows in gls:
        g = rows.get(scene)
        tg = ms(g) if g else None
        row.append(fmt(tg))
        ratios += [fmt(t0 / tg if t0 and tg else None, 2), fmt(t1 / tg if t1 and tg else None, 2)]
    print("| " + " | ".join(row + ratios) + " |")

print("\n## GL stages and harness overhead at 1920x1080 (ms, medians)\n")
print("First context: the process's first (driver loading). First render: the process's "
      "first 1080p frame (context, compile, FBO allocation, readback into untouched memory), "
      "what each `rastercheck render` child pays. The rest: steady state, wall ms, with the "
      "calling thread's CPU ms (load-independent) in parentheses. Overhead = upload + "
      "readback (with conversion) + writing frame.exr, color.png and frame.json.\n")
cols = ["driver", "first context", "context (again)", "first render: compile / framebuffer / readback cpu",
        "upload", "draw", "readback", "write frame", "harness overhead", "draw (rgba8)"]
print("| " + " | ".join(cols) + " |")
print("|" + "---|" * len(cols))
for driver, context, rows in gls:
    def counter(name, key, digits=1):
        e = rows.get(name)
        return fmt(e.get(key) if e else None, digits)
    def both(name, key, digits=1):
        return f"{counter(name, key + '_ms', digits)} ({counter(name, key + '_cpu_ms', digits)})"
    again = rows.get("BM_ContextCreate")
    first = "BM_FirstRender1080p/iterations:1"
    h = "BM_HarnessOverhead1080p"
    print("| " + " | ".join([
        driver, fmt(float(context.get("first_context_ms", "nan"))),
        fmt(ms(again) if again else None),
        " / ".join([counter(first, "compile_ms"), counter(first, "framebuffer_cpu_ms"),
                    counter(first, "readback_cpu_ms")]),
        both(h, "upload", 2), counter(h, "draw_ms"), both(h, "readback"),
        both(h, "write_frame"), both(h, "harness_overhead"),
        counter("BM_Stages1080p/rgba8:1", "draw_ms")]) + " |")

fio = medians(load(os.path.join(out, "frame_io.json")))
if fio:
    print("\n## Frame files at 1920x1080 (wall ms, medians; 6 channels = GL frame, 8 = reference)\n")
    print("| benchmark | 6 channels | 8 channels |")
    print("|---|---|---|")
    for name, label in [("BM_WriteFrameDir", "writeFrameDir into a new DIR (exr + png + json)"),
                        ("BM_WriteFrameDir+replace", "writeFrameDir replacing a DIR (old frame deleted)"),
                        ("BM_ReadFrameDir", "readFrameDir"),
                        ("BM_ExrWrite/compression:0", "frame.exr write (none)"),
                        ("BM_ExrRead/compression:0", "frame.exr read (none)"),
                        ("BM_FloorMemcpy", "floor: memcpy of the same bytes"),
                        ("BM_FloorWriteFile", "floor: one write() of the same bytes")]:
        def get(ch):
            base, _, variant = name.partition("+")
            if base == "BM_WriteFrameDir":
                key = f"{base}/channels:{ch}/replace:{1 if variant else 0}"
            else:
                key = f"{name}/channels:{ch}"
            e = fio.get(key)
            return fmt(ms(e)) if e else "—"
        print(f"| {label} | {get(6)} | {get(8)} |")
    png = fio.get("BM_PngWrite/level:1/filter:8")
    if png:
        print(f"| color.png write (level 1, no filter) | {fmt(ms(png))} | |")

cmp = medians(load(os.path.join(out, "compare.json")))
if cmp:
    print("\n## Comparator (1920x1080 pair, wall ms, medians)\n")
    print("| benchmark | ms |")
    print("|---|---|")
    for name, e in cmp.items():
        print(f"| {name} | {fmt(ms(e))} |")
EOF
