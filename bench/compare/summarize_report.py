#!/usr/bin/env python3
"""Per-backend error distributions of a rastercheck report (docs/tolerances.md).

    bench/compare/summarize_report.py OUT/report.json

For every actual backend: the pairs and their verdicts, the depth and shading error
histograms summed over all pairs (the report's power-of-two bins), the largest max and
p99 over the pairs (with the fixture), ambiguous and hard visibility pixels, and how many
pixels needed a slope from a plane fit or had none.
"""
import json
import sys
from collections import defaultdict


def merge(total, hist):
    """Adds one report histogram into total {(lower, upper edge): count}. Every report
    uses the same power-of-two edges for a format, so bins line up."""
    edges = hist["edges"]
    for i, n in enumerate(hist["counts"]):
        total[(edges[i], edges[i + 1])] += n


def show(total, unit):
    return ", ".join(f"[{lo:g},{hi:g}): {n}" for (lo, hi), n in sorted(total.items()) if n)


def p99(total):
    """Upper edge of the bin holding the 99th percentile of all the pixels."""
    n = sum(total.values())
    seen = 0
    for (lo, hi), count in sorted(total.items()):
        seen += count
        if seen >= 0.99 * n:
            return hi
    return None


def main(path):
    report = json.load(open(path))
    by_backend = defaultdict(list)
    for row in report["results"]:
        by_backend[row["actual"]].append(row)
    for backend, rows in by_backend.items():
        status = defaultdict(int)
        depth_hist = defaultdict(lambda: defaultdict(int))  # by depth format
        shade_hist = defaultdict(lambda: defaultdict(int))  # by colour format
        worst = {}
        sums = defaultdict(int)
        for r in rows:
            status[r["status"]] += 1
            if r["status"] == "error":
                continue
            d, s, v = r["depth"], r["shading"], r["visibility"]
            merge(depth_hist[r["tolerances"]["depth_format"]], d["histogram"])
            t = r["tolerances"]
            textured = t.get("texture_weight_error", 0) > 0
            merge(shade_hist[t["color_format"] + (", linear textures" if textured else "")],
                  s["histogram"])
            for key, value in (("depth max_steps", d["max_steps"]), ("depth p99_steps", d["p99_steps"]),
                               ("shading max_abs", s["max_abs"]), ("shading p99_abs", s["p99_abs"])):
                if value is not None and value > worst.get(key, (-1, ""))[0]:
                    worst[key] = (value, r["fixture"])
            for key in ("ambiguous", "ambiguous_by_depth_gap", "hard", "mismatched"):
                sums["visibility " + key] += v[key]
            for key in ("compared", "over_tolerance", "slope_fitted", "slope_unknown"):
                sums["depth " + key] += d.get(key, 0)
            sums["shading over_tolerance"] += s["over_tolerance"]
        print(f"== {backend}: {len(rows)} pairs, " +
              ", ".join(f"{n} {k}" for k, n in sorted(status.items())))
        for key, (value, fixture) in sorted(worst.items()):
            print(f"  largest {key}: {value:.6g} ({fixture})")
        for key, n in sorted(sums.items()):
            print(f"  total {key}: {n}")
        for fmt, hist in sorted(depth_hist.items()):
            print(f"  depth |dZ| ({fmt} steps), compared pixels: {show(hist, 'steps')}; "
                  f"p99 below {p99(hist):g}")
        for fmt, hist in sorted(shade_hist.items()):
            print(f"  shading max |dC| ({fmt}, 8-bit units), compared pixels: {show(hist, 'units')}; "
                  f"p99 below {p99(hist):g}")


if __name__ == "__main__":
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    main(sys.argv[1])
