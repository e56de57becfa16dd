#!/usr/bin/env python3
"""Draws the slope matching of the mixed solver's line search as SVG.

In the manner of the thesis's Figure 8.1 ([Thesis8], eq. 8.8-8.14): benefit
against predicted cost. From the roots O the smooth variables follow the
benefit gradient (solid curve) until, at Q, the curve's slope has fallen to
slope_d, the slope of the discrete increment (dashed, O -> P); the increment
is taken next and gives R. The curve's tangent at Q (dotted) is parallel to
the increment.

Input: the CSV of tclod_mixed_figure (bench/mixed_figure.c), from the file
named as the first argument or from stdin. Output: SVG on stdout.

    ./build/bench/tclod_mixed_figure | python3 docs/figures/slope_matching.py \
        > docs/figures/slope_matching.svg

Standard library only.
"""

import csv
import math
import sys
from xml.sax.saxutils import escape

WIDTH, HEIGHT = 760, 500
# Plot area inside the canvas: room for tick labels and axis titles on the left
# and below, for the caption under the x axis title.
LEFT, RIGHT, TOP, BOTTOM = 78, 28, 28, 92
FONT = "DejaVu Sans, Helvetica, Arial, sans-serif"

CURVE_COLOUR = "#1f5fa8"
CURVE_LIGHT = "#9dbbe0"
INCREMENT_COLOUR = "#c8641e"
TANGENT_COLOUR = "#555555"
AXIS_COLOUR = "#222222"
GRID_COLOUR = "#e4e4e4"
# Later selections closer than this to R (pixels) are not drawn apart.
MIN_SEPARATION_PX = 8.0


def read_input(stream):
    """Returns (comments as a dict, rows by kind)."""
    comments = {}
    data_lines = []
    for line in stream:
        line = line.strip()
        if not line:
            continue
        if line.startswith("#"):
            body = line[1:].strip()
            if "=" in body and not body.startswith("scene:"):
                key, value = body.split("=", 1)
                comments[key.strip()] = value.strip()
            continue
        data_lines.append(line)
    rows = {"curve": [], "step": [], "tangent": []}
    for row in csv.DictReader(data_lines):
        kind = row["kind"]
        if kind in rows:
            rows[kind].append(row)
    return comments, rows


def number_pair(text):
    x, y = text.split(",")
    return float(x), float(y)


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
    return f"{value:.{decimals}f}"


class Plot:
    def __init__(self, x_max, y_max):
        self.x_step = nice_step(x_max, 7)
        self.y_step = nice_step(y_max, 7)
        self.x_max = math.ceil(x_max / self.x_step - 1e-9) * self.x_step
        self.y_max = math.ceil(y_max / self.y_step - 1e-9) * self.y_step
        self.w = WIDTH - LEFT - RIGHT
        self.h = HEIGHT - TOP - BOTTOM
        self.out = []

    def px(self, x, y):
        return (LEFT + x / self.x_max * self.w, TOP + self.h - y / self.y_max * self.h)

    def add(self, element):
        self.out.append(element)

    def polyline(self, points, **attrs):
        coords = " ".join(f"{a:.2f},{b:.2f}" for a, b in (self.px(x, y) for x, y in points))
        self.add(f'<polyline points="{coords}" fill="none"{attributes(attrs)}/>')

    def text(self, x, y, content, **attrs):
        self.add(f'<text x="{x:.2f}" y="{y:.2f}"{attributes(attrs)}>{escape(content)}</text>')

    def point(self, x, y, label, note, dx, dy, anchor, colour):
        """A marked point with its letter in bold and a short note after it."""
        px, py = self.px(x, y)
        self.add(f'<circle cx="{px:.2f}" cy="{py:.2f}" r="4.2" fill="{colour}" '
                 f'stroke="white" stroke-width="1.2"/>')
        self.add(f'<text x="{px + dx:.2f}" y="{py + dy:.2f}" text-anchor="{anchor}">'
                 f'<tspan font-size="15" font-weight="bold" fill="{colour}">{escape(label)}'
                 f'</tspan><tspan dx="5" font-size="12" fill="#444444">{escape(note)}</tspan>'
                 f'</text>')


def attributes(attrs):
    return "".join(f' {k.replace("_", "-")}="{v}"' for k, v in attrs.items())


