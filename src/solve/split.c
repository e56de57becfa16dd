/*
 * Smooth variables of a frame: quadtree culling and variable splitting
 * ([ZMK02 §3.5] and Appendix A; [Thesis8 eq. 8.15-8.23, Algorithm 3]).
 *
 * The scene keeps its smooth objects in a quadtree over their ground positions
 * (scene.c), so every quadtree node is a contiguous range of the smooth order.
 * A frame walks it from the root with an explicit stack: nodes outside the
 * frustum or smaller on screen than the small-detail area produce no variable,
 * nor do objects that are not resident (docs/streaming.md), like culled ones.
 * Without splitting every visible object is a variable of its own. With
 * splitting, a first pass asks every visible object's benefit scale c_j (its
 * benefit at full resolution) and sums C = sum c_j and Q = sum c_j^2 up the
 * tree; then a node whose n objects are all visible and expected to receive a
 * total resolution X keeps one shared variable when what sharing loses
 * against a variable per object,
 *     L = sqrt(X) * (sqrt(Q) - C / sqrt(n)),
 * is within its share of the threshold; otherwise its visible children are
 * visited with X_i = X * (C_i^2 / n_i) / sum (C_j^2 / n_j) (at most n_i, the
 * excess handed to the others) and an equal part of the share. docs/mixed.md
 * derives L from eq. 8.22 for the square-root benefit of eq. 8.20: it is the
 * loss at the per-object optimum, never more than eq. 8.23's worst case
 * C sqrt(X) (1 - 1/sqrt(n)), which it equals when one object holds all the
 * benefit.
 *
 * Layer: solve, which may call core, eval and solve. Calls: core (view.c); eval
 * (evaluate.c).
 */
#include "../eval/evaluate.h"

#include <math.h>

/* Screen area and distance of a sphere: 0 outside the frustum; -1 and -1
 * without a view. */
static void measure(const tclod_selector *sel, const float bounds[4], float *area,
                    float *distance) {
    if (!sel->has_view) {
        *area = *distance = -1.0f;
        return;
    }
    tclod_view_cache_measure(&sel->view, bounds, area, distance);
}

/* Outside the frustum, or below the small-detail area. Nothing is culled
 * without a view. */
static int culled(const tclod_selector *sel, float area) {
    return sel->has_view && (!(area > 0.0f) || (double)area < sel->desc.smooth_cull_area);
}

/* Whether the object at smooth order position pos is not resident: it is left
 * out of every variable, like a culled one (docs/streaming.md). */
static int absent(const tclod_selector *sel, uint32_t pos) {
    const tclod_scene *s = sel->scene;
    return s->smooth_absent_count != 0 &&
           (s->smooth_flags[s->smooth_order[pos]] & TCLOD_NODE_ABSENT) != 0;
}

static void add_variable(tclod_selector *sel, uint32_t first, uint32_t count, const float bounds[4],
                         float area, float distance) {
    tclod_vars *v = &sel->mixed.vars;
    uint32_t i = v->count++;
    v->first[i] = first;
    v->size[i] = count;
    v->bounds[4u * i] = bounds[0];
    v->bounds[4u * i + 1u] = bounds[1];
    v->bounds[4u * i + 2u] = bounds[2];
    v->bounds[4u * i + 3u] = bounds[3];
    v->area[i] = area;
    v->distance[i] = distance;
    v->r[i] = 0.0;
    v->b[i] = v->c[i] = 0.0;
    v->state[i] = TCLOD_VAR_LIVE;
}

static const float *object_bounds(const tclod_scene *s, uint32_t pos) {
    return &s->smooth_bounds[4u * s->smooth_order[pos]];
}

/* Every visible, resident object of node k becomes a variable of its own. */
static void split_flat(tclod_selector *sel) {
    const tclod_scene *s = sel->scene;
    uint32_t top = 0;
    sel->mixed.split_node[top++] = 0;
    while (top > 0) {
        const tclod_smooth_node *node = &s->qt[sel->mixed.split_node[--top]];
        float area, distance;
        uint32_t i;
        measure(sel, node->bounds, &area, &distance);
        if (culled(sel, area))
            continue;
        if (node->count == 1) {
            if (!absent(sel, node->first))
                add_variable(sel, node->first, 1, node->bounds, area, distance);
        } else if (node->child_count == 0) {
            for (i = node->first; i < node->first + node->count; ++i) {
                const float *b = object_bounds(s, i);
                if (absent(sel, i))
                    continue;
                measure(sel, b, &area, &distance);
                if (!culled(sel, area))
                    add_variable(sel, i, 1, b, area, distance);
            }
        } else {
            /* reverse, so that the stack hands them out in order */
            for (i = node->child_count; i-- > 0;)
                sel->mixed.split_node[top++] = node->child + i;
        }
    }
}

