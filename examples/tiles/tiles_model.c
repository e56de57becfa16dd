/*
 * tiles_model — the benefit model of tclod_tiles (tiles_model.h).
 */
#include "tiles_model.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* A tile in the frustum whose share rounds to nothing still counts this many
 * px², and one that adds nothing to its additive ancestor this fraction of its
 * share: benefit 0 would cull its subtree. */
#define MIN_SHARE 1e-3
#define MIN_GAIN 1e-6

int model_init(tiles_model *m, const tileset *ts) {
    size_t n = ts->count ? ts->count : 1;
    memset(m, 0, sizeof(*m));
    m->ts = ts;
    m->area_stamp = (uint32_t *)calloc(n, sizeof(uint32_t));
    m->share_stamp = (uint32_t *)calloc(n, sizeof(uint32_t));
    m->sum_stamp = (uint32_t *)calloc(n, sizeof(uint32_t));
    m->distance_stamp = (uint32_t *)calloc(n, sizeof(uint32_t));
    m->area = (double *)malloc(n * sizeof(double));
    m->share = (double *)malloc(n * sizeof(double));
    m->child_sum = (double *)malloc(n * sizeof(double));
    m->distance = (double *)malloc(n * sizeof(double));
    m->path = (uint32_t *)malloc(((size_t)ts->counts.max_depth + 1) * sizeof(uint32_t));
    if (!m->area_stamp || !m->share_stamp || !m->sum_stamp || !m->distance_stamp || !m->area ||
        !m->share || !m->child_sum || !m->distance || !m->path) {
        model_free(m);
        return 1;
    }
    return 0;
}

void model_free(tiles_model *m) {
    free(m->area_stamp);
    free(m->share_stamp);
    free(m->sum_stamp);
    free(m->distance_stamp);
    free(m->area);
    free(m->share);
    free(m->child_sum);
    free(m->distance);
    free(m->path);
    memset(m, 0, sizeof(*m));
}

void model_set_view(tiles_model *m, const tclod_view *v) {
    m->view = *v;
    m->sse_factor = (double)v->viewport_height / (2.0 * tan(0.5 * (double)v->fov_y));
    /* stamp 0 is what calloc left: never a view's */
    if (++m->stamp == 0) {
        size_t n = m->ts->count;
        memset(m->area_stamp, 0, n * sizeof(uint32_t));
        memset(m->share_stamp, 0, n * sizeof(uint32_t));
        memset(m->sum_stamp, 0, n * sizeof(uint32_t));
        memset(m->distance_stamp, 0, n * sizeof(uint32_t));
        m->stamp = 1;
    }
}

double model_distance(tiles_model *m, uint32_t t) {
    if (m->distance_stamp[t] != m->stamp) {
        m->distance[t] = tclod_view_bounds_distance(&m->view, &m->ts->tiles[t].bounds);
        m->distance_stamp[t] = m->stamp;
    }
    return m->distance[t];
}

double model_area(tiles_model *m, uint32_t t) {
    if (m->area_stamp[t] != m->stamp) {
        const tclod_bounds *b = &m->ts->tiles[t].bounds;
        m->area[t] =
            tclod_view_bounds_visible(&m->view, b) ? tclod_view_bounds_area(&m->view, b) : 0.0;
        m->area_stamp[t] = m->stamp;
    }
    return m->area[t];
}

/* The children's projected areas summed: what a parent's share is split by. */
static double children_area(tiles_model *m, uint32_t p) {
    if (m->sum_stamp[p] != m->stamp) {
        const tile *x = &m->ts->tiles[p];
        double sum = 0.0;
        uint32_t i;
        for (i = 0; i < x->child_count; ++i)
            sum += model_area(m, m->ts->children[x->first_child + i]);
        m->child_sum[p] = sum;
        m->sum_stamp[p] = m->stamp;
    }
    return m->child_sum[p];
}

/* a_t: the root's projected area, split down the tree. The ancestors without a
 * share for this view are collected first and then filled from the top, so
 * that no tile is measured twice and nothing recurses. */
static double share_of(tiles_model *m, uint32_t t) {
    uint32_t n = 0, x = t;
    while (x != TILE_NONE && m->share_stamp[x] != m->stamp) {
        m->path[n++] = x;
        x = m->ts->tiles[x].parent;
    }
    while (n > 0) {
        uint32_t p;
        double s;
        x = m->path[--n];
        p = m->ts->tiles[x].parent;
        if (p == TILE_NONE) {
            s = model_area(m, x);
        } else {
            double sum = children_area(m, p);
            s = sum > 0.0 ? m->share[p] * (model_area(m, x) / sum) : 0.0;
        }
        m->share[x] = s;
        m->share_stamp[x] = m->stamp;
    }
    return m->share[t];
}

double model_sse(const tiles_model *m, uint32_t t, double distance) {
    double d = distance > MODEL_MIN_DISTANCE ? distance : MODEL_MIN_DISTANCE;
    return m->ts->tiles[t].geometric_error * m->sse_factor / d;
}

static double quality(double sse) {
    return 1.0 / (1.0 + sse / MODEL_HALF_QUALITY_SSE);
}

double model_benefit(tiles_model *m, uint32_t t, double distance) {
    uint32_t anchor = m->ts->tiles[t].add_anchor;
    double a = share_of(m, t), q = quality(model_sse(m, t, distance)), b;
    if (a < MIN_SHARE)
        a = MIN_SHARE;
    /* below an additive tile that stays drawn, only the improvement counts:
     * the sums over a drawn subtree then telescope to what its finest tiles
     * show, as with replacement */
    if (anchor != TILE_NONE)
        q -= quality(model_sse(m, anchor, model_distance(m, anchor)));
    b = a * q;
    return b > a * MIN_GAIN ? b : a * MIN_GAIN;
}

double model_reference_distance(const tclod_bounds *b, const double eye[3]) {
    double d[3], p[3], e2 = 0.0;
    int i, k;
    for (i = 0; i < 3; ++i)
        d[i] = eye[i] - b->center[i];
    if (b->kind == TCLOD_BOUNDS_SPHERE) {
        double r = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]) - b->radius;
        return r > 0.0 ? r : 0.0;
    }
    if (b->kind == TCLOD_BOUNDS_NONE)
        return -1.0;
    /* a box: the nearest point is the eye's offset clamped along each
     * (orthogonal) axis; a zero axis clamps to 0, so the offset across a flat
     * box counts whole */
    for (i = 0; i < 3; ++i)
        p[i] = d[i];
    for (k = 0; k < 3; ++k) {
        double axis[3], len, u, c;
        for (i = 0; i < 3; ++i)
            axis[i] = b->kind == TCLOD_BOUNDS_AABB ? (i == k ? b->half_extents[k] : 0.0)
                                                   : b->half_axes[k][i];
        len = sqrt(axis[0] * axis[0] + axis[1] * axis[1] + axis[2] * axis[2]);
        if (len == 0.0)
            continue;
        u = (d[0] * axis[0] + d[1] * axis[1] + d[2] * axis[2]) / len;
        c = u > len ? len : (u < -len ? -len : u);
        for (i = 0; i < 3; ++i)
            p[i] -= c * axis[i] / len;
    }
    for (i = 0; i < 3; ++i)
        e2 += p[i] * p[i];
    return sqrt(e2);
}
