#!/usr/bin/env python3
"""Draws frame time against the target over a simulated flight, as SVG.

In the manner of [RH]'s Figure 3 (time-critical test, linear path): the
target frame time as a dashed line, the frame time the calibrated budget gave
as a thin solid line, and the unconstrained frame time (every visible object
at its finest) as a bold light line. Below it, the frame time's deviation from
the target in per cent, and the hidden render-time factor of the simulated
machine beside the calibration's estimate of it (tclod_calib_scale). Frames
whose unconstrained frame time is below the target are shaded: there the
scene, not the calibration, decides the frame time.

Input: the CSV that `flyover_sim --simulate-gpu --csv FILE` writes, from the
file named as the argument or from stdin. Output: SVG on stdout, or with
--stats the frame-time figures of the summary line, over all frames and over
the frames whose unconstrained time reaches the target.

    ./build/examples/flyover_sim --solver greedy --simulate-gpu --target-ms 25 \
        --frames 2400 --csv frame_time.csv
    python3 docs/figures/frame_time.py frame_time.csv > docs/figures/frame_time.svg

Standard library only.
"""

import csv
import math
import sys
from xml.sax.saxutils import escape

WIDTH = 900
LEFT, RIGHT = 78, 24
FONT = "DejaVu Sans, Helvetica, Arial, sans-serif"
# Three panels stacked: (top, height) of each plot area.
PANELS = ((40, 300), (392, 150), (594, 150))
HEIGHT = 830

FRAME_COLOUR = "#1f5fa8"
UNCONSTRAINED_COLOUR = "#f0b27a"
TARGET_COLOUR = "#222222"
FACTOR_COLOUR = "#c8641e"
SCALE_COLOUR = "#1f5fa8"
SHADE_COLOUR = "#eeeeee"
AXIS_COLOUR = "#222222"
GRID_COLOUR = "#e4e4e4"
# The deviation panel shows at most this many per cent either way; frames
# beyond it are clipped (the scene cannot reach the target there, or the
# calibration has not settled yet).
DEVIATION_LIMIT = 12.0


def read_rows(stream):
    rows = list(csv.DictReader(stream))
    needed = ("frame", "frame_ms", "target_ms", "scale", "unconstrained_ms", "factor")
    if not rows or any(k not in rows[0] for k in needed):
        sys.exit("frame_time.py: expected the CSV of flyover_sim --simulate-gpu (columns "
                 + ", ".join(needed) + ")")
    return rows


def nice_step(span, target_ticks):
    """A tick step of 1, 2, 2.5 or 5 times a power of ten giving about
    target_ticks intervals over span."""
    raw = span / target_ticks
    power = 10.0 ** math.floor(math.log10(raw))
    for m in (1.0, 2.0, 2.5, 5.0, 10.0):
        if m * power >= raw:
            return m * power
    return 10.0 * power


def tick_label(value, step):
    decimals = max(0, -int(math.floor(math.log10(step) + 1e-9)))
    if abs(step * 10 ** decimals - round(step * 10 ** decimals)) > 1e-9:
        decimals += 1
    text = f"{value:.{decimals}f}"
    return "0" if text.strip("-0.") == "" else text


def attributes(attrs):
    return "".join(f' {k.replace("_", "-")}="{v}"' for k, v in attrs.items())


