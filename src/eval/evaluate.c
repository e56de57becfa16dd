/*
 * Batch evaluation: the nodes a solver needs together (a warm start's
 * frontier, the children of what an increment adds) are gathered into a
 * list, projected in plain loops over arrays, and asked for in batches: the
 * host's batch callbacks when it gave them, else its per-node ones in a loop.
 * With the host's task system (tclod_tasks) the list is split over its
 * workers. Every node gets the values the per-node path gives it (the same
 * arithmetic, sanitised the same way), so selections are bit-identical
 * whichever way they were asked for (docs/api.md, batch evaluation).
 *
 * Layer: eval, which may call core and eval. Calls: core (alloc.c, view.c).
 */
#include "evaluate.h"

#include <math.h>
#include <string.h>

/* ---- the workspace ------------------------------------------------------------ */

static uint32_t batch_slots(const tclod_selector *sel) {
    return sel->desc.tasks.worker_count > 1u ? sel->desc.tasks.worker_count : 1u;
}

static size_t batch_bytes(const tclod_selector *sel) {
    return sizeof(tclod_batch_worker) * batch_slots(sel) + sizeof(tclod_id) * TCLOD_GATHER +
           TCLOD_GATHER;
}

tclod_status tclod_batch_create(tclod_selector *sel) {
    unsigned char *mem;
    uint32_t i;
    sel->gather_count = 0;
    sel->batching = sel->desc.callbacks.benefit_batch || sel->desc.callbacks.cost_batch ||
                    sel->desc.tasks.worker_count > 1u;
    if (!sel->batching) /* the greedy gathers nothing: no workspace */
        return TCLOD_OK;
    mem = (unsigned char *)tclod_mem_alloc(&sel->alloc, batch_bytes(sel));
    if (!mem)
        return TCLOD_ERR_NOMEM;
    sel->workers = (tclod_batch_worker *)(void *)mem;
    sel->gather = (tclod_id *)(void *)(mem + sizeof(tclod_batch_worker) * batch_slots(sel));
    sel->gathered_done = (unsigned char *)(sel->gather + TCLOD_GATHER);
    for (i = 0; i < batch_slots(sel); ++i) {
        memset(&sel->workers[i].query, 0, sizeof sel->workers[i].query);
        sel->workers[i].query.count = 1;
    }
    return TCLOD_OK;
}

void tclod_batch_destroy(tclod_selector *sel) {
    if (sel->workers)
        tclod_mem_free(&sel->alloc, sel->workers, batch_bytes(sel));
    sel->workers = NULL;
    sel->gather = NULL;
    sel->gathered_done = NULL;
}

/* ---- projection ---------------------------------------------------------------- */

/* Screen area and distance of the m nodes ids[] into area[] and dist[], as
 * tclod_view_measure_bounds gives them (-1 and -1 without bounds or view).
 * Spheres go through a loop over arrays with no branch, which compilers
 * vectorise (GCC once -fno-trapping-math lets it compute both sides of the
 * loop's selects); boxes and nodes without bounds are measured after it. */
