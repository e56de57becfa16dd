/*
 * What the Robin Hood solver's two files share (robin_hood.c, the three
 * cycles; robin_hood_prepare.c, the instances and their order): the
 * evaluation of an instance's head and levels and the chains' bookkeeping.
 */
#ifndef TCLOD_ROBIN_HOOD_INTERNAL_H
#define TCLOD_ROBIN_HOOD_INTERNAL_H

#include "../eval/evaluate.h"

#include <math.h>
#include <string.h>

/* ---- value functions (eq. 8-11) ------------------------------------------------- */

/* v / I of value function f, for valid arguments (the default first: one
 * test where it is chosen). */
static inline double value_scale(tclod_value f, double area, double depth, double distance) {
    if (f == TCLOD_VALUE_AREA_SQRT_DEPTH)
        return area / sqrt(depth);
    switch (f) {
    case TCLOD_VALUE_AREA_DEPTH:
        return area / depth;
    case TCLOD_VALUE_AREA_DEPTH2:
        return area / (depth * depth);
    case TCLOD_VALUE_SQRT_AREA_DISTANCE2:
        return sqrt(area) / (distance * distance);
    default:
        return 1.0; /* TCLOD_VALUE_BENEFIT */
    }
}

/* The value of an instance of importance I > 0 whose bounds have radius r,
 * depth z and distance d (both at least the near plane) under this frame's
 * view, or, without bounds or view, the defaults a = 1, z = d = 1. */
static inline double value_at(const tclod_selector *sel, double area, double depth, double distance,
                              double importance) {
    return value_scale(sel->desc.robin_hood.value, area, depth, distance) * importance;
}

/* The value of an instance whose bounds are the sphere of radius r (< 0:
 * none; a box's enclosing sphere) around centre b, of importance I > 0, under
 * this frame's view: a = pi r², z the depth of the centre along the view
 * direction and d its distance, both at least the near plane. Without bounds
 * a = 1; without a view z = d = 1. Bounds and view are finite (the scene and
 * the frame check them) and the importance is a sanitised callback value, so
 * tclod_value_of's checks would all pass: only what the value function uses
 * is computed. */
static inline double instance_value(const tclod_selector *sel, const double b[3], double r,
                                    double importance) {
    tclod_value f = sel->desc.robin_hood.value;
    double area = 1.0, depth = 1.0, distance = 1.0;
    if (f == TCLOD_VALUE_BENEFIT)
        return importance;
    if (r >= 0.0) {
        area = 3.14159265358979323846 * r * r;
        if (sel->has_view) {
            const tclod_view_cache *c = &sel->view;
            double p0 = b[0] - c->eye[0], p1 = b[1] - c->eye[1], p2 = b[2] - c->eye[2];
            depth = p0 * c->forward[0] + p1 * c->forward[1] + p2 * c->forward[2];
            if (depth < c->near_z)
                depth = c->near_z;
            if (f == TCLOD_VALUE_SQRT_AREA_DISTANCE2) {
                distance = sqrt(p0 * p0 + p1 * p1 + p2 * p2);
                if (distance < c->near_z)
                    distance = c->near_z;
            }
        }
    }
    return value_at(sel, area, depth, distance, importance);
}

/* ---- evaluation ------------------------------------------------------------------- */

static inline int visible(const tclod_selector *sel, tclod_id n) {
    return sel->node[n].benefit > 0.0;
}

static inline int robin_hood_value_bad(double v) {
    return !(v >= 0.0) || isinf(v);
}

/* The importance of the instance that query q asks about: the importance
 * callback's value (a bad one counts and gives 0), or without one `benefit`;
 * -1 when a bad one failed a strict solve. */
static inline double importance_of(tclod_selector *sel, const tclod_query *q, double benefit,
                                   int plain) {
    const tclod_callbacks *cb = &sel->desc.callbacks;
    double i;
    if (!plain && !cb->importance)
        return benefit;
    i = cb->importance(cb->user, q);
    if (tclod_bits(i) <= TCLOD_BITS_MAX || !robin_hood_value_bad(i)) /* >= 0 and finite; then -0 */
        return i;
    tclod_bad_value(sel);
    return sel->failed ? -1.0 : 0.0;
}

/* Whether the solve has a view, the default value function and an
 * importance callback: the common case, for which evaluate_head has a copy
 * of its own that tests none of them. */
static inline int plain_heads(const tclod_selector *sel) {
    return sel->has_view && sel->desc.robin_hood.value == TCLOD_VALUE_AREA_SQRT_DEPTH &&
           sel->desc.callbacks.importance != NULL;
}

/* Node n, which starts an instance and was not evaluated in this solve yet,
 * evaluated (as tclod_evaluate_node would), with the instance's value in
 * *value (0 when it is not visible). The projection that measures its screen
 * area also gives the depth and distance its value needs. `inside`: its
 * bounds lie in a sphere that tclod_view_cache_inside found inside the
 * frustum, so the frustum test would pass. `plain`: plain_heads(sel) holds (a
 * constant where it is inlined). Returns 1 when n is visible, 0 when not, -1
 * on a strict error. */