class Panel:
    """One plot area: x the frame, y from y_min to y_max (rounded out to ticks)."""

    def __init__(self, out, index, x_max, y_min, y_max, y_ticks):
        self.out = out
        self.index = index
        self.top, self.h = PANELS[index]
        self.w = WIDTH - LEFT - RIGHT
        self.x_step = nice_step(x_max, 8)
        self.x_max = math.ceil(x_max / self.x_step - 1e-9) * self.x_step
        self.y_step = nice_step(y_max - y_min, y_ticks)
        self.y_min = math.floor(y_min / self.y_step + 1e-9) * self.y_step
        self.y_max = math.ceil(y_max / self.y_step - 1e-9) * self.y_step
        out.append(f'<clipPath id="panel{index}"><rect x="{LEFT}" y="{self.top}" '
                   f'width="{self.w}" height="{self.h}"/></clipPath>')

    def px(self, x, y):
        return (LEFT + x / self.x_max * self.w,
                self.top + self.h - (y - self.y_min) / (self.y_max - self.y_min) * self.h)

    def text(self, x, y, content, **attrs):
        self.out.append(f'<text x="{x:.2f}" y="{y:.2f}"{attributes(attrs)}>{escape(content)}'
                        f'</text>')

    def polyline(self, points, **attrs):
        coords = " ".join(f"{a:.1f},{b:.1f}" for a, b in (self.px(x, y) for x, y in points))
        self.out.append(f'<polyline points="{coords}" fill="none" '
                        f'clip-path="url(#panel{self.index})"{attributes(attrs)}/>')

    def shade(self, spans):
        for a, b in spans:
            x0, _ = self.px(a, 0.0)
            x1, _ = self.px(b, 0.0)
            self.out.append(f'<rect x="{x0:.2f}" y="{self.top}" width="{x1 - x0:.2f}" '
                            f'height="{self.h}" fill="{SHADE_COLOUR}"/>')

    def axes(self, y_title, x_title=None):
        x0, y0 = self.px(0.0, self.y_min)
        x1, y1 = self.px(self.x_max, self.y_max)
        for i in range(int(round(self.x_max / self.x_step)) + 1):
            v = i * self.x_step
            x, _ = self.px(v, self.y_min)
            if i > 0:
                self.out.append(f'<line x1="{x:.2f}" y1="{y1:.2f}" x2="{x:.2f}" y2="{y0:.2f}" '
                                f'stroke="{GRID_COLOUR}" stroke-width="1"/>')
            self.out.append(f'<line x1="{x:.2f}" y1="{y0:.2f}" x2="{x:.2f}" y2="{y0 + 5:.2f}" '
                            f'stroke="{AXIS_COLOUR}" stroke-width="1"/>')
            self.text(x, y0 + 18, tick_label(v, self.x_step), font_size=12,
                      text_anchor="middle", fill=AXIS_COLOUR)
        ticks = int(round((self.y_max - self.y_min) / self.y_step))
        for i in range(ticks + 1):
            v = self.y_min + i * self.y_step
            _, y = self.px(0.0, v)
            if i > 0:
                self.out.append(f'<line x1="{x0:.2f}" y1="{y:.2f}" x2="{x1:.2f}" y2="{y:.2f}" '
                                f'stroke="{GRID_COLOUR}" stroke-width="1"/>')
            self.out.append(f'<line x1="{x0 - 5:.2f}" y1="{y:.2f}" x2="{x0:.2f}" y2="{y:.2f}" '
                            f'stroke="{AXIS_COLOUR}" stroke-width="1"/>')
            self.text(x0 - 9, y + 4, tick_label(v, self.y_step), font_size=12,
                      text_anchor="end", fill=AXIS_COLOUR)
        self.out.append(f'<rect x="{x0:.2f}" y="{y1:.2f}" width="{x1 - x0:.2f}" '
                        f'height="{y0 - y1:.2f}" fill="none" stroke="{AXIS_COLOUR}" '
                        f'stroke-width="1.2"/>')
        yc = (y0 + y1) / 2
        self.text(24, yc, y_title, font_size=13, text_anchor="middle", fill=AXIS_COLOUR,
                  transform=f"rotate(-90 24 {yc:.2f})")
        if x_title:
            self.text((x0 + x1) / 2, y0 + 38, x_title, font_size=13, text_anchor="middle",
                      fill=AXIS_COLOUR)

    def legend(self, items, width, right=False):
        x = LEFT + self.w - width - 6 if right else LEFT + 14
        y = self.top + 18
        self.out.append(f'<rect x="{x - 8}" y="{y - 13}" width="{width}" '
                        f'height="{len(items) * 18 + 6}" fill="white" fill-opacity="0.92" '
                        f'stroke="#cccccc" stroke-width="1"/>')
        for i, (label, colour, dash, stroke_width) in enumerate(items):
            yy = y + i * 18
            if colour == SHADE_COLOUR:
                self.out.append(f'<rect x="{x}" y="{yy - 10}" width="30" height="12" '
                                f'fill="{SHADE_COLOUR}" stroke="#cccccc" stroke-width="0.8"/>')
            else:
                dash_attr = f' stroke-dasharray="{dash}"' if dash else ""
                self.out.append(f'<line x1="{x}" y1="{yy - 4}" x2="{x + 30}" y2="{yy - 4}" '
                                f'stroke="{colour}" stroke-width="{stroke_width}"{dash_attr}/>')
            self.text(x + 40, yy, label, font_size=12, fill=AXIS_COLOUR)