static void batch_measure(const tclod_selector *sel, tclod_batch_worker *w, const tclod_id *ids,
                          uint32_t m) {
    const tclod_view_cache *c = &sel->view;
    const tclod_scene *s = sel->scene;
    const tclod_node_bounds *bounds = s->bounds;
    const tclod_node_state *node = sel->node;
    double *px = w->px, *py = w->py, *pz = w->pz, *pr = w->pr;
    float *area = w->area, *dist = w->dist, *pa = w->varea, *pd = w->vdist;
    tclod_id *at = w->vis;
    uint32_t i, k = 0, special = m;
    if (!sel->has_view) {
        for (i = 0; i < m; ++i)
            area[i] = dist[i] = -1.0f;
        return;
    }
    /* a node with its parent's bounds takes the parent's figures (the levels
     * of one object usually share their bounds): no gathered node's parent
     * is gathered in the same flush, so a parent of this solve is measured.
     * Spheres fill at[] from the front, boxes and nodes without bounds from
     * the back */
    for (i = 0; i < m; ++i) {
        const tclod_node_bounds *b = &bounds[ids[i]];
        tclod_id p = s->parent[ids[i]];
        if (p != TCLOD_NONE && node[p].stamp == sel->solve_id &&
            memcmp(b, &bounds[p], sizeof *b) == 0) {
            area[i] = node[p].area;
            dist[i] = node[p].distance;
            continue;
        }
        if (b->r < 0.0 || b->box != TCLOD_NONE) {
            at[--special] = i;
            continue;
        }
        at[k] = i;
        px[k] = b->c[0] - c->eye[0];
        py[k] = b->c[1] - c->eye[1];
        pz[k] = b->c[2] - c->eye[2];
        pr[k] = b->r;
        ++k;
    }
    /* vectorised: CI checks that GCC and Clang at -O3 report this loop */
    for (i = 0; i < k; ++i) {
        double x = px[i], y = py[i], z0 = pz[i], r = pr[i];
        double d2 = x * x + y * y + z0 * z0, r2 = r * r;
        double z = x * c->forward[0] + y * c->forward[1] + z0 * c->forward[2];
        double u = fabs(x * c->up[0] + y * c->up[1] + z0 * c->up[2]) * c->cos_y - z * c->sin_y;
        double v =
            fabs(x * c->right[0] + y * c->right[1] + z0 * c->right[2]) * c->cos_x - z * c->sin_x;
        int seen = !(z < c->near_z - r) & !(z > c->far_z + r) & !(u > r) & (v <= r);
        int inside = d2 <= r2;
        double a = c->pi_focal2 * r2 / (inside ? 1.0 : d2 - r2);
        double d = sqrt(d2) - r;
        a = inside ? c->viewport_area : (a < c->viewport_area ? a : c->viewport_area);
        pa[i] = seen ? (float)a : 0.0f;
        pd[i] = (float)(d > 0.0 ? d : 0.0);
    }
    for (i = 0; i < k; ++i) {
        area[at[i]] = pa[i];
        dist[at[i]] = pd[i];
    }
    for (i = special; i < m; ++i) {
        const tclod_node_bounds *b = &bounds[ids[at[i]]];
        if (b->r < 0.0) {
            area[at[i]] = dist[at[i]] = -1.0f;
        } else {
            double p[3], d;
            p[0] = b->c[0] - c->eye[0];
            p[1] = b->c[1] - c->eye[1];
            p[2] = b->c[2] - c->eye[2];
            tclod_view_cache_measure_box(c, p, &s->boxes[b->box], &area[at[i]], &d);
            dist[at[i]] = (float)d;
        }
    }
}

/* ---- the callbacks ---------------------------------------------------------------- */

/* The per-node query of node n into w->query. */
static void batch_query(const tclod_selector *sel, tclod_batch_worker *w, tclod_id n, float area,
                        float dist) {
    tclod_query *q = &w->query;
    q->id = n;
    q->view = sel->query.view;
    q->screen_area = area;
    q->distance = dist;
    if (sel->scene->bounds[n].r >= 0.0) {
        tclod_node_public_bounds(sel->scene, n, &w->qbounds);
        q->bounds = &w->qbounds;
    } else {
        q->bounds = NULL;
    }
}

/* Asks benefit (cost: 0) or cost (1) of the m nodes ids[] into out[]. */
static void batch_ask(const tclod_selector *sel, tclod_batch_worker *w, uint32_t worker, int cost,
                      const tclod_id *ids, const float *area, const float *dist, uint32_t m,
                      double *out) {
    const tclod_callbacks *cb = &sel->desc.callbacks;
    void (*batch)(void *, const tclod_batch *, double *) =
        cost ? cb->cost_batch : cb->benefit_batch;
    uint32_t i;
    if (batch && !(cost && cb->features)) { /* features are asked node by node */
        tclod_batch b;
        b.count = m;
        b.ids = ids;
        b.screen_area = area;
        b.distance = dist;
        b.view = sel->query.view;
        b.worker = worker;
        for (i = 0; i < m; ++i) /* what the callback leaves unwritten is a bad value */
            out[i] = (double)NAN;
        batch(cb->user, &b, out);
        return;
    }
    for (i = 0; i < m; ++i) {
        batch_query(sel, w, ids[i], area[i], dist[i]);
        out[i] = cost ? tclod_node_cost(sel, &w->query) : cb->benefit(cb->user, &w->query);
    }
}

/* A benefit as tclod_evaluate_invisible and tclod_evaluate_bounded keep it:
 * 1 when the node is visible; a bad value counts and gives 0. */