def axes(p):
    x0, y0 = p.px(0.0, 0.0)
    x1, y1 = p.px(p.x_max, p.y_max)
    ticks = int(round(p.x_max / p.x_step))
    for i in range(ticks + 1):
        v = i * p.x_step
        x, _ = p.px(v, 0.0)
        if i > 0:
            p.add(f'<line x1="{x:.2f}" y1="{y1:.2f}" x2="{x:.2f}" y2="{y0:.2f}" '
                  f'stroke="{GRID_COLOUR}" stroke-width="1"/>')
        p.add(f'<line x1="{x:.2f}" y1="{y0:.2f}" x2="{x:.2f}" y2="{y0 + 5:.2f}" '
              f'stroke="{AXIS_COLOUR}" stroke-width="1"/>')
        p.text(x, y0 + 19, tick_label(v, p.x_step), font_size=12, text_anchor="middle",
               fill=AXIS_COLOUR)
    ticks = int(round(p.y_max / p.y_step))
    for i in range(ticks + 1):
        v = i * p.y_step
        _, y = p.px(0.0, v)
        if i > 0:
            p.add(f'<line x1="{x0:.2f}" y1="{y:.2f}" x2="{x1:.2f}" y2="{y:.2f}" '
                  f'stroke="{GRID_COLOUR}" stroke-width="1"/>')
        p.add(f'<line x1="{x0 - 5:.2f}" y1="{y:.2f}" x2="{x0:.2f}" y2="{y:.2f}" '
              f'stroke="{AXIS_COLOUR}" stroke-width="1"/>')
        p.text(x0 - 9, y + 4, tick_label(v, p.y_step), font_size=12, text_anchor="end",
               fill=AXIS_COLOUR)
    p.add(f'<polyline points="{x0:.2f},{y1:.2f} {x0:.2f},{y0:.2f} {x1:.2f},{y0:.2f}" '
          f'fill="none" stroke="{AXIS_COLOUR}" stroke-width="1.3"/>')
    p.text((x0 + x1) / 2, y0 + 42, "predicted cost (ms)", font_size=14, text_anchor="middle",
           fill=AXIS_COLOUR)
    yc = (y0 + y1) / 2
    p.text(22, yc, "benefit", font_size=14, text_anchor="middle", fill=AXIS_COLOUR,
           transform=f"rotate(-90 22 {yc:.2f})")


def legend(p, slope_d):
    x, y = LEFT + 18, TOP + 18
    items = [
        ("smooth step along the gradient (line search)", CURVE_COLOUR, "", 2.6),
        ("the same direction beyond Q, up to the budget", CURVE_LIGHT, "", 2.2),
        (f"discrete increment, slope_d = {slope_d:g}", INCREMENT_COLOUR, "7 5", 2.2),
        ("line of slope slope_d through Q", TANGENT_COLOUR, "1.5 4", 1.8),
    ]
    p.add(f'<rect x="{x - 10}" y="{y - 13}" width="330" height="{len(items) * 20 + 8}" '
          f'fill="white" fill-opacity="0.92" stroke="#cccccc" stroke-width="1"/>')
    for i, (label, colour, dash, width) in enumerate(items):
        yy = y + i * 20
        dash_attr = f' stroke-dasharray="{dash}"' if dash else ""
        cap = ' stroke-linecap="round"' if dash.startswith("1.5") else ""
        p.add(f'<line x1="{x}" y1="{yy - 4}" x2="{x + 34}" y2="{yy - 4}" stroke="{colour}" '
              f'stroke-width="{width}"{dash_attr}{cap}/>')
        p.text(x + 44, yy, label, font_size=12, fill=AXIS_COLOUR)


