#!/usr/bin/env python3
"""Log-log charts of validation/scale.md from validation/scale_results.csv (written by hand
from bench_scale.sh output): wall time, peak memory and stored links against the patch count
for both exchange paths, and the hierarchical path's heat-rate error against wall time at
several tolerances. Pure standard library: writes SVG.

Run: python3 validation/scenes/plot_scale.py
"""
import csv
import math
import os

HERE = os.path.dirname(os.path.abspath(__file__))
VAL = os.path.join(HERE, "..")
COLOURS = ["#1f77b4", "#d62728", "#2ca02c", "#ff7f0e", "#9467bd", "#8c564b", "#17becf"]
W, H, M = 640, 420, 70


def decades(lo, hi):
    return range(math.floor(math.log10(lo)), math.ceil(math.log10(hi)) + 1)


def chart(path, title, xlabel, ylabel, series, guide=None):
    """series: [(label, [(x, y), ...])], log-log."""
    xs = [x for _, pts in series for x, _ in pts]
    ys = [y for _, pts in series for _, y in pts]
    dx, dy = list(decades(min(xs), max(xs))), list(decades(min(ys), max(ys)))
    x0, x1, y0, y1 = dx[0], max(dx[-1], dx[0] + 1), dy[0], max(dy[-1], dy[0] + 1)
    px = lambda x: M + (math.log10(x) - x0) / (x1 - x0) * (W - 2 * M)
    py = lambda y: H - M + -(math.log10(y) - y0) / (y1 - y0) * (H - 2 * M)
    out = [f'<svg xmlns="http://www.w3.org/2000/svg" width="{W}" height="{H}" font-family="sans-serif" font-size="12">',
           f'<rect width="{W}" height="{H}" fill="white"/>',
           f'<text x="{W / 2}" y="20" text-anchor="middle" font-size="14">{title}</text>',
           f'<text x="{W / 2}" y="{H - 15}" text-anchor="middle">{xlabel}</text>',
           f'<text x="15" y="{H / 2}" text-anchor="middle" transform="rotate(-90 15 {H / 2})">{ylabel}</text>']
    for d in range(x0, x1 + 1):
        out.append(f'<line x1="{px(10 ** d)}" y1="{M}" x2="{px(10 ** d)}" y2="{H - M}" stroke="#ddd"/>')
        out.append(f'<text x="{px(10 ** d)}" y="{H - M + 16}" text-anchor="middle">1e{d}</text>')
    for d in range(y0, y1 + 1):
        out.append(f'<line x1="{M}" y1="{py(10 ** d)}" x2="{W - M}" y2="{py(10 ** d)}" stroke="#ddd"/>')
        out.append(f'<text x="{M - 6}" y="{py(10 ** d) + 4}" text-anchor="end">1e{d}</text>')
    if guide:
        label, pts = guide
        d = " ".join(f"{px(x):.1f},{py(y):.1f}" for x, y in pts)
        out.append(f'<polyline points="{d}" fill="none" stroke="#999" stroke-dasharray="5,4"/>')
        out.append(f'<text x="{px(pts[-1][0]) - 4}" y="{py(pts[-1][1]) - 6}" text-anchor="end" fill="#777">{label}</text>')
    for k, (label, pts) in enumerate(series):
        c = COLOURS[k % len(COLOURS)]
        pts = sorted(pts)
        d = " ".join(f"{px(x):.1f},{py(y):.1f}" for x, y in pts)
        out.append(f'<polyline points="{d}" fill="none" stroke="{c}" stroke-width="2"/>')
        out += [f'<circle cx="{px(x):.1f}" cy="{py(y):.1f}" r="3.5" fill="{c}"/>' for x, y in pts]
        out.append(f'<text x="{M + 10}" y="{M + 16 * k + 4}" fill="{c}">{label}</text>')
    out.append("</svg>")
    with open(path, "w") as f:
        f.write("\n".join(out))


def main():
    rows = list(csv.DictReader(open(os.path.join(VAL, "scale_results.csv"))))
    scaling = [r for r in rows if r["study"] == "scaling"]
    groups = {}
    for r in scaling:
        groups.setdefault(f'{r["scene"]}, {r["path"]}' + (f' {r["tolerance"]}' if r["path"] == "hierarchical" else ""), []).append(r)
    for key, ylabel, name, title in [("wall_s", "wall time, s", "scale_time.svg", "solve wall time (2 cores)"),
                                      ("rss_mb", "peak RSS, MB", "scale_memory.svg", "solve peak memory"),
                                      ("stored", "stored links + patch pairs", "scale_links.svg", "exchange entries stored")]:
        series = [(g, [(float(r["patches"]), float(r[key])) for r in rs if r[key]]) for g, rs in groups.items()]
        series = [s for s in series if s[1]]
        guide = None
        if key == "stored":
            n = [1e3, 1e5]
            guide = ("N²/2", [(x, x * x / 2) for x in n])
        chart(os.path.join(VAL, name), title, "patches N", ylabel, series, guide)
    tradeoff = [r for r in rows if r["study"] == "tolerance"]
    series = {}
    for r in tradeoff:
        series.setdefault(r["scene"], []).append((float(r["wall_s"]), float(r["error"])))
    chart(os.path.join(VAL, "scale_error_time.svg"), "hierarchical: heat-rate error vs wall time",
          "wall time, s", "max |ΔQ| / max |Q| (vs dense)", list(series.items()))


if __name__ == "__main__":
    main()