static int batch_benefit(tclod_batch_worker *w, tclod_node_state *st, double b) {
    if (tclod_bits(b) - 1u >= TCLOD_BITS_MAX) { /* not positive and finite */
        if (!(b >= 0.0 && b < HUGE_VAL)) {
            w->invalid++;
            b = 0.0;
        }
        st->benefit = b;
        st->cost = 0.0;
        return 0;
    }
    st->benefit = b;
    return 1;
}

/* A visible node's cost as tclod_evaluate_bad_cost keeps it: a bad value
 * counts and gives +inf (-0 passes); a node not resident is counted for the
 * flush, which calls tclod_evaluate_absent. */
static void batch_cost(const tclod_selector *sel, tclod_batch_worker *w, tclod_id n, double c) {
    if (tclod_bits(c) > TCLOD_BITS_MAX && !(c >= 0.0 && c < HUGE_VAL)) {
        w->invalid++;
        c = HUGE_VAL;
    }
    sel->node[n].cost = c;
    if (TCLOD_UNLIKELY(tclod_scene_streams(sel->scene)) &&
        (sel->scene->flags[n] & TCLOD_NODE_ABSENT))
        w->absent++;
}

/* Evaluates the m (<= TCLOD_BATCH_CHUNK) nodes ids[] into their records. */
static void batch_chunk(tclod_selector *sel, tclod_batch_worker *w, uint32_t worker,
                        const tclod_id *ids, uint32_t m) {
    const tclod_callbacks *cb = &sel->desc.callbacks;
    tclod_node_state *node = sel->node;
    uint32_t i, v = 0;
    batch_measure(sel, w, ids, m);
    for (i = 0; i < m; ++i) {
        node[ids[i]].area = w->area[i];
        node[ids[i]].distance = w->dist[i];
    }
    if (!cb->benefit_batch && !cb->cost_batch) { /* per node, one query for both */
        for (i = 0; i < m; ++i) {
            batch_query(sel, w, ids[i], w->area[i], w->dist[i]);
            if (batch_benefit(w, &node[ids[i]], cb->benefit(cb->user, &w->query)))
                batch_cost(sel, w, ids[i], tclod_node_cost(sel, &w->query));
        }
        return;
    }
    batch_ask(sel, w, worker, 0, ids, w->area, w->dist, m, w->benefit);
    for (i = 0; i < m; ++i) {
        if (!batch_benefit(w, &node[ids[i]], w->benefit[i]))
            continue;
        w->vis[v] = ids[i];
        w->varea[v] = w->area[i];
        w->vdist[v] = w->dist[i];
        ++v;
    }
    if (v == 0)
        return;
    batch_ask(sel, w, worker, 1, w->vis, w->varea, w->vdist, v, w->cost);
    for (i = 0; i < v; ++i)
        batch_cost(sel, w, w->vis[i], w->cost[i]);
}

/* Evaluates gathered nodes [start, end) on worker `worker`. */
static void batch_range(tclod_selector *sel, uint32_t worker, uint32_t start, uint32_t end) {
    tclod_batch_worker *w = &sel->workers[worker];
    while (start < end) {
        uint32_t m = end - start < TCLOD_BATCH_CHUNK ? end - start : TCLOD_BATCH_CHUNK;
        batch_chunk(sel, w, worker, sel->gather + start, m);
        start += m;
    }
}

/* The first index in [i, end) whose mark is `mark` (0 or 1), or end. */
static uint32_t next_mark(const unsigned char *done, uint32_t i, uint32_t end, int mark) {
    const unsigned char *at = (const unsigned char *)memchr(done + i, mark, end - i);
    return at ? (uint32_t)(at - done) : end;
}

/* The task: gathered nodes [start, end) on worker `worker`, each marked done
 * as it is evaluated. A task system that breaks its contract changes nothing
 * it can be seen to: nodes a range run before this one marked (a range run
 * twice, or overlapping another, one after the other) are not evaluated
 * again (counted in the worker's `repeated`); a range with a worker index
 * beyond the selector's workers is left undone (it has no scratch of its
 * own), and the flush evaluates it after the task. */
static void batch_task(uint32_t start, uint32_t end, uint32_t worker, void *ctx) {
    tclod_selector *sel = (tclod_selector *)ctx;
    unsigned char *done = sel->gathered_done;
    if (worker >= batch_slots(sel) || start >= end || end > sel->gather_count)
        return;
    while (start < end) {
        uint32_t first = next_mark(done, start, end, 0), stop;
        if (first != start) /* a sound task system never stores here */
            sel->workers[worker].repeated += first - start;
        if (first == end)
            break;
        stop = next_mark(done, first, end, 1);
        memset(done + first, 1, stop - first);
        batch_range(sel, worker, first, stop);
        start = stop;
    }
}