TCLOD_ALWAYS_INLINE int evaluate_head(tclod_selector *sel, tclod_id n, int inside, int plain,
                                      double *value) {
    const tclod_node_bounds *b = &sel->scene->bounds[n];
    const tclod_view_cache *c = &sel->view;
    double p[3], r, d2, z, d, scale, i, distance;
    float area;
    int seen;
    assert(sel->node[n].stamp != sel->solve_id);
    assert(!plain || plain_heads(sel));
    if (!(plain || sel->has_view) || !(b->r >= 0.0)) {
        if (tclod_evaluate_node(sel, n) != 0)
            return -1;
        *value = 0.0;
        if (!visible(sel, n))
            return 0;
        i = importance_of(sel, &sel->query, sel->node[n].benefit, 0);
        if (i < 0.0)
            return -1;
        *value = instance_value(sel, b->c, b->r, i);
        return 1;
    }
    r = b->r;
    p[0] = b->c[0] - c->eye[0];
    p[1] = b->c[1] - c->eye[1];
    p[2] = b->c[2] - c->eye[2];
    d2 = p[0] * p[0] + p[1] * p[1] + p[2] * p[2];
    d = sqrt(d2);
    z = p[0] * c->forward[0] + p[1] * c->forward[1] + p[2] * c->forward[2];
    if (b->box != TCLOD_NONE) {
        tclod_view_cache_measure_box(c, p, &sel->scene->boxes[b->box], &area, &distance);
    } else {
        area = inside || tclod_view_cache_visible(c, p, r) ? (float)tclod_view_cache_area(c, d2, r)
                                                           : 0.0f;
        distance = d > r ? d - r : 0.0;
    }
    /* v / I before the callbacks, so that nothing but it lives across them */
    scale = value_scale(plain ? TCLOD_VALUE_AREA_SQRT_DEPTH : sel->desc.robin_hood.value,
                        3.14159265358979323846 * r * r, z < c->near_z ? c->near_z : z,
                        d < c->near_z ? c->near_z : d);
    *value = 0.0;
    seen = tclod_evaluate_bounded(sel, n, area, distance, 1);
    if (seen <= 0)
        return seen;
    /* the evaluation left n's query in sel->query */
    i = importance_of(sel, &sel->query, plain ? 0.0 : sel->node[n].benefit, plain);
    if (i < 0.0)
        return -1;
    *value = scale * i;
    return 1;
}

/* Node n, a finer level of the instance starting at head (evaluated in this
 * solve), not evaluated in this solve yet. A level with the head's bounds
 * (`shared`: all of the chain's levels have them) takes its screen area and
 * distance. Returns -1 on a strict error. */
static inline int evaluate_level(tclod_selector *sel, tclod_id n, tclod_id head, int shared) {
    const tclod_scene *s = sel->scene;
    float area = sel->node[head].area;
    double distance = (double)sel->node[head].distance;
    if (!shared && memcmp(&s->bounds[n], &s->bounds[head], sizeof(tclod_node_bounds)) != 0) {
        area = -1.0f;
        distance = -1.0;
        if (sel->has_view && s->bounds[n].r >= 0.0)
            tclod_view_measure_bounds(&sel->view, &s->bounds[n], s->boxes, &area, &distance);
    }
    return tclod_evaluate_measured(sel, n, area, distance);
}

/* The level head's chain (of len levels) took last: where its search starts
 * (any level would do; what is no level of the chain reads as 0). */
static inline uint32_t last_level(const tclod_selector *sel, tclod_id head, uint32_t len) {
    uint32_t l = sel->rh.level[head];
    return l < len ? l : 0u;
}

/* Keeps `level` as the level head's chain took last (beyond 255, 255: the
 * search then starts there). */
static inline void set_last_level(tclod_selector *sel, tclod_id head, uint32_t level) {
    sel->rh.level[head] = (uint8_t)(level < UINT8_MAX ? level : UINT8_MAX);
}

/* The solver reads the scene's child index through a copy of its own, made
 * when the scene changed, with every node's children contiguous in id order
 * (rh.kids, rh.first): the positions of a branch's children there are the
 * slots its sorted list and its values use. */
static inline uint32_t child_count(const tclod_selector *sel, tclod_id n) {
    return sel->rh.first[n + 1u] - sel->rh.first[n];
}

/* Whether smooth objects are instances: the smooth callbacks are set. */
static inline int with_smooth(const tclod_selector *sel) {
    return sel->desc.callbacks.smooth_benefit && tclod_smooth_priced(&sel->desc.callbacks);
}

/* ---- robin_hood_prepare.c ------------------------------------------------------ */

/* The chains (every node belongs to the chain of the nearest instance start
 * above it), each branching node's children and the top-level instances, in
 * order of complexity. Smooth objects are identified by their position in the
 * scene's smooth order, plus the node count. Returns -1 on a strict error. */
int tclod_rh_prepare(tclod_selector *sel);

#endif /* TCLOD_ROBIN_HOOD_INTERNAL_H */
