#!/usr/bin/env python3
"""Draws glfw_forest's frame times against their target, before and after, as SVG.

Two panels, one per run (the scale calibration, then the learned cost model, by
default), each with the target as a dashed line, the frame time as a thin line
and its running median over 31 frames as a bold one; the legend gives each
run's avg_err, p95_err and mean_ratio as glfw_forest's summary computes them.

Input: the CSVs that `glfw_forest --csv FILE` writes, each given as LABEL=FILE.
Output: SVG on stdout.

    xvfb-run -a -s "-screen 0 1280x720x24" ./build/examples/glfw_forest/glfw_forest \\
        --frames 600 --target-ms 100 --cost-model scale --csv scale.csv
    xvfb-run -a -s "-screen 0 1280x720x24" ./build/examples/glfw_forest/glfw_forest \\
        --frames 600 --target-ms 100 --csv features.csv
    python3 docs/figures/glfw_frame_time.py "scale=scale.csv" "learned=features.csv" \\
        > docs/figures/glfw_frame_time.svg

Standard library only.
"""

import csv
import math
import sys
from xml.sax.saxutils import escape

WIDTH = 900
LEFT, RIGHT = 70, 24
PANEL_HEIGHT = 230
GAP = 70
TOP = 40
FONT = "DejaVu Sans, Helvetica, Arial, sans-serif"
FRAME_COLOUR = "#1f5fa8"
MEDIAN_COLOUR = "#c8641e"
TARGET_COLOUR = "#222222"


def read(path):
    with open(path, newline="") as f:
        rows = list(csv.DictReader(f))
    return [(float(r["frame_ms"]), float(r["target_ms"])) for r in rows]


def figures(rows):
    errs = sorted(abs(t - T) / T for t, T in rows)
    n = len(rows)
    p95 = errs[max(1, math.ceil(0.95 * n)) - 1]
    return (sum(errs) / n, p95, sum(t / T for t, T in rows) / n)


def running_median(values, half=15):
    out = []
    for i in range(len(values)):
        w = sorted(values[max(0, i - half):i + half + 1])
        out.append(w[len(w) // 2])
    return out


def polyline(points, colour, width, dash=None):
    d = f' stroke-dasharray="{dash}"' if dash else ""
    pts = " ".join(f"{x:.1f},{y:.1f}" for x, y in points)
    return (f'<polyline fill="none" stroke="{colour}" stroke-width="{width}"{d} '
            f'points="{pts}"/>')


def main(argv):
    runs = []
    for arg in argv:
        label, _, path = arg.partition("=")
        runs.append((label, read(path)))
    if not runs:
        sys.exit("usage: glfw_frame_time.py LABEL=FILE.csv [LABEL=FILE.csv ...] > out.svg")
    height = TOP + len(runs) * (PANEL_HEIGHT + GAP)
    top_ms = max(2.0 * max(T for _, T in rows) for _, rows in runs)
    plot_w = WIDTH - LEFT - RIGHT
    out = [f'<?xml version="1.0" encoding="UTF-8"?>',
           f'<svg xmlns="http://www.w3.org/2000/svg" width="{WIDTH}" height="{height}" '
           f'font-family="{FONT}" font-size="12">',
           f'<rect width="{WIDTH}" height="{height}" fill="white"/>',
           f'<text x="{LEFT}" y="22" font-size="14">glfw_forest under Xvfb and llvmpipe: '
           f'frame time against its target</text>']
    for k, (label, rows) in enumerate(runs):
        y0 = TOP + k * (PANEL_HEIGHT + GAP)
        n = len(rows)

        def px(i):
            return LEFT + plot_w * i / max(1, n - 1)

        def py(ms):
            return y0 + PANEL_HEIGHT * (1.0 - min(ms, top_ms) / top_ms)

        avg, p95, ratio = figures(rows)
        out.append(f'<rect x="{LEFT}" y="{y0}" width="{plot_w}" height="{PANEL_HEIGHT}" '
                   f'fill="none" stroke="#999"/>')
        for ms in (0.0, top_ms / 4, top_ms / 2, 3 * top_ms / 4, top_ms):
            out.append(f'<text x="{LEFT - 6}" y="{py(ms) + 4:.1f}" text-anchor="end">'
                       f'{ms:g}</text>')
        for i in range(0, n, 100):
            out.append(f'<text x="{px(i):.1f}" y="{y0 + PANEL_HEIGHT + 16}" '
                       f'text-anchor="middle">{i}</text>')
        out.append(f'<text x="{LEFT - 52}" y="{y0 + PANEL_HEIGHT / 2}" '
                   f'transform="rotate(-90 {LEFT - 52} {y0 + PANEL_HEIGHT / 2})" '
                   f'text-anchor="middle">ms</text>')
        out.append(polyline([(px(i), py(T)) for i, (_, T) in enumerate(rows)], TARGET_COLOUR,
                            1.2, "6,4"))
        out.append(polyline([(px(i), py(t)) for i, (t, _) in enumerate(rows)], FRAME_COLOUR,
                            0.8))
        med = running_median([t for t, _ in rows])
        out.append(polyline([(px(i), py(m)) for i, m in enumerate(med)], MEDIAN_COLOUR, 2.2))
        out.append(f'<text x="{LEFT + 8}" y="{y0 + 16}">{escape(label)}: avg_err {avg:.4f}, '
                   f'p95_err {p95:.4f}, mean_ratio {ratio:.4f} ({n} frames; thin: frame time, '
                   f'bold: its running median, dashed: the target)</text>')
    out.append("</svg>")
    print("\n".join(out))


if __name__ == "__main__":
    main(sys.argv[1:])