def main():
    if len(sys.argv) > 2:
        sys.exit("usage: slope_matching.py [tclod_mixed_figure.csv] > slope_matching.svg")
    if len(sys.argv) == 2:
        with open(sys.argv[1], newline="") as f:
            comments, rows = read_input(f)
    else:
        comments, rows = read_input(sys.stdin)

    curve = [(float(r["cost"]), float(r["benefit"])) for r in rows["curve"]]
    steps = [(float(r["cost"]), float(r["benefit"])) for r in rows["step"]]
    tangent = [(float(r["cost"]), float(r["benefit"])) for r in rows["tangent"]]
    if len(curve) < 2 or len(steps) < 2 or len(tangent) != 2:
        sys.exit("slope_matching.py: expected curve rows, at least two step rows and two "
                 "tangent rows")
    o = number_pair(comments["O"]) if "O" in comments else curve[0]
    q, r = steps[0], steps[1]
    # P: the increment taken at O instead of at Q
    p_point = number_pair(comments["P"]) if "P" in comments else (
        o[0] + r[0] - q[0], o[1] + r[1] - q[1])
    slope_d = float(comments["slope_d"]) if "slope_d" in comments else (
        (r[1] - q[1]) / (r[0] - q[0]))
    budget = float(comments["budget"]) if "budget" in comments else None

    everything = curve + steps + tangent + [p_point]
    x_max = max(x for x, _ in everything)
    if budget is not None:
        x_max = max(x_max, budget)
    y_max = max(y for _, y in everything)
    plot = Plot(x_max * 1.04, y_max * 1.04)

    axes(plot)

    if budget is not None:
        bx, by0 = plot.px(budget, 0.0)
        _, by1 = plot.px(budget, plot.y_max)
        plot.add(f'<line x1="{bx:.2f}" y1="{by1:.2f}" x2="{bx:.2f}" y2="{by0:.2f}" '
                 f'stroke="#999999" stroke-width="1.2" stroke-dasharray="4 3"/>')
        plot.text(bx - 5, by0 - 8, f"budget {budget:g} ms", font_size=12, text_anchor="end",
                  fill="#666666")

    # The curve up to Q (the step taken) strong, beyond it (looked at by the
    # line search, not taken) light.
    taken = [c for c in curve if c[0] <= q[0]] + [q]
    rest = [q] + [c for c in curve if c[0] > q[0]]
    plot.polyline(rest, stroke=CURVE_LIGHT, stroke_width=2.2)
    plot.polyline(tangent, stroke=TANGENT_COLOUR, stroke_width=1.8, stroke_dasharray="1.5 4",
                  stroke_linecap="round")
    plot.polyline(taken, stroke=CURVE_COLOUR, stroke_width=2.6)
    for a, b in ((o, p_point), (q, r)):
        plot.polyline([a, b], stroke=INCREMENT_COLOUR, stroke_width=2.2, stroke_dasharray="7 5")

    # Selections after R (the rest of the budget spent), where they stand apart
    rx, ry = plot.px(*r)
    for extra in steps[2:]:
        ex, ey = plot.px(*extra)
        if math.hypot(ex - rx, ey - ry) >= MIN_SEPARATION_PX:
            plot.polyline([r, extra], stroke=CURVE_COLOUR, stroke_width=1.6)
            plot.add(f'<circle cx="{ex:.2f}" cy="{ey:.2f}" r="3" fill="{CURVE_COLOUR}"/>')
            rx, ry, r = ex, ey, extra

    plot.point(*o, "O", "start", -10, 18, "end", AXIS_COLOUR)
    plot.point(*p_point, "P", "the increment at O", 10, 16, "start", INCREMENT_COLOUR)
    plot.point(*q, "Q", "end of the line search", -10, -10, "end", CURVE_COLOUR)
    plot.point(*steps[1], "R", "after the increment", -10, -10, "end", INCREMENT_COLOUR)

    legend(plot, slope_d)

    caption = (f"The line search stops at Q, where the slope has fallen to slope_d = "
               f"{slope_d:g} (eq. 8.14); the increment then gives R.")
    plot.text(WIDTH / 2, HEIGHT - 16, caption, font_size=12.5, text_anchor="middle",
              fill=AXIS_COLOUR, font_style="italic")

    out = sys.stdout
    out.write('<?xml version="1.0" encoding="UTF-8"?>\n')
    out.write(f'<svg xmlns="http://www.w3.org/2000/svg" width="{WIDTH}" height="{HEIGHT}" '
              f'viewBox="0 0 {WIDTH} {HEIGHT}" font-family="{FONT}">\n')
    out.write(f'<rect width="{WIDTH}" height="{HEIGHT}" fill="white"/>\n')
    for element in plot.out:
        out.write(element + "\n")
    out.write("</svg>\n")


if __name__ == "__main__":
    main()