/* After the host's task: the gathered nodes no range evaluated (a task
 * system that skipped a range or gave a worker index out of range),
 * evaluated here on the calling thread, as worker 0 (docs/api.md, worker
 * threads). Returns how many there were. */
static uint32_t batch_missed(tclod_selector *sel, uint32_t n) {
    uint32_t i = 0, missed = 0;
    while ((i = next_mark(sel->gathered_done, i, n, 0)) < n) {
        uint32_t end = next_mark(sel->gathered_done, i, n, 1);
        batch_range(sel, 0u, i, end);
        missed += end - i;
        i = end;
    }
    return missed;
}

int tclod_batch_flush(tclod_selector *sel) {
    const tclod_tasks *T = &sel->desc.tasks;
    uint32_t n = sel->gather_count, slots = batch_slots(sel), i, invalid = 0, absent = 0;
    if (n == 0) /* also every flush of a selector without the workspace */
        return 0;
    for (i = 0; i < slots; ++i)
        sel->workers[i].invalid = sel->workers[i].absent = sel->workers[i].repeated = 0;
    if (slots > 1u && n >= 2u * TCLOD_BATCH_CHUNK) {
        void *task;
        uint32_t repeated = 0;
        memset(sel->gathered_done, 0, n);
        task = T->enqueue(batch_task, n, TCLOD_BATCH_CHUNK, sel, T->user);
        if (task)
            T->finish(task, T->user);
        if (batch_missed(sel, n) != 0)
            sel->stats.notes |= TCLOD_NOTE_TASKS_MISSED;
        for (i = 0; i < slots; ++i)
            repeated += sel->workers[i].repeated;
        if (repeated != 0)
            sel->stats.notes |= TCLOD_NOTE_TASKS_REPEATED;
    } else {
        batch_range(sel, 0u, 0u, n);
    }
    sel->gather_count = 0;
    sel->stats.evaluations += n;
    for (i = 0; i < slots; ++i) {
        invalid += sel->workers[i].invalid;
        absent += sel->workers[i].absent;
    }
    if (invalid) {
        sel->stats.invalid_values += invalid;
        if (sel->desc.strict)
            sel->failed = 1;
    }
    if (sel->failed)
        return -1;
    for (i = 0; absent && i < n; ++i) { /* in gathered order, as the per-node path */
        tclod_id id = sel->gather[i];
        const tclod_node_state *st = &sel->node[id];
        if (st->benefit > 0.0 && (sel->scene->flags[id] & TCLOD_NODE_ABSENT)) {
            tclod_evaluate_absent(sel, id);
            absent--;
        }
    }
    return 0;
}

/* ---- one node, out of line ---------------------------------------------------- */

int tclod_evaluate_self(tclod_selector *sel, tclod_id n) {
    tclod_id owner = sel->scene->up[n];
    tclod_node_state *st = &sel->node[n];
    const tclod_node_state *o = &sel->node[owner];
    tclod_query *q = &sel->query;
    if (o->stamp != sel->solve_id && tclod_evaluate_fresh(sel, owner) < 0)
        return -1;
    st->stamp = sel->solve_id;
    st->benefit = o->benefit;
    st->cost = o->cost;
    st->area = o->area;
    st->distance = o->distance;
    q->id = owner;
    q->screen_area = o->area;
    q->distance = o->distance;
    q->bounds = sel->scene->bounds[owner].r >= 0.0 ? tclod_query_bounds(sel, owner) : NULL;
    return o->benefit > 0.0;
}

int tclod_evaluate_bad_cost(tclod_selector *sel, tclod_node_state *st, double c) {
    tclod_id n = (tclod_id)(st - sel->node); /* st is node n's record */
    if (!(c >= 0.0 && c < HUGE_VAL)) {       /* NaN, infinite or negative; -0 passes */
        tclod_bad_value(sel);
        c = HUGE_VAL;
    }
    st->cost = c;
    if (sel->failed)
        return -1;
    if (tclod_scene_streams(sel->scene) && (sel->scene->flags[n] & TCLOD_NODE_ABSENT))
        return tclod_evaluate_absent(sel, n);
    return 1;
}

