/*
 * frame_plot — see frame_plot.h.
 *
 * The picture: a title; the top panel with the predicted cost (solid) and the
 * budget (dashed) in ms; the bottom panel with the selection time in us; both
 * against the frame number, each with ticks at 1, 2 or 5 times a power of ten,
 * grid lines, axis labels and a legend.
 */
#include "frame_plot.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#define WIDTH 900.0
#define HEIGHT 600.0
#define LEFT 70.0   /* the panels' left edge */
#define RIGHT 870.0 /* and right edge */
#define TOP_Y 70.0  /* the top panel: y from TOP_Y to TOP_Y + TOP_H */
#define TOP_H 240.0
#define LOW_Y 385.0 /* the bottom panel */
#define LOW_H 160.0
#define TICKS 5 /* about this many ticks per axis */

static const char *const colours[PLOT_SERIES] = {"#1f77b4", "#d62728", "#2ca02c"};

int frame_plot_init(frame_plot *p, unsigned long frames) {
    size_t k;
    int ok = 1;
    p->frames = frames ? frames : 1;
    p->columns = p->frames < FRAME_PLOT_COLUMNS ? (size_t)p->frames : FRAME_PLOT_COLUMNS;
    for (k = 0; k < PLOT_SERIES; ++k) {
        p->lo[k] = (double *)malloc(p->columns * sizeof(double));
        p->hi[k] = (double *)malloc(p->columns * sizeof(double));
        ok = ok && p->lo[k] && p->hi[k];
    }
    p->filled = (unsigned char *)calloc(p->columns, 1);
    return ok && p->filled;
}

void frame_plot_free(frame_plot *p) {
    size_t k;
    for (k = 0; k < PLOT_SERIES; ++k) {
        free(p->lo[k]);
        free(p->hi[k]);
        p->lo[k] = p->hi[k] = NULL;
    }
    free(p->filled);
    p->filled = NULL;
}

void frame_plot_add(frame_plot *p, unsigned long frame, double cost_ms, double budget_ms,
                    double time_us) {
    const double v[PLOT_SERIES] = {cost_ms, budget_ms, time_us};
    size_t c, k;
    if (frame >= p->frames)
        return;
    c = (size_t)((unsigned long long)frame * p->columns / p->frames);
    for (k = 0; k < PLOT_SERIES; ++k) {
        double x = isfinite(v[k]) && v[k] > 0.0 ? v[k] : 0.0;
        if (!p->filled[c] || x < p->lo[k][c])
            p->lo[k][c] = x;
        if (!p->filled[c] || x > p->hi[k][c])
            p->hi[k][c] = x;
    }
    p->filled[c] = 1;
}

/* A tick step of 1, 2 or 5 times a power of ten that cuts [0, range] into
 * about TICKS parts. */
static double tick_step(double range) {
    double raw = range / TICKS, mag = pow(10.0, floor(log10(raw))), f = raw / mag;
    return (f <= 1.0 ? 1.0 : f <= 2.0 ? 2.0 : f <= 5.0 ? 5.0 : 10.0) * mag;
}

/* The largest value the columns of the given series reach. */
static double series_max(const frame_plot *p, int first, int last) {
    double m = 0.0;
    size_t c;
    int k;
    for (k = first; k <= last; ++k)
        for (c = 0; c < p->columns; ++c)
            if (p->filled[c] && p->hi[k][c] > m)
                m = p->hi[k][c];
    return m;
}

/* Text with the characters XML reserves escaped. */
static void put_text(FILE *f, const char *s) {
    for (; *s; ++s) {
        if (*s == '&')
            fputs("&amp;", f);
        else if (*s == '<')
            fputs("&lt;", f);
        else if (*s == '>')
            fputs("&gt;", f);
        else
            fputc(*s, f);
    }
}

/* The frame a column stands for: its middle. */
static double column_frame(const frame_plot *p, size_t c) {
    return ((double)c + 0.5) * (double)p->frames / (double)p->columns - 0.5;
}

static double x_of(const frame_plot *p, double frame) {
    double last = p->frames > 1 ? (double)(p->frames - 1) : 1.0;
    return LEFT + (RIGHT - LEFT) * frame / last;
}

/* One panel: frame, grid, ticks and labels on both axes, the series first ..
 * last as polylines, and their legend. */