/* Benefit scale of one object (a leaf of one, with the leaf's bounds, or an
 * object of a leaf of several, with its own) measured at area and distance:
 * its benefit at full resolution, 0 when culled, not resident or its benefit
 * is bad. Returns -1 on a strict error. */
TCLOD_ALWAYS_INLINE int object_scale(tclod_selector *sel, uint32_t pos, const float bounds[4],
                                     float area, float distance, double *scale) {
    double db;
    *scale = 0.0;
    if (culled(sel, area) || absent(sel, pos))
        return 0;
    tclod_smooth_call(sel, pos, 1, bounds, area, distance, 1.0, scale, &db, NULL, NULL);
    return sel->failed ? -1 : 0;
}

/* The first pass: every visible object's benefit scale c_j into
 * vars.ratio[position] (scratch until the solve; 0 when culled), and for every
 * quadtree node reached, the sums C = sum c_j and Q = sum c_j^2 over its
 * objects and whether all of them are visible (split_c, split_q,
 * split_whole). Culled nodes are not descended into; their records say
 * nothing visible. Inner nodes are listed in split_order in the order they
 * were reached (a parent before its children) and summed up in reverse. */
static int gather(tclod_selector *sel) {
    const tclod_scene *s = sel->scene;
    double *scale = sel->mixed.vars.ratio;
    uint32_t top = 0, inner = 0, i;
    sel->mixed.split_node[top++] = 0;
    while (top > 0) {
        uint32_t k = sel->mixed.split_node[--top];
        const tclod_smooth_node *node = &s->qt[k];
        float area, distance;
        double c = 0.0, q = 0.0;
        int whole = 1;
        measure(sel, node->bounds, &area, &distance);
        if (culled(sel, area)) {
            whole = 0;
        } else if (node->count == 1) { /* measured just now */
            if (object_scale(sel, node->first, node->bounds, area, distance, &c) != 0)
                return -1;
            scale[node->first] = c;
            q = c * c;
            whole = c > 0.0;
        } else if (node->child_count == 0) {
            for (i = node->first; i < node->first + node->count; ++i) {
                measure(sel, object_bounds(s, i), &area, &distance);
                if (object_scale(sel, i, object_bounds(s, i), area, distance, &scale[i]) != 0)
                    return -1;
                c += scale[i];
                q += scale[i] * scale[i];
                whole &= scale[i] > 0.0;
            }
        } else {
            sel->mixed.split_order[inner++] = k;
            for (i = node->child_count; i-- > 0;)
                sel->mixed.split_node[top++] = node->child + i;
            continue;
        }
        sel->mixed.split_c[k] = c;
        sel->mixed.split_q[k] = q;
        sel->mixed.split_whole[k] = (uint8_t)whole;
    }
    while (inner-- > 0) {
        uint32_t k = sel->mixed.split_order[inner];
        const tclod_smooth_node *node = &s->qt[k];
        double c = 0.0, q = 0.0;
        int whole = 1;
        for (i = node->child; i < node->child + node->child_count; ++i) {
            c += sel->mixed.split_c[i];
            q += sel->mixed.split_q[i];
            whole &= sel->mixed.split_whole[i];
        }
        sel->mixed.split_c[k] = c;
        sel->mixed.split_q[k] = q;
        sel->mixed.split_whole[k] = (uint8_t)whole;
    }
    return 0;
}

/* The expected resolutions of a quadtree node's children, x_i = x w_i /
 * sum w_j with w_i = C_i^2 / n_i (docs/mixed.md), each at most n_i: what a
 * capped child cannot take goes to the others in proportion to their w_i
 * (the level x / sum w only rises as children are capped, so a child capped
 * once stays capped). Children with nothing visible get nothing. The sum of
 * the open children's w is summed again each round rather than decreased,
 * which could leave it 0 by cancellation. */