int tclod_evaluate_absent(tclod_selector *sel, tclod_id n) {
    const tclod_scene *s = sel->scene;
    tclod_stream_state *S = &sel->stream;
    tclod_node_state *st = &sel->node[n];
    tclod_id p = s->parent[n];
    S->absent_seen++;
    if (S->seen && n < S->cap) {
        S->seen[n] = sel->solve_id;
        S->benefit[n] = st->benefit;
        S->cost[n] = st->cost;
    }
    if (p == TCLOD_NONE || (s->flags[p] & TCLOD_NODE_ADD)) {
        if (p == TCLOD_NONE)
            sel->stats.absent_roots++;
        st->benefit = 0.0;
        st->cost = 0.0;
        return 0;
    }
    st->cost = HUGE_VAL;
    return 1;
}

int tclod_out_of_time(tclod_selector *sel) {
    const tclod_frame *f = sel->frame;
    uint32_t it = sel->stats.iterations;
    int read_clock = it % TCLOD_CLOCK_STRIDE == 0;
    double now = 0.0;
    if (sel->stopped)
        return 1;
    if (f->max_iterations && it >= f->max_iterations) {
        sel->stats.stop_reason = TCLOD_STOP_ITERATIONS;
        sel->stopped = 1;
        return 1;
    }
    if (read_clock && (f->solve_seconds > 0.0 || sel->slice_end > 0.0))
        now = tclod_now();
    if (read_clock && f->solve_seconds > 0.0 &&
        sel->elapsed + (now - sel->start_time) >= f->solve_seconds) {
        sel->stats.stop_reason = TCLOD_STOP_TIME;
        sel->stopped = 1;
        return 1;
    }
    /* a step makes at least one iteration, so that steps always progress */
    if (it != sel->step_start && ((sel->slice_iterations && it >= sel->slice_iterations) ||
                                  (read_clock && sel->slice_end > 0.0 && now >= sel->slice_end))) {
        sel->paused = 1;
        return 1;
    }
    return 0;
}

/* ---- smooth objects ------------------------------------------------------------- */

int tclod_smooth_call(tclod_selector *sel, uint32_t first, uint32_t count, const float *bounds,
                      float area, float distance, double x, double *b, double *db, double *c,
                      double *dc) {
    return tclod_smooth_call_inline(sel, first, count, bounds, area, distance, x, b, db, c, dc);
}

/* ---- costs from features ------------------------------------------------ */

/* Whether a feature is a valid count: finite and >= 0 (-0 passes). */
static int feature_valid(double f) {
    return f >= 0.0 && f < HUGE_VAL;
}

double tclod_feature_cost(const tclod_selector *sel, const tclod_query *q) {
    const tclod_callbacks *cb = &sel->desc.callbacks;
    const double *coef = sel->desc.coefficients;
    double f[TCLOD_MAX_FEATURES], c = 0.0;
    uint32_t i, n = sel->desc.feature_count;
    for (i = 0; i < n; ++i) /* what the callback leaves unwritten is a bad value */
        f[i] = (double)NAN;
    cb->features(cb->user, q, f);
    if (cb->cost) {
        c = cb->cost(cb->user, q);
        if (!feature_valid(c))
            return (double)NAN;
    }
    for (i = 0; i < n; ++i) {
        if (!feature_valid(f[i]))
            return (double)NAN;
        c += coef[i] * f[i];
    }
    return c; /* +inf when the sum overflows: a bad cost too */
}

double tclod_feature_smooth_cost(const tclod_selector *sel, const tclod_query *q, double r,
                                 double *d_dr) {
    const tclod_callbacks *cb = &sel->desc.callbacks;
    const double *coef = sel->desc.coefficients;
    double f[TCLOD_MAX_FEATURES], df[TCLOD_MAX_FEATURES], c = 0.0, d = 0.0;
    uint32_t i, n = sel->desc.feature_count;
    for (i = 0; i < n; ++i)
        f[i] = df[i] = (double)NAN;
    cb->smooth_features(cb->user, q, r, f, df);
    if (cb->smooth_cost) {
        c = cb->smooth_cost(cb->user, q, r, &d);
        if (!feature_valid(c))
            return (double)NAN;
    }
    for (i = 0; i < n; ++i) {
        if (!feature_valid(f[i]))
            return (double)NAN;
        c += coef[i] * f[i];
        /* a bad slope spoils only the slope, as a bad d/dr of smooth_cost does */
        d = feature_valid(df[i]) && feature_valid(d) ? d + coef[i] * df[i] : (double)NAN;
    }
    *d_dr = d;
    return c;
}
