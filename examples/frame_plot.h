/*
 * frame_plot — a self-contained SVG plot of a flight, frame by frame: the
 * predicted cost of what was drawn against the budget (top panel) and the time
 * the selection took (bottom panel). Plain SVG text, no dependency.
 *
 * Frames are gathered into at most FRAME_PLOT_COLUMNS columns, each keeping the
 * least and the largest value of its frames, so that a long flight still makes a
 * small file and no spike is lost.
 */
#ifndef FRAME_PLOT_H
#define FRAME_PLOT_H

#include <stddef.h>

#define FRAME_PLOT_COLUMNS 1000u

/* The series, in the order frame_plot_add takes them. */
enum { PLOT_COST, PLOT_BUDGET, PLOT_TIME, PLOT_SERIES };

typedef struct frame_plot {
    unsigned long frames;                      /* frames the flight has, >= 1 */
    size_t columns;                            /* min(frames, FRAME_PLOT_COLUMNS) */
    double *lo[PLOT_SERIES], *hi[PLOT_SERIES]; /* per column */
    unsigned char *filled;                     /* per column: 1 once a frame landed in it */
} frame_plot;

/* Room for a flight of `frames` frames (>= 1). 0 when out of memory (p can
 * then still be freed). */
int frame_plot_init(frame_plot *p, unsigned long frames);

/* Frees what frame_plot_init allocated. */
void frame_plot_free(frame_plot *p);

/* Frame `frame` (< frames): its predicted cost and budget (ms) and the time its
 * selection took (us). */
void frame_plot_add(frame_plot *p, unsigned long frame, double cost_ms, double budget_ms,
                    double time_us);

/* Writes the plot to path as an SVG document. title heads it; time_label names
 * the bottom panel's quantity (e.g. "selection time"). 0 when the file cannot
 * be written. */
int frame_plot_write(const frame_plot *p, const char *path, const char *title,
                     const char *time_label);

#endif /* FRAME_PLOT_H */
