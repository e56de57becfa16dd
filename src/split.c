/*
 * Smooth variables of a frame: quadtree culling and variable splitting
 * (seed 000 §3.5 and Appendix A; thesis (seed 001) eq. 8.15-8.23, Algorithm 3).
 *
 * The scene keeps its smooth objects in a quadtree over their ground positions
 * (scene.c), so every quadtree node is a contiguous range of the smooth order.
 * A frame walks it from the root with an explicit stack: nodes outside the
 * frustum or smaller on screen than the small-detail area produce no variable.
 * Without splitting every visible object is a variable of its own. With
 * splitting, a node whose n objects are expected to receive a total resolution
 * X keeps one shared variable when the benefit that sharing loses against a
 * variable per child,
 *     L = sqrt(X) * (sqrt(sum C_i^2 / n_i) - sum C_i / sqrt(n)),
 * is within its share of the threshold; otherwise its children are visited
 * with X_i = X * (C_i^2 / n_i) / sum (C_j^2 / n_j) and an equal part of the
 * share. C_i is a child's benefit scale (its benefit at full resolution) and
 * n_i its object count. docs/mixed.md derives L and X_i from eq. 8.22-8.23 for
 * the square-root benefit of eq. 8.20: L is the exact loss when each child's
 * objects are alike, and eq. 8.23's worst case C sqrt(X) (1 - 1/sqrt(n)) when
 * a single object holds all the benefit.
 */
#include "internal.h"

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

static void add_variable(tclod_selector *sel, uint32_t first, uint32_t count,
                         const float bounds[4], float area, float distance) {
    tclod_vars *v = &sel->vars;
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

/* Every visible object of node k becomes a variable of its own. */
static void split_flat(tclod_selector *sel) {
    const tclod_scene *s = sel->scene;
    uint32_t top = 0;
    sel->split_node[top++] = 0;
    while (top > 0) {
        const tclod_smooth_node *node = &s->qt[sel->split_node[--top]];
        float area, distance;
        uint32_t i;
        measure(sel, node->bounds, &area, &distance);
        if (culled(sel, area)) continue;
        if (node->count == 1) {
            add_variable(sel, node->first, 1, node->bounds, area, distance);
        } else if (node->child_count == 0) {
            for (i = node->first; i < node->first + node->count; ++i) {
                const float *b = object_bounds(s, i);
                measure(sel, b, &area, &distance);
                if (!culled(sel, area)) add_variable(sel, i, 1, b, area, distance);
            }
        } else {
            /* reverse, so that the stack hands them out in order */
            for (i = node->child_count; i-- > 0;) sel->split_node[top++] = node->child + i;
        }
    }
}

/* Benefit scale of a group: its benefit at full resolution; 0 when culled or
 * its benefit is bad. Returns -1 on a strict error. */
static int scale_of(tclod_selector *sel, uint32_t first, uint32_t count, const float bounds[4],
                    double *scale) {
    float area, distance;
    double db;
    *scale = 0.0;
    measure(sel, bounds, &area, &distance);
    if (culled(sel, area)) return 0;
    tclod_smooth_call(sel, first, count, bounds, area, distance, 1.0, scale, &db, NULL, NULL);
    return sel->failed ? -1 : 0;
}

/* One child of a node being split: a quadtree node, or an object of a leaf
 * that holds several. */
static void child_range(const tclod_scene *s, const tclod_smooth_node *node, uint32_t i,
                        uint32_t *first, uint32_t *count, const float **bounds) {
    if (node->child_count > 0) {
        const tclod_smooth_node *c = &s->qt[node->child + i];
        *first = c->first;
        *count = c->count;
        *bounds = c->bounds;
    } else {
        *first = node->first + i;
        *count = 1;
        *bounds = object_bounds(s, node->first + i);
    }
}

/* Decides for the node on top of the stack: one shared variable, or its
 * visible children onto the stack (objects of a leaf become variables). */
static int split_node(tclod_selector *sel, uint32_t k, double x, double theta, uint32_t *top) {
    const tclod_scene *s = sel->scene;
    const tclod_smooth_node *node = &s->qt[k];
    uint32_t children = node->child_count > 0 ? node->child_count : node->count;
    uint32_t i, visible = 0;
    double sum = 0.0, spread = 0.0, loss, *scale = sel->vars.ratio; /* scratch until the solve */
    float area, distance;
    measure(sel, node->bounds, &area, &distance);
    if (node->count == 1) {
        add_variable(sel, node->first, 1, node->bounds, area, distance);
        return 0;
    }
    for (i = 0; i < children; ++i) {
        uint32_t first, count;
        const float *b;
        child_range(s, node, i, &first, &count, &b);
        if (scale_of(sel, first, count, b, &scale[i]) != 0) return -1;
        if (scale[i] > 0.0) {
            visible++;
            sum += scale[i];
            spread += scale[i] * scale[i] / (double)count;
        }
    }
    if (visible == 0) return 0;
    loss = sqrt(x) * (sqrt(spread) - sum / sqrt((double)node->count));
    if (loss <= theta) {
        add_variable(sel, node->first, node->count, node->bounds, area, distance);
        return 0;
    }
    for (i = children; i-- > 0;) {
        uint32_t first, count;
        const float *b;
        double xi;
        if (!(scale[i] > 0.0)) continue;
        child_range(s, node, i, &first, &count, &b);
        if (node->child_count == 0) {
            /* an object of a leaf: pushed as such, decided when popped */
            continue;
        }
        xi = x * (scale[i] * scale[i] / (double)count) / spread;
        if (xi > (double)count) xi = (double)count;
        sel->split_node[*top] = node->child + i;
        sel->split_x[*top] = xi;
        sel->split_theta[*top] = theta / (double)visible;
        (*top)++;
    }
    if (node->child_count == 0) /* objects of a leaf, in order */
        for (i = 0; i < children; ++i)
            if (scale[i] > 0.0) {
                const float *b = object_bounds(s, node->first + i);
                measure(sel, b, &area, &distance);
                add_variable(sel, node->first + i, 1, b, area, distance);
            }
    return 0;
}

/* Algorithm 3 from the root. The root's expected resolution X is what the
 * budget buys if all of it went to the smooth objects, and the loss allowed
 * in all is theta times the root's benefit at the mean resolution X / n. */
static int split_tree(tclod_selector *sel) {
    const tclod_scene *s = sel->scene;
    const tclod_smooth_node *root = &s->qt[0];
    double n = (double)root->count, scale, cost, db, dc, x = n, budget = sel->frame->budget;
    float area, distance;
    uint32_t top = 0;
    measure(sel, root->bounds, &area, &distance);
    if (culled(sel, area)) return 0;
    tclod_smooth_call(sel, root->first, root->count, root->bounds, area, distance, 1.0, &scale,
                      &db, &cost, &dc);
    if (sel->failed) return -1;
    if (!(scale > 0.0)) return 0;
    if (cost > 0.0 && budget < cost) x = n * budget / cost;
    sel->split_node[top] = 0;
    sel->split_x[top] = x;
    sel->split_theta[top] = sel->desc.split_threshold * scale * sqrt(x / n);
    top++;
    while (top > 0) {
        --top;
        if (split_node(sel, sel->split_node[top], sel->split_x[top], sel->split_theta[top],
                       &top) != 0)
            return -1;
    }
    return 0;
}

int tclod_split_variables(tclod_selector *sel) {
    sel->vars.count = 0;
    if (sel->scene->smooth_count == 0) return 0;
    if (!sel->desc.split_smooth) {
        split_flat(sel);
        return 0;
    }
    return split_tree(sel);
}