def unreachable_spans(frames, unconstrained, target):
    """Runs of frames whose unconstrained frame time is below the target."""
    spans, start = [], None
    for f, u in zip(frames, unconstrained):
        if u < target and start is None:
            start = f - 0.5
        elif u >= target and start is not None:
            spans.append((start, f - 0.5))
            start = None
    if start is not None:
        spans.append((start, frames[-1] + 0.5))
    return spans


def figures(frame_ms, target):
    """mean, population stddev, avg_err and nearest-rank p99 overshoot, as the
    summary line of flyover_sim computes them."""
    n = len(frame_ms)
    if n == 0:
        return None
    mean = sum(frame_ms) / n
    var = max(0.0, sum(t * t for t in frame_ms) / n - mean * mean)
    avg_err = sum(abs(t / target - 1.0) for t in frame_ms) / n
    over = sorted(max(0.0, t / target - 1.0) for t in frame_ms)
    p99 = over[min(n, max(1, math.ceil(0.99 * n))) - 1]
    return mean, math.sqrt(var), avg_err, p99


def print_stats(rows):
    target = float(rows[0]["target_ms"])
    frame_ms = [float(r["frame_ms"]) for r in rows]
    reach = [float(r["frame_ms"]) for r in rows if float(r["unconstrained_ms"]) >= target]
    for name, values in (("all", frame_ms), ("reachable", reach)):
        f = figures(values, target)
        if f is None:
            print(f"{name}: frames=0 target_ms={target:.3f}")
        else:
            print(f"{name}: frames={len(values)} target_ms={target:.3f} mean_ms={f[0]:.4f} "
                  f"stddev_ms={f[1]:.4f} avg_err={f[2]:.5f} p99_overshoot={f[3]:.5f}")


