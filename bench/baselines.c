/*
 * baselines — threshold LOD (fixed and tuned bias), priority-queue refinement that stops
 * at the first misfit, and the flat per-object greedy. See baselines.h.
 *
 * Node values are cached per call with a stamp (no clearing between frames). The view
 * is set up once per call in the same way as src/core/view.c does it (its header states the
 * formulas): the public helpers tclod_view_sphere_visible and tclod_view_screen_area
 * re-derive the camera basis at every call, which an engine's culling loop would not
 * do, and which would make the baselines look slower than they are.
 */
#include "baselines.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define BASELINE_PI 3.14159265358979323846
/* log2(bias) range of the tuned threshold's bisection. */
#define BASELINE_LOG2_BIAS_MIN (-16.0)
#define BASELINE_LOG2_BIAS_MAX 16.0

typedef struct baseline_view {
    double eye[3], forward[3], up[3], right[3];
    double cos_y, sin_y, cos_x, sin_x, near_z, far_z, pi_focal2, viewport_area;
} baseline_view;

typedef struct baseline_entry {
    double key;
    tclod_id id;
} baseline_entry;

struct baseline_selector {
    const baseline_scene *scene;
    tclod_callbacks cb;
    const tclod_view *view;
    baseline_view vc;
    uint32_t frame;
    /* per node */
    uint32_t *stamp, *cost_stamp, *refined; /* == frame: evaluated / cost known / refined */
    double *benefit, *cost;
    float *area;
    /* per call */
    tclod_id *ids, *stack;
    baseline_entry *heap;
    size_t heap_n;
    tclod_id *level; /* flat: current node of each object (TCLOD_NONE: not drawn) */
    uint32_t evaluations;
    uint32_t *listed, listed_stamp; /* baseline_count_holes: == listed_stamp when listed */
};

/* ---- view ----------------------------------------------------------------------- */

