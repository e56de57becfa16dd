/*
 * Benefit and cost models of the source papers, as helpers hosts may call from
 * their callbacks (docs/api.md, "Views"; docs/mixed.md, the models).
 *
 * - terrain patch benefit S * 2^(d - dmax), [Thesis8 eq. 8.21];
 * - tree-group benefit k * S * (N / 64) * sqrt(x / N), [Thesis8 eq. 8.20];
 * - splat cost with a per-tree setup, piecewise linear, [Thesis8 eq. 8.18];
 * - triangle-strip cost c_vertex * n, [Thesis8 eq. 8.19] and [GEO §4.2];
 * - accuracy * screen size, [GEO §4.2].
 * The formulas are written out in the header; docs/mixed.md derives the
 * resolution convention (x = r * N).
 *
 * Layer: core, which may call core. Calls: libc and libm only.
 */
#include "internal.h"

#include <math.h>

/* The square root's slope is infinite at 0; it is taken here instead. */
#define SLOPE_FLOOR 1e-12

double tclod_benefit_terrain(double screen_area, uint32_t depth, uint32_t max_depth) {
    if (!(screen_area > 0.0))
        return 0.0;
    return screen_area * ldexp(1.0, (int)depth - (int)max_depth);
}

double tclod_benefit_tree_group(double k, double screen_area, double trees, double r,
                                double *d_dr) {
    double scale = (screen_area > 0.0 && trees > 0.0) ? k * screen_area * (trees / 64.0) : 0.0;
    double rr = r > 0.0 ? (r < 1.0 ? r : 1.0) : 0.0;
    if (d_dr)
        *d_dr = scale * 0.5 / sqrt(rr > SLOPE_FLOOR ? rr : SLOPE_FLOOR);
    return scale * sqrt(rr);
}

double tclod_cost_splats(double c_splat, double c_tree, double splats, double trees, double r,
                         double *d_dr) {
    double rr = r > 0.0 ? (r < 1.0 ? r : 1.0) : 0.0;
    double n = rr * splats;
    if (n < trees) {
        if (d_dr)
            *d_dr = (c_splat + c_tree) * splats;
        return (c_splat + c_tree) * n;
    }
    if (d_dr)
        *d_dr = c_splat * splats;
    return c_splat * n + c_tree * trees;
}

double tclod_cost_vertices(double c_vertex, double vertices) {
    return c_vertex * vertices;
}

double tclod_benefit_accuracy(double screen_size, double faces, double original_faces) {
    double fine, coarse;
    if (!(screen_size > 0.0) || !(faces > 0.0) || !(original_faces > 0.0))
        return 0.0;
    fine = screen_size / original_faces;
    coarse = screen_size / faces;
    return screen_size * (fine > 1.0 ? fine : 1.0) / (coarse > 1.0 ? coarse : 1.0);
}