def draw(rows):
    frames = [float(r["frame"]) for r in rows]
    frame_ms = [float(r["frame_ms"]) for r in rows]
    unconstrained = [float(r["unconstrained_ms"]) for r in rows]
    scale = [float(r["scale"]) for r in rows]
    factor = [float(r["factor"]) for r in rows]
    target = float(rows[0]["target_ms"])
    x_max = frames[-1] + 1.0
    spans = unreachable_spans(frames, unconstrained, target)
    out = []

    # 1: frame time, target and unconstrained frame time
    # The unconstrained line may be far above the target: the plot shows up to 3 T.
    clipped = max(unconstrained) > 3.0 * target
    top = Panel(out, 0, x_max, 0.0,
                max(min(max(unconstrained), 3.0 * target), max(frame_ms), target) * 1.05, 6)
    top.shade(spans)
    top.axes("frame time (ms)")
    top.polyline(list(zip(frames, unconstrained)), stroke=UNCONSTRAINED_COLOUR, stroke_width=2.4)
    top.polyline([(0.0, target), (x_max, target)], stroke=TARGET_COLOUR, stroke_width=1.4,
                 stroke_dasharray="7 5")
    top.polyline(list(zip(frames, frame_ms)), stroke=FRAME_COLOUR, stroke_width=1.0)
    top.legend([
        ("unconstrained: every visible object at its finest"
         + (" (cut at 3× the target)" if clipped else ""), UNCONSTRAINED_COLOUR, "", 2.4),
        (f"target {target:g} ms", TARGET_COLOUR, "7 5", 1.4),
        ("frame time with the calibrated budget", FRAME_COLOUR, "", 1.4),
        ("the finest selection is below the target", SHADE_COLOUR, "", 0),
    ], 470 if clipped else 360, right=True)

    # 2: deviation from the target, per cent
    deviation = [(t / target - 1.0) * 100.0 for t in frame_ms]
    lo = max(-DEVIATION_LIMIT, min(deviation))
    hi = min(DEVIATION_LIMIT, max(deviation))
    lim = max(abs(lo), abs(hi), 1.0)
    mid = Panel(out, 1, x_max, -lim, lim, 4)
    mid.shade(spans)
    mid.axes("frame / target - 1 (%)")
    mid.polyline([(0.0, 0.0), (x_max, 0.0)], stroke=TARGET_COLOUR, stroke_width=1.2,
                 stroke_dasharray="7 5")
    mid.polyline(list(zip(frames, deviation)), stroke=FRAME_COLOUR, stroke_width=0.9)

    # 3: hidden factor and its estimate
    lo = min(min(factor), min(scale))
    hi = max(max(factor), max(scale))
    # headroom above the curves for the legend
    bottom = Panel(out, 2, x_max, lo - 0.05 * (hi - lo), hi + 0.5 * (hi - lo), 4)
    bottom.axes("ms per cost unit", "frame")
    bottom.polyline(list(zip(frames, factor)), stroke=FACTOR_COLOUR, stroke_width=1.6)
    bottom.polyline(list(zip(frames, scale)), stroke=SCALE_COLOUR, stroke_width=1.0)
    bottom.legend([
        ("hidden factor: true render time / predicted cost", FACTOR_COLOUR, "", 1.6),
        ("calibration's scale (tclod_calib_scale)", SCALE_COLOUR, "", 1.4),
    ], 340)

    f = figures(frame_ms, target)
    caption = (f"{len(frames)} frames: mean {f[0]:.2f} ms, stddev {f[1]:.2f} ms, "
               f"avg_err {f[2]:.4f}, p99 overshoot {f[3] * 100.0:.2f} %")
    title = "Frame time against its target, simulated GPU (flyover_sim --simulate-gpu)"
    text = [f'<text x="{WIDTH / 2:.1f}" y="24" text-anchor="middle" font-size="15" '
            f'fill="{AXIS_COLOUR}">{escape(title)}</text>',
            f'<text x="{WIDTH / 2:.1f}" y="{HEIGHT - 14}" text-anchor="middle" font-size="12.5" '
            f'font-style="italic" fill="{AXIS_COLOUR}">{escape(caption)}</text>']

    w = sys.stdout
    w.write('<?xml version="1.0" encoding="UTF-8"?>\n')
    w.write(f'<svg xmlns="http://www.w3.org/2000/svg" width="{WIDTH}" height="{HEIGHT}" '
            f'viewBox="0 0 {WIDTH} {HEIGHT}" font-family="{FONT}">\n')
    w.write(f'<rect width="{WIDTH}" height="{HEIGHT}" fill="white"/>\n')
    for element in out + text:
        w.write(element + "\n")
    w.write("</svg>\n")


def main():
    args = sys.argv[1:]
    stats = "--stats" in args
    args = [a for a in args if a != "--stats"]
    if len(args) > 1:
        sys.exit("usage: frame_time.py [--stats] [flyover_sim.csv] > frame_time.svg")
    if args:
        with open(args[0], newline="") as f:
            rows = read_rows(f)
    else:
        rows = read_rows(sys.stdin)
    if stats:
        print_stats(rows)
    else:
        draw(rows)


if __name__ == "__main__":
    main()