static void share_resolution(const tclod_selector *sel, const tclod_smooth_node *node, double x,
                             double xi[4]) {
    const tclod_scene *s = sel->scene;
    double w[4], wsum;
    uint32_t i, n = node->child_count;
    int open[4], changed = 1;
    assert(n <= 4u);
    for (i = 0; i < n; ++i) {
        double c = sel->mixed.split_c[node->child + i];
        w[i] = c * c / (double)s->qt[node->child + i].count;
        open[i] = w[i] > 0.0;
        xi[i] = 0.0;
    }
    while (changed) {
        changed = 0;
        for (wsum = 0.0, i = 0; i < n; ++i)
            if (open[i])
                wsum += w[i];
        for (i = 0; i < n; ++i) {
            double count = (double)s->qt[node->child + i].count;
            if (!open[i] || !(x * w[i] > count * wsum))
                continue;
            xi[i] = count;
            open[i] = 0;
            x -= count;
            changed = 1;
            break; /* the others against the new level */
        }
    }
    for (wsum = 0.0, i = 0; i < n; ++i)
        if (open[i])
            wsum += w[i];
    for (i = 0; i < n; ++i)
        if (open[i])
            xi[i] = x * w[i] / wsum;
}

/* Decides for quadtree node k, expected to receive the total resolution x and
 * allowed the loss theta: one shared variable when all of its objects are
 * visible (a culled object in a group would be drawn and paid for) and the
 * loss of sharing against a variable per object (docs/mixed.md),
 *     sqrt(x) * (sqrt(Q) - C / sqrt(n)),
 * is within theta; otherwise its visible children onto the stack (objects of a
 * leaf become variables). The margin of 1e-12 of the group's benefit keeps
 * rounding from splitting alike objects at theta = 0. */
static void split_node(tclod_selector *sel, uint32_t k, double x, double theta, uint32_t *top) {
    const tclod_scene *s = sel->scene;
    const tclod_smooth_node *node = &s->qt[k];
    double c = sel->mixed.split_c[k], n = (double)node->count, xi[4];
    uint32_t i, visible = 0;
    float area, distance;
    if (node->count == 1 ||
        (sel->mixed.split_whole[k] && sqrt(x) * (sqrt(sel->mixed.split_q[k]) - c / sqrt(n)) <=
                                          theta + 1e-12 * c * sqrt(x / n))) {
        measure(sel, node->bounds, &area, &distance);
        add_variable(sel, node->first, node->count, node->bounds, area, distance);
        return;
    }
    if (node->child_count == 0) { /* the visible objects of a leaf, in order */
        for (i = node->first; i < node->first + node->count; ++i)
            if (sel->mixed.vars.ratio[i] > 0.0) {
                const float *b = object_bounds(s, i);
                measure(sel, b, &area, &distance);
                add_variable(sel, i, 1, b, area, distance);
            }
        return;
    }
    for (i = 0; i < node->child_count; ++i)
        visible += sel->mixed.split_c[node->child + i] > 0.0;
    share_resolution(sel, node, x, xi);
    /* reverse, so that the stack hands them out in order */
    for (i = node->child_count; i-- > 0;) {
        if (!(sel->mixed.split_c[node->child + i] > 0.0))
            continue;
        sel->mixed.split_node[*top] = node->child + i;
        sel->mixed.split_x[*top] = xi[i];
        sel->mixed.split_theta[*top] = theta / (double)visible;
        (*top)++;
    }
}

/* Algorithm 3 from the root, after the first pass. The root's expected
 * resolution X is what the budget buys if all of it went to the smooth
 * objects, and the loss allowed in all is theta times the visible objects'
 * benefit at the mean resolution X / n. */
static int split_tree(tclod_selector *sel) {
    const tclod_scene *s = sel->scene;
    const tclod_smooth_node *root = &s->qt[0];
    double n = (double)root->count, b, cost, db, dc, x = n, budget = sel->frame->budget;
    float area, distance;
    uint32_t top = 0;
    measure(sel, root->bounds, &area, &distance);
    if (culled(sel, area))
        return 0;
    if (gather(sel) != 0)
        return -1;
    if (!(sel->mixed.split_c[0] > 0.0))
        return 0;
    tclod_smooth_call(sel, root->first, root->count, root->bounds, area, distance, 1.0, &b, &db,
                      &cost, &dc);
    if (sel->failed)
        return -1;
    if (cost > 0.0 && budget < cost)
        x = n * budget / cost;
    sel->mixed.split_node[top] = 0;
    sel->mixed.split_x[top] = x;
    sel->mixed.split_theta[top] =
        sel->desc.mixed.split_threshold * sel->mixed.split_c[0] * sqrt(x / n);
    top++;
    while (top > 0) {
        --top;
        split_node(sel, sel->mixed.split_node[top], sel->mixed.split_x[top],
                   sel->mixed.split_theta[top], &top);
    }
    return 0;
}

int tclod_split_variables(tclod_selector *sel) {
    sel->mixed.vars.count = 0;
    if (sel->scene->smooth_live == 0)
        return 0;
    if (!sel->desc.mixed.split_smooth) {
        split_flat(sel);
        return 0;
    }
    return split_tree(sel);
}
