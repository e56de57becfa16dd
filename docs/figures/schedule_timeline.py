#!/usr/bin/env python3
"""Draws the predictive geomorph scheduler's timeline as SVG.

In the manner of [GEO]'s Figures 5 and 6: time runs left to right, cut into
intervals of tau. The top band shows the pipeline: the selection that runs
during interval I_j (in slices, while the frames draw) is for I_{j+2}. Below,
the level positions of three objects of the flyover world as the scheduler
drew them, frame by frame: level k, or k - 1 + w while level k morphs from
level k - 1 with weight w. Down-morphs end when the interval they were chosen
for begins; up-morphs run through that interval and end with it; a jump of
several levels is as many adjacent morphs in turn.

Input: the CSV of tclod_schedule_figure (bench/schedule_figure.c), from the
file named as the first argument or from stdin. Output: SVG on stdout.

    ./build/bench/tclod_schedule_figure | python3 docs/figures/schedule_timeline.py \
        > docs/figures/schedule_timeline.svg

Standard library only.
"""

import csv
import math
import sys
from xml.sax.saxutils import escape

WIDTH, HEIGHT = 900, 600
LEFT, RIGHT = 70, 24
BAND_TOP, BAND_ROW, BAND_ROWS = 40, 22, 3
PLOT_TOP, PLOT_BOTTOM = 150, 470
FONT = "DejaVu Sans, Helvetica, Arial, sans-serif"
COLOURS = ["#1f77b4", "#d62728", "#2ca02c"]


def read(stream):
    boundaries, series, notes = [], {}, []
    rows = []
    for line in stream:
        if line.startswith("#"):
            notes.append(line[1:].strip())
        else:
            rows.append(line)
    for row in csv.DictReader(rows):
        t = float(row["time_s"])
        if row["kind"] == "boundary":
            boundaries.append(t)
        elif row["kind"] == "level":
            pos = float(row["position"]) if row["position"] else None
            series.setdefault(row["object"], []).append((t, pos))
    return boundaries, series, notes