static double bl_dot(const double a[3], const double b[3]) {
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

static void bl_cross(const double a[3], const double b[3], double out[3]) {
    out[0] = a[1] * b[2] - a[2] * b[1];
    out[1] = a[2] * b[0] - a[0] * b[2];
    out[2] = a[0] * b[1] - a[1] * b[0];
}

static void bl_normalize(double v[3]) {
    double len = sqrt(bl_dot(v, v));
    if (len > 0.0) {
        v[0] /= len;
        v[1] /= len;
        v[2] /= len;
    }
}

static void bl_view_init(baseline_view *c, const tclod_view *v) {
    double half_y = 0.5 * (double)v->fov_y;
    double half_x = atan((double)v->aspect * tan(half_y));
    double focal = 0.5 * (double)v->viewport_height / tan(half_y);
    int i;
    for (i = 0; i < 3; ++i) {
        c->eye[i] = (double)v->eye[i];
        c->forward[i] = (double)v->forward[i];
        c->up[i] = (double)v->up[i];
    }
    bl_normalize(c->forward);
    bl_cross(c->forward, c->up, c->right);
    bl_normalize(c->right);
    bl_cross(c->right, c->forward, c->up);
    c->cos_y = cos(half_y);
    c->sin_y = sin(half_y);
    c->cos_x = cos(half_x);
    c->sin_x = sin(half_x);
    c->near_z = (double)v->near_z;
    c->far_z = (double)v->far_z;
    c->pi_focal2 = BASELINE_PI * focal * focal;
    c->viewport_area = (double)v->viewport_height * (double)v->viewport_height * (double)v->aspect;
}

/* Screen area (0 outside the frustum) and distance of a bounding sphere. */
static void bl_measure(const baseline_view *c, const float *bounds, float *area, float *distance) {
    double p[3], r = (double)bounds[3], d2, z;
    p[0] = (double)bounds[0] - c->eye[0];
    p[1] = (double)bounds[1] - c->eye[1];
    p[2] = (double)bounds[2] - c->eye[2];
    d2 = bl_dot(p, p);
    *distance = (float)(sqrt(d2) > r ? sqrt(d2) - r : 0.0); /* to the sphere, as the library's */
    z = bl_dot(p, c->forward);
    if (z < c->near_z - r || z > c->far_z + r ||
        fabs(bl_dot(p, c->up)) * c->cos_y - z * c->sin_y > r ||
        fabs(bl_dot(p, c->right)) * c->cos_x - z * c->sin_x > r) {
        *area = 0.0f;
        return;
    }
    if (d2 <= r * r) {
        *area = (float)c->viewport_area;
    } else {
        double a = c->pi_focal2 * (r * r) / (d2 - r * r); /* as the library's view cache */
        *area = (float)(a < c->viewport_area ? a : c->viewport_area);
    }
}

/* ---- scene ---------------------------------------------------------------------- */

void baseline_scene_free(baseline_scene *b) {
    if (b == NULL)
        return;
    free(b->child_first);
    free(b->children);
    free(b->roots);
    free(b->objects);
    memset(b, 0, sizeof *b);
}

tclod_status baseline_scene_init(baseline_scene *b, const tclod_scene *s, const float *bounds,
                                 const uint32_t *detail, const tclod_id *objects,
                                 uint32_t object_count) {
    uint32_t n, i, *fill;
    int chains = 1;
    if (b == NULL || s == NULL)
        return TCLOD_ERR_ARG;
    memset(b, 0, sizeof *b);
    n = tclod_scene_node_count(s);
    b->count = n;
    b->bounds = bounds;
    b->detail = detail;
    b->child_first = (uint32_t *)calloc((size_t)n + 1u, sizeof *b->child_first);
    b->children = (tclod_id *)malloc(((size_t)n + 1u) * sizeof *b->children);
    b->roots = (tclod_id *)malloc(((size_t)n + 1u) * sizeof *b->roots);
    fill = (uint32_t *)malloc(((size_t)n + 1u) * sizeof *fill);
    if (!b->child_first || !b->children || !b->roots || !fill) {
        free(fill);
        baseline_scene_free(b);
        return TCLOD_ERR_NOMEM;
    }
    for (i = 0; i < n; ++i) {
        tclod_id p = tclod_scene_parent(s, i);
        if (p == TCLOD_NONE)
            b->roots[b->root_count++] = i;
        else
            b->child_first[p]++;
    }
    /* Counts to offsets (exclusive prefix sums), then children in id order. */
    {
        uint32_t sum = 0;
        for (i = 0; i <= n; ++i) {
            uint32_t c = i < n ? b->child_first[i] : 0u;
            b->child_first[i] = sum;
            if (i < n)
                fill[i] = sum;
            sum += c;
            if (c > 1u)
                chains = 0;
        }
    }
    for (i = 0; i < n; ++i) {
        tclod_id p = tclod_scene_parent(s, i);
        if (p != TCLOD_NONE)
            b->children[fill[p]++] = i;
    }
    free(fill);
    if (objects != NULL || chains) {
        uint32_t count = objects != NULL ? object_count : b->root_count;
        b->objects = (tclod_id *)malloc(((size_t)count + 1u) * sizeof *b->objects);
        if (b->objects == NULL) {
            baseline_scene_free(b);
            return TCLOD_ERR_NOMEM;
        }
        memcpy(b->objects, objects != NULL ? objects : b->roots, count * sizeof *b->objects);
        b->object_count = count;
    }
    return TCLOD_OK;
}

/* ---- selector ------------------------------------------------------------------- */

tclod_status baseline_create(const baseline_scene *b, const tclod_callbacks *cb,
                             baseline_selector **out) {
    baseline_selector *sel;
    size_t n;
    if (b == NULL || cb == NULL || out == NULL || cb->benefit == NULL || cb->cost == NULL)
        return TCLOD_ERR_ARG;
    n = (size_t)b->count + 1u;
    sel = (baseline_selector *)calloc(1, sizeof *sel);
    if (sel == NULL)
        return TCLOD_ERR_NOMEM;
    sel->scene = b;
    sel->cb = *cb;
    sel->stamp = (uint32_t *)calloc(n, sizeof *sel->stamp);
    sel->cost_stamp = (uint32_t *)calloc(n, sizeof *sel->cost_stamp);
    sel->refined = (uint32_t *)calloc(n, sizeof *sel->refined);
    sel->benefit = (double *)malloc(n * sizeof *sel->benefit);
    sel->cost = (double *)malloc(n * sizeof *sel->cost);
    sel->area = (float *)malloc(n * sizeof *sel->area);
    sel->ids = (tclod_id *)malloc(n * sizeof *sel->ids);
    sel->stack = (tclod_id *)malloc(n * sizeof *sel->stack);
    sel->heap = (baseline_entry *)malloc(n * sizeof *sel->heap);
    sel->level = (tclod_id *)malloc(((size_t)b->object_count + 1u) * sizeof *sel->level);
    sel->listed = (uint32_t *)calloc(n, sizeof *sel->listed);
    if (!sel->listed || !sel->stamp || !sel->cost_stamp || !sel->refined || !sel->benefit ||
        !sel->cost || !sel->area || !sel->ids || !sel->stack || !sel->heap || !sel->level) {
        baseline_destroy(sel);
        return TCLOD_ERR_NOMEM;
    }
    *out = sel;
    return TCLOD_OK;
}

void baseline_destroy(baseline_selector *sel) {
    if (sel == NULL)
        return;
    free(sel->stamp);
    free(sel->cost_stamp);
    free(sel->refined);
    free(sel->benefit);
    free(sel->cost);
    free(sel->area);
    free(sel->ids);
    free(sel->stack);
    free(sel->heap);
    free(sel->level);
    free(sel->listed);
    free(sel);
}

/* A new frame: every cached value is stale. */
static void bl_begin(baseline_selector *sel, const tclod_view *view) {
    sel->view = view;
    if (view != NULL)
        bl_view_init(&sel->vc, view);
    sel->frame++;
    if (sel->frame == 0u) { /* the stamps wrapped: clear them once */
        memset(sel->stamp, 0, (size_t)sel->scene->count * sizeof *sel->stamp);
        memset(sel->cost_stamp, 0, (size_t)sel->scene->count * sizeof *sel->cost_stamp);
        memset(sel->refined, 0, (size_t)sel->scene->count * sizeof *sel->refined);
        sel->frame = 1u;
    }
    sel->evaluations = 0;
}

static void bl_query(const baseline_selector *sel, tclod_id n, tclod_query *q) {
    const float *bounds = sel->scene->bounds ? sel->scene->bounds + 4u * (size_t)n : NULL;
    q->id = n;
    q->count = 1;
    q->view = sel->view;
    q->screen_area = -1.0f;
    q->distance = -1.0f;
    q->members = NULL;
    q->bounds = NULL;
    if (sel->view != NULL && bounds != NULL && bounds[3] >= 0.0f)
        bl_measure(&sel->vc, bounds, &q->screen_area, &q->distance);
}

/* The node's benefit this frame (0 = culled), evaluating it on first use. */
static double bl_benefit(baseline_selector *sel, tclod_id n) {
    tclod_query q;
    double b;
    if (sel->stamp[n] == sel->frame)
        return sel->benefit[n];
    bl_query(sel, n, &q);
    b = sel->cb.benefit(sel->cb.user, &q);
    if (!(b >= 0.0) || isinf(b))
        b = 0.0;
    sel->stamp[n] = sel->frame;
    sel->benefit[n] = b;
    sel->area[n] = q.screen_area;
    sel->evaluations++;
    return b;
}

/* The node's cost this frame (0 when culled, +inf for a bad value). */
static double bl_cost(baseline_selector *sel, tclod_id n) {
    tclod_query q;
    double c;
    if (sel->cost_stamp[n] == sel->frame)
        return sel->cost[n];
    c = 0.0;
    if (bl_benefit(sel, n) > 0.0) {
        bl_query(sel, n, &q);
        c = sel->cb.cost(sel->cb.user, &q);
        if (!(c >= 0.0))
            c = HUGE_VAL;
    }
    sel->cost_stamp[n] = sel->frame;
    sel->cost[n] = c;
    return c;
}

/* Sums the result's benefit and cost in result order. */
static void bl_finish(baseline_selector *sel, size_t n, baseline_result *r) {
    size_t i;
    r->ids = sel->ids;
    r->n = n;
    r->benefit = 0.0;
    r->cost = 0.0;
    for (i = 0; i < n; ++i) {
        r->benefit += sel->benefit[sel->ids[i]];
        r->cost += sel->cost[sel->ids[i]];
    }
    r->evaluations = sel->evaluations;
}

/* ---- binary max-heap: key descending, then id ascending ---------------------------- */

static int bl_above(const baseline_entry *a, const baseline_entry *b) {
    return a->key > b->key || (a->key == b->key && a->id < b->id);
}

static void bl_push(baseline_selector *sel, double key, tclod_id id) {
    size_t i = sel->heap_n++;
    baseline_entry e;
    e.key = key;
    e.id = id;
    while (i > 0 && bl_above(&e, &sel->heap[(i - 1u) / 2u])) {
        sel->heap[i] = sel->heap[(i - 1u) / 2u];
        i = (i - 1u) / 2u;
    }
    sel->heap[i] = e;
}

static baseline_entry bl_pop(baseline_selector *sel) {
    baseline_entry top = sel->heap[0], last = sel->heap[--sel->heap_n];
    size_t i = 0, n = sel->heap_n;
    for (;;) {
        size_t c = 2u * i + 1u;
        if (c >= n)
            break;
        if (c + 1u < n && bl_above(&sel->heap[c + 1u], &sel->heap[c]))
            c++;
        if (!bl_above(&sel->heap[c], &last))
            break;
        sel->heap[i] = sel->heap[c];
        i = c;
    }
    if (n > 0)
        sel->heap[i] = last;
    return top;
}

/* ---- threshold LOD ---------------------------------------------------------------- */

/* One pass at a bias: depth first from the roots, refining while the rule says so.
 * Returns the number of selected nodes (in sel->ids) and their summed cost. */
static size_t bl_threshold_pass(baseline_selector *sel, double bias, double *cost) {
    const baseline_scene *b = sel->scene;
    double bias2 = bias * bias, sum = 0.0;
    size_t n = 0, top = 0;
    uint32_t i;
    for (i = b->root_count; i-- > 0;)
        sel->stack[top++] = b->roots[i];
    while (top > 0) {
        tclod_id v = sel->stack[--top];
        uint32_t first = b->child_first[v], end = b->child_first[v + 1u];
        if (!(bl_benefit(sel, v) > 0.0))
            continue; /* culled with its subtree */
        if (first < end && (double)sel->area[v] * bias2 > (double)b->detail[v]) {
            uint32_t c;
            for (c = end; c-- > first;)
                sel->stack[top++] = b->children[c];
            continue;
        }
        sel->ids[n++] = v;
        sum += bl_cost(sel, v);
    }
    *cost = sum;
    return n;
}

int baseline_threshold(baseline_selector *sel, const tclod_view *view, double bias,
                       baseline_result *r) {
    double cost;
    size_t n;
    if (view == NULL || sel->scene->bounds == NULL || sel->scene->detail == NULL)
        return -1;
    bl_begin(sel, view);
    n = bl_threshold_pass(sel, bias, &cost);
    bl_finish(sel, n, r);
    r->iterations = 1;
    r->refinements = 0;
    r->bias = bias;
    return 0;
}

int baseline_threshold_tuned(baseline_selector *sel, const tclod_view *view, double budget,
                             baseline_result *r) {
    double lo = BASELINE_LOG2_BIAS_MIN, hi = BASELINE_LOG2_BIAS_MAX, cost, chosen;
    uint32_t passes = 0;
    int step;
    size_t n;
    if (view == NULL || sel->scene->bounds == NULL || sel->scene->detail == NULL)
        return -1;
    bl_begin(sel, view);
    /* Largest bias first: when it fits there is nothing to tune. */
    bl_threshold_pass(sel, exp2(hi), &cost);
    passes++;
    if (cost <= budget) {
        chosen = hi;
    } else {
        for (step = 0; step < BASELINE_BISECTION_STEPS; ++step) {
            double mid = 0.5 * (lo + hi);
            bl_threshold_pass(sel, exp2(mid), &cost);
            passes++;
            if (cost <= budget)
                lo = mid;
            else
                hi = mid;
        }
        chosen = lo;
    }
    n = bl_threshold_pass(sel, exp2(chosen), &cost);
    passes++;
    bl_finish(sel, n, r);
    r->iterations = passes;
    r->refinements = 0;
    r->bias = exp2(chosen);
    return 0;
}

/* ---- priority queue that stops at the first misfit --------------------------------- */

static double bl_priority(baseline_selector *sel, tclod_id v) {
    double b = bl_benefit(sel, v);
    return sel->area[v] >= 0.0f ? (double)sel->area[v] : b;
}

int baseline_pq_stop(baseline_selector *sel, const tclod_view *view, double budget,
                     baseline_result *r) {
    const baseline_scene *b = sel->scene;
    double cost = 0.0;
    uint32_t i, pops = 0, refinements = 0;
    size_t n = 0, top = 0;
    int stopped = 0;
    bl_begin(sel, view);
    sel->heap_n = 0;
    /* Roots by priority; the first that does not fit ends the selection there. */
    for (i = 0; i < b->root_count; ++i)
        if (bl_benefit(sel, b->roots[i]) > 0.0)
            bl_push(sel, bl_priority(sel, b->roots[i]), b->roots[i]);
    while (sel->heap_n > 0) {
        baseline_entry e = bl_pop(sel);
        double c = bl_cost(sel, e.id);
        if (stopped || cost + c > budget) {
            stopped = 1;
            continue;
        }
        cost += c;
        sel->stack[top++] = e.id; /* drawn roots, reused below as the frontier's seed */
    }
    /* Then refinements, largest on screen first. */
    for (i = 0; i < top; ++i)
        if (b->child_first[sel->stack[i] + 1u] > b->child_first[sel->stack[i]])
            bl_push(sel, bl_priority(sel, sel->stack[i]), sel->stack[i]);
    while (!stopped && sel->heap_n > 0) {
        baseline_entry e = bl_pop(sel);
        uint32_t first = b->child_first[e.id], end = b->child_first[e.id + 1u], c;
        double delta = -bl_cost(sel, e.id);
        pops++;
        for (c = first; c < end; ++c)
            delta += bl_cost(sel, b->children[c]);
        if (cost + delta > budget) {
            stopped = 1;
            break;
        }
        cost += delta;
        sel->refined[e.id] = sel->frame;
        refinements++;
        for (c = first; c < end; ++c) {
            tclod_id ch = b->children[c];
            if (bl_benefit(sel, ch) > 0.0 && b->child_first[ch + 1u] > b->child_first[ch])
                bl_push(sel, bl_priority(sel, ch), ch);
        }
    }
    /* The result: the drawn roots' subtrees, down to the unrefined nodes. */
    while (top > 0) {
        tclod_id v = sel->stack[--top];
        if (!(bl_benefit(sel, v) > 0.0))
            continue;
        if (sel->refined[v] == sel->frame) {
            uint32_t c;
            for (c = b->child_first[v + 1u]; c-- > b->child_first[v];)
                sel->stack[top++] = b->children[c];
        } else {
            sel->ids[n++] = v;
        }
    }
    bl_finish(sel, n, r);
    r->iterations = pops;
    r->refinements = refinements;
    r->bias = 0.0;
    return 0;
}

/* ---- flat per-object greedy ----------------------------------------------------- */

/* Benefit gained per cost of an object's next level; +inf when it saves cost. */
static double bl_step_key(double db, double dc) {
    return dc > 0.0 ? db / dc : HUGE_VAL;
}

/* Queues the step of object o from its current level, when it gains and can be paid. */
static void bl_flat_queue(baseline_selector *sel, uint32_t o) {
    const baseline_scene *b = sel->scene;
    tclod_id cur = sel->level[o], next;
    double db, dc;
    if (b->child_first[cur + 1u] == b->child_first[cur])
        return;
    next = b->children[b->child_first[cur]];
    db = bl_benefit(sel, next) - bl_benefit(sel, cur);
    if (!(db > 0.0))
        return;
    dc = bl_cost(sel, next) - bl_cost(sel, cur);
    if (isinf(dc))
        return;
    bl_push(sel, bl_step_key(db, dc), (tclod_id)o);
}

int baseline_flat(baseline_selector *sel, const tclod_view *view, double budget,
                  baseline_result *r) {
    const baseline_scene *b = sel->scene;
    double cost = 0.0;
    uint32_t o, pops = 0, steps = 0;
    size_t n = 0;
    if (b->object_count == 0)
        return -1;
    bl_begin(sel, view);
    sel->heap_n = 0;
    /* Every object in view at its level 0, by value (benefit per cost) while they fit. */
    for (o = 0; o < b->object_count; ++o) {
        tclod_id root = b->objects[o];
        sel->level[o] = TCLOD_NONE;
        if (bl_benefit(sel, root) > 0.0)
            bl_push(sel, bl_step_key(bl_benefit(sel, root), bl_cost(sel, root)), (tclod_id)o);
    }
    while (sel->heap_n > 0) {
        baseline_entry e = bl_pop(sel);
        tclod_id root = b->objects[e.id];
        if (cost + bl_cost(sel, root) <= budget) {
            cost += bl_cost(sel, root);
            sel->level[e.id] = root;
        }
    }
    for (o = 0; o < b->object_count; ++o)
        if (sel->level[o] != TCLOD_NONE)
            bl_flat_queue(sel, o);
    /* Level steps, best gain per cost first; a step that does not fit is skipped. */
    while (sel->heap_n > 0) {
        baseline_entry e = bl_pop(sel);
        tclod_id cur = sel->level[e.id], next = b->children[b->child_first[cur]];
        double dc = bl_cost(sel, next) - bl_cost(sel, cur);
        pops++;
        if (cost + dc > budget)
            continue;
        cost += dc;
        sel->level[e.id] = next;
        steps++;
        bl_flat_queue(sel, e.id);
    }
    for (o = 0; o < b->object_count; ++o)
        if (sel->level[o] != TCLOD_NONE)
            sel->ids[n++] = sel->level[o];
    bl_finish(sel, n, r);
    r->iterations = pops;
    r->refinements = steps;
    r->bias = 0.0;
    return 0;
}

void baseline_values(baseline_selector *sel, const tclod_view *view, double *benefit,
                     double *cost) {
    uint32_t n;
    bl_begin(sel, view);
    for (n = 0; n < sel->scene->count; ++n) {
        benefit[n] = bl_benefit(sel, n);
        cost[n] = bl_cost(sel, n);
    }
}

uint32_t baseline_count_holes(baseline_selector *sel, const double *benefit, const tclod_id *ids,
                              size_t n) {
    const baseline_scene *b = sel->scene;
    uint32_t r, holes = 0;
    size_t i;
    if (++sel->listed_stamp == 0u) {
        memset(sel->listed, 0, (size_t)b->count * sizeof *sel->listed);
        sel->listed_stamp = 1u;
    }
    for (i = 0; i < n; ++i)
        sel->listed[ids[i]] = sel->listed_stamp;
    for (r = 0; r < b->root_count; ++r) {
        size_t top = 0;
        int hole = 0;
        sel->stack[top++] = b->roots[r];
        while (top > 0 && !hole) {
            tclod_id v = sel->stack[--top];
            uint32_t c, first = b->child_first[v], end = b->child_first[v + 1u];
            if (!(benefit[v] > 0.0) || sel->listed[v] == sel->listed_stamp)
                continue;
            if (first == end)
                hole = 1;
            for (c = first; c < end; ++c)
                sel->stack[top++] = b->children[c];
        }
        holes += (uint32_t)hole;
    }
    return holes;
}