static void panel(FILE *f, const frame_plot *p, double top, double height, int first, int last,
                  const char *y_label, const char *const names[]) {
    double ymax = series_max(p, first, last), step, x_step;
    double xlast = p->frames > 1 ? (double)(p->frames - 1) : 1.0;
    int i, k;
    size_t c;
    if (!(ymax > 0.0))
        ymax = 1.0;
    step = tick_step(ymax * 1.05);
    ymax = ceil(ymax * 1.05 / step) * step;
    x_step = tick_step(xlast);
    if (x_step < 1.0)
        x_step = 1.0;

    fprintf(f, "<g>\n");
    for (i = 0; (double)i * step <= ymax * (1.0 + 1e-9); ++i) {
        double v = (double)i * step, y = top + height - height * v / ymax;
        fprintf(f,
                "<line x1=\"%.1f\" y1=\"%.1f\" x2=\"%.1f\" y2=\"%.1f\" stroke=\"#dddddd\"/>\n"
                "<line x1=\"%.1f\" y1=\"%.1f\" x2=\"%.1f\" y2=\"%.1f\" stroke=\"black\"/>\n"
                "<text x=\"%.1f\" y=\"%.1f\" text-anchor=\"end\">%g</text>\n",
                LEFT, y, RIGHT, y, LEFT - 5.0, y, LEFT, y, LEFT - 8.0, y + 4.0, v);
    }
    for (i = 0; (double)i * x_step <= xlast * (1.0 + 1e-9); ++i) {
        double v = (double)i * x_step, x = x_of(p, v);
        fprintf(f,
                "<line x1=\"%.1f\" y1=\"%.1f\" x2=\"%.1f\" y2=\"%.1f\" stroke=\"black\"/>\n"
                "<text x=\"%.1f\" y=\"%.1f\" text-anchor=\"middle\">%g</text>\n",
                x, top + height, x, top + height + 5.0, x, top + height + 18.0, v);
    }
    fprintf(f,
            "<rect x=\"%.1f\" y=\"%.1f\" width=\"%.1f\" height=\"%.1f\" fill=\"none\" "
            "stroke=\"black\"/>\n",
            LEFT, top, RIGHT - LEFT, height);
    fprintf(f, "<text x=\"%.1f\" y=\"%.1f\" text-anchor=\"middle\">frame</text>\n",
            0.5 * (LEFT + RIGHT), top + height + 34.0);
    /* above the axis, not along it: rotated text is where SVG renderers differ */
    fprintf(f, "<text x=\"%.1f\" y=\"%.1f\">", LEFT - 40.0, top - 10.0);
    put_text(f, y_label);
    fprintf(f, "</text>\n");

    for (k = first; k <= last; ++k) {
        fprintf(f, "<polyline fill=\"none\" stroke=\"%s\" stroke-width=\"1.2\"%s points=\"",
                colours[k], k == PLOT_BUDGET ? " stroke-dasharray=\"6,4\"" : "");
        for (c = 0; c < p->columns; ++c) {
            double x = x_of(p, column_frame(p, c));
            if (!p->filled[c])
                continue;
            fprintf(f, "%.2f,%.2f ", x, top + height - height * p->hi[k][c] / ymax);
            if (p->lo[k][c] != p->hi[k][c])
                fprintf(f, "%.2f,%.2f ", x, top + height - height * p->lo[k][c] / ymax);
        }
        fprintf(f, "\"/>\n");
    }

    for (k = first; k <= last; ++k) {
        double y = top + 16.0 + 16.0 * (double)(k - first), x = RIGHT - 170.0;
        fprintf(f,
                "<line x1=\"%.1f\" y1=\"%.1f\" x2=\"%.1f\" y2=\"%.1f\" stroke=\"%s\" "
                "stroke-width=\"2\"%s/>\n<text x=\"%.1f\" y=\"%.1f\">",
                x, y - 4.0, x + 24.0, y - 4.0, colours[k],
                k == PLOT_BUDGET ? " stroke-dasharray=\"6,4\"" : "", x + 30.0, y);
        put_text(f, names[k - first]);
        fprintf(f, "</text>\n");
    }
    fprintf(f, "</g>\n");
}

int frame_plot_write(const frame_plot *p, const char *path, const char *title,
                     const char *time_label) {
    static const char *const cost_names[] = {"predicted cost", "budget"};
    char time_axis[128];
    const char *time_names[1];
    FILE *f = fopen(path, "w");
    int ok;
    if (!f)
        return 0;
    snprintf(time_axis, sizeof time_axis, "%s (\xc2\xb5s)", time_label);
    time_names[0] = time_label;
    fprintf(f,
            "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
            "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"%.0f\" height=\"%.0f\" "
            "viewBox=\"0 0 %.0f %.0f\" font-family=\"sans-serif\" font-size=\"12\">\n"
            "<rect width=\"100%%\" height=\"100%%\" fill=\"white\"/>\n"
            "<text x=\"%.1f\" y=\"30\" text-anchor=\"middle\" font-size=\"15\">",
            WIDTH, HEIGHT, WIDTH, HEIGHT, 0.5 * WIDTH);
    put_text(f, title);
    fprintf(f, "</text>\n");
    panel(f, p, TOP_Y, TOP_H, PLOT_COST, PLOT_BUDGET, "predicted cost (ms)", cost_names);
    panel(f, p, LOW_Y, LOW_H, PLOT_TIME, PLOT_TIME, time_axis, time_names);
    fprintf(f, "</svg>\n");
    ok = !ferror(f);
    return fclose(f) == 0 && ok;
}