def main():
    stream = open(sys.argv[1]) if len(sys.argv) > 1 else sys.stdin
    boundaries, series, notes = read(stream)
    t_end = max(t for pts in series.values() for t, _ in pts)
    tau = boundaries[1] - boundaries[0]
    t_end = math.ceil(t_end / tau) * tau
    top_level = max(p for pts in series.values() for _, p in pts if p is not None)
    top_level = max(1.0, math.ceil(top_level))

    def x(t):
        return LEFT + (WIDTH - LEFT - RIGHT) * t / t_end

    def y(level):
        return PLOT_BOTTOM - (PLOT_BOTTOM - PLOT_TOP) * level / top_level

    out = []
    add = out.append
    add('<svg xmlns="http://www.w3.org/2000/svg" width="%d" height="%d" '
        'viewBox="0 0 %d %d" font-family="%s" font-size="12">' % (WIDTH, HEIGHT, WIDTH, HEIGHT,
                                                                   FONT))
    add('<rect width="100%" height="100%" fill="white"/>')
    add('<text x="%d" y="20" font-size="14">Predictive geomorph scheduler: '
        'flyover world, tau = %.1f s, 60 frames per second</text>' % (LEFT, tau))

    # pipeline band: the selection running during I_j is for I_{j+2}
    add('<text x="%d" y="%d" text-anchor="end">selection</text>' %
        (LEFT - 8, BAND_TOP + BAND_ROW * 1.6))
    for j, b in enumerate(boundaries):
        if b + tau > t_end + 1e-9:
            break
        row = j % BAND_ROWS
        y0 = BAND_TOP + row * BAND_ROW
        add('<rect x="%.1f" y="%d" width="%.1f" height="%d" fill="#e8eef7" stroke="#7a8fb0"/>' %
            (x(b) + 1, y0, x(b + tau) - x(b) - 2, BAND_ROW - 4))
        add('<text x="%.1f" y="%d" text-anchor="middle" font-size="10">for I%d</text>' %
            ((x(b) + x(b + tau)) / 2, y0 + BAND_ROW - 9, j + 2))

    # interval boundaries and their names
    for j, b in enumerate(boundaries):
        if b > t_end + 1e-9:
            break
        add('<line x1="%.1f" y1="%d" x2="%.1f" y2="%d" stroke="#bbbbbb" '
            'stroke-dasharray="3,3"/>' % (x(b), BAND_TOP, x(b), PLOT_BOTTOM))
        if b + tau <= t_end + 1e-9:
            add('<text x="%.1f" y="%d" text-anchor="middle" font-size="10" fill="#666666">'
                'I%d</text>' % ((x(b) + x(b + tau)) / 2, PLOT_TOP - 8, j))

    # axes
    add('<line x1="%d" y1="%d" x2="%d" y2="%d" stroke="black"/>' %
        (LEFT, PLOT_BOTTOM, WIDTH - RIGHT, PLOT_BOTTOM))
    add('<line x1="%d" y1="%d" x2="%d" y2="%d" stroke="black"/>' %
        (LEFT, PLOT_TOP, LEFT, PLOT_BOTTOM))
    level = 0
    while level <= top_level:
        add('<text x="%d" y="%.1f" text-anchor="end">%d</text>' % (LEFT - 6, y(level) + 4, level))
        add('<line x1="%d" y1="%.1f" x2="%d" y2="%.1f" stroke="#eeeeee"/>' %
            (LEFT + 1, y(level), WIDTH - RIGHT, y(level)))
        level += 1
    t = 0.0
    while t <= t_end + 1e-9:
        add('<text x="%.1f" y="%d" text-anchor="middle">%g</text>' % (x(t), PLOT_BOTTOM + 16, t))
        t += 1.0
    add('<text x="%.1f" y="%d" text-anchor="middle">time (s)</text>' %
        ((LEFT + WIDTH - RIGHT) / 2, PLOT_BOTTOM + 34))
    add('<text transform="translate(18,%.1f) rotate(-90)" text-anchor="middle">'
        'level drawn (k - 1 + weight while morphing)</text>' % ((PLOT_TOP + PLOT_BOTTOM) / 2))

    # the objects' level positions; gaps where an object is not drawn
    for i, (obj, pts) in enumerate(sorted(series.items(), key=lambda kv: int(kv[0]))):
        colour = COLOURS[i % len(COLOURS)]
        path, pen = [], False
        for t, p in pts:
            if p is None:
                pen = False
                continue
            path.append("%s%.1f,%.1f" % ("L" if pen else "M", x(t), y(p) - i * 1.5))
            pen = True
        add('<path d="%s" fill="none" stroke="%s" stroke-width="2"/>' % (" ".join(path), colour))
        add('<line x1="%d" y1="%d" x2="%d" y2="%d" stroke="%s" stroke-width="2"/>' %
            (LEFT + 10 + 170 * i, PLOT_BOTTOM + 52, LEFT + 34 + 170 * i, PLOT_BOTTOM + 52, colour))
        add('<text x="%d" y="%d">object %s</text>' % (LEFT + 40 + 170 * i, PLOT_BOTTOM + 56, obj))

    caption = ("Each selection runs in slices during one interval and is for the interval two "
               "ahead. A coarser level is reached when its interval begins (down-morph during the "
               "interval before); a finer one is reached when its interval ends (up-morph during "
               "it). Two levels at once are two adjacent morphs in turn.")
    words, line, lines = caption.split(), "", []
    for word in words:
        if len(line) + len(word) > 130:
            lines.append(line)
            line = ""
        line += (" " if line else "") + word
    lines.append(line)
    for k, text in enumerate(lines):
        add('<text x="%d" y="%d" font-size="11" fill="#333333">%s</text>' %
            (LEFT, PLOT_BOTTOM + 76 + 14 * k, escape(text)))
    add("</svg>")
    sys.stdout.write("\n".join(out) + "\n")


if __name__ == "__main__":
    main()
