/*
 * Selector: the public entry points around the solvers.
 *
 * tclod_select validates its arguments before touching anything, grows the
 * per-node buffers to the scene's size (the only allocations, all or nothing),
 * runs the solver on a working cut and then either commits it as the new result
 * or, on a strict-mode callback error, rolls the working cut back to the
 * committed one, so the previous result stays readable and warm starts stay
 * valid. A busy flag refuses re-entry from the host's callbacks.
 *
 * Layer: select, which may call core, eval, solve, plan and select. Calls: core
 * (alloc.c, scene.c, scene_prepare.c, view.c); eval (evaluate.c); solve
 * (greedy, mixed_solve.c, robin_hood.c); plan (stream.c).
 */
#include "selector.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

const char *tclod_status_string(tclod_status s) {
    switch (s) {
    case TCLOD_OK:
        return "ok";
    case TCLOD_ERR_ARG:
        return "invalid argument";
    case TCLOD_ERR_NOMEM:
        return "out of memory";
    case TCLOD_ERR_HIERARCHY:
        return "invalid hierarchy";
    case TCLOD_ERR_CALLBACK:
        return "callback returned an invalid value";
    case TCLOD_ERR_STATE:
        return "call out of order or re-entered";
    }
    return "unknown status";
}

unsigned tclod_version(void) {
    return (unsigned)TCLOD_VERSION_NUMBER;
}

#define TCLOD_STR2(x) #x
#define TCLOD_STR(x) TCLOD_STR2(x)

const char *tclod_version_string(void) {
    return TCLOD_STR(TCLOD_VERSION_MAJOR) "." TCLOD_STR(TCLOD_VERSION_MINOR) "." TCLOD_STR(
        TCLOD_VERSION_PATCH);
}

void tclod_selector_desc_default(tclod_selector_desc *d) {
    if (!d)
        return;
    memset(d, 0, sizeof *d);
    d->solver = TCLOD_SOLVER_GREEDY;
    d->smooth_cull_area = 1.0;
    d->greedy.restarts = 32;
    d->mixed.split_threshold = 0.1;
    d->mixed.smooth_epsilon = 1e-3;
    d->mixed.smooth_tolerance = 0.05;
    d->robin_hood.value = TCLOD_VALUE_AREA_SQRT_DEPTH;
    d->robin_hood.misfit = TCLOD_MISFIT_DROP;
    d->robin_hood.reference_area = 10000.0;
}

/* An on/off field of a description: exactly 0 or 1. */
static int flag(int v) {
    return v == 0 || v == 1;
}

/* A real field whose 0 means the default: 0, TCLOD_OFF, or finite in (lo, hi). */
static int defaulted(double v, double lo, double hi) {
    return v == 0.0 || v == (double)TCLOD_OFF || (v > lo && v < hi);
}

/* A defaulted field's value: def for 0, 0 for TCLOD_OFF. */
static double resolve(double v, double def) {
    return v == 0.0 ? def : (v < 0.0 ? 0.0 : v);
}

/* The first of the n coefficients that is NaN, infinite or negative (-0
 * passes), or -1. */
static int coefficient_bad(const double *c, uint32_t n) {
    uint32_t i;
    for (i = 0; i < n; ++i)
        if (!(c[i] >= 0.0 && c[i] < HUGE_VAL))
            return (int)i;
    return -1;
}

const char *tclod_selector_desc_check(const tclod_scene *s, const tclod_selector_desc *d) {
    if (!d)
        return "desc is NULL";
    if ((unsigned)d->solver > (unsigned)TCLOD_SOLVER_ROBIN_HOOD)
        return "desc.solver is not a tclod_solver";
    if (!d->callbacks.benefit)
        return "desc.callbacks.benefit is NULL";
    if (!d->callbacks.cost && !d->callbacks.features)
        return "desc.callbacks.cost and features are NULL: one of them prices the nodes";
    if (d->solver == TCLOD_SOLVER_MIXED && s && s->smooth_live > 0 &&
        (!d->callbacks.smooth_benefit || !tclod_smooth_priced(&d->callbacks)))
        return "desc.callbacks.smooth_benefit and smooth_cost are NULL: the mixed solver "
               "needs both on a scene with smooth objects";
    if (d->feature_count > TCLOD_MAX_FEATURES)
        return "desc.feature_count must be at most TCLOD_MAX_FEATURES (8)";
    if ((d->callbacks.features || d->callbacks.smooth_features) && d->feature_count == 0)
        return "desc.feature_count is 0 but callbacks.features or smooth_features is set";
    if (d->feature_count > 0 && !d->callbacks.features && !d->callbacks.smooth_features)
        return "desc.feature_count is set but callbacks.features and smooth_features are NULL";
    if (d->feature_count > 0 && !d->callbacks.features && !d->callbacks.cost)
        return "desc.callbacks.cost and features are NULL: one of them prices the nodes";
    if (coefficient_bad(d->coefficients, d->feature_count) >= 0)
        return "desc.coefficients: each of the first feature_count must be finite and >= 0";
    if (!flag(d->cold_start))
        return "desc.cold_start must be 0 or 1";
    if (!flag(d->strict))
        return "desc.strict must be 0 or 1";
    if ((unsigned)d->overflow > (unsigned)TCLOD_OVERFLOW_DRAW_ROOTS)
        return "desc.overflow is not a tclod_overflow";
    if (!defaulted(d->smooth_cull_area, 0.0, HUGE_VAL))
        return "desc.smooth_cull_area must be finite and > 0, 0 (default) or TCLOD_OFF";
    if (d->greedy.lookahead > TCLOD_MAX_LOOKAHEAD)
        return "desc.greedy.lookahead must be at most TCLOD_MAX_LOOKAHEAD (63)";
    if (d->greedy.restarts != TCLOD_OFF &&
        (d->greedy.restarts < 0 || d->greedy.restarts > TCLOD_MAX_RESTARTS))
        return "desc.greedy.restarts must be 0 (default), TCLOD_OFF or 1 .. "
               "TCLOD_MAX_RESTARTS (256)";
    if (d->greedy.fallback != 0 && d->greedy.fallback != 1 && d->greedy.fallback != TCLOD_OFF)
        return "desc.greedy.fallback must be 0 (default), 1 or TCLOD_OFF";
    if (!flag(d->mixed.split_smooth))
        return "desc.mixed.split_smooth must be 0 or 1";
    if (!defaulted(d->mixed.split_threshold, 0.0, HUGE_VAL))
        return "desc.mixed.split_threshold must be finite and > 0, 0 (default) or TCLOD_OFF";
    if (!flag(d->mixed.plain_gradient))
        return "desc.mixed.plain_gradient must be 0 or 1";
    if (!defaulted(d->mixed.smooth_epsilon, 0.0, 1.0))
        return "desc.mixed.smooth_epsilon must be in (0, 1), 0 (default) or TCLOD_OFF";
    if (!defaulted(d->mixed.smooth_tolerance, 0.0, 1.0))
        return "desc.mixed.smooth_tolerance must be in (0, 1), 0 (default) or TCLOD_OFF";
    if ((unsigned)d->robin_hood.value > (unsigned)TCLOD_VALUE_BENEFIT)
        return "desc.robin_hood.value is not a tclod_value";
    if ((unsigned)d->robin_hood.misfit > (unsigned)TCLOD_MISFIT_COARSEST)
        return "desc.robin_hood.misfit is not a tclod_misfit";
    if (!(d->robin_hood.reference_area == 0.0 ||
          (d->robin_hood.reference_area > 0.0 && d->robin_hood.reference_area < HUGE_VAL)))
        return "desc.robin_hood.reference_area must be finite and > 0, or 0 (default)";
    if (d->tasks.worker_count > TCLOD_MAX_WORKERS)
        return "desc.tasks.worker_count must be at most TCLOD_MAX_WORKERS (64)";
    if (d->tasks.worker_count > 1u && (!d->tasks.enqueue || !d->tasks.finish))
        return "desc.tasks.enqueue and finish must be set when worker_count > 1";
    return NULL;
}

/* A valid desc with its defaults filled in: what the solvers read. */
static tclod_selector_desc selector_resolved(const tclod_selector_desc *d) {
    tclod_selector_desc r = *d;
    r.smooth_cull_area = resolve(d->smooth_cull_area, 1.0);
    r.greedy.restarts =
        d->greedy.restarts == 0 ? 32 : (d->greedy.restarts < 0 ? 0 : d->greedy.restarts);
    r.mixed.split_threshold = resolve(d->mixed.split_threshold, 0.1);
    r.mixed.smooth_epsilon = resolve(d->mixed.smooth_epsilon, 1e-3);
    r.mixed.smooth_tolerance = resolve(d->mixed.smooth_tolerance, 0.05);
    r.robin_hood.reference_area = resolve(d->robin_hood.reference_area, 10000.0);
    return r;
}

/* Every per-node buffer of a selector, for growing and freeing them together:
 * the common ones and the greedy's (which the mixed solver runs too). Node
 * records are filled with 0xff bytes: no cut or heap slot (TCLOD_NONE), and a
 * stamp no solve uses. */
static size_t node_buffers(tclod_selector *sel, tclod_array out[TCLOD_MAX_ARRAYS]) {
    size_t n = 0;
    out[n++] = (tclod_array){(void **)&sel->node, sizeof(tclod_node_state), 0xff};
    out[n++] = (tclod_array){(void **)&sel->path, 2 * sizeof(double), 0};
    out[n++] = (tclod_array){(void **)&sel->flags, sizeof(uint8_t), 0};
    out[n++] = (tclod_array){(void **)&sel->cut, sizeof(tclod_id), -1};
    out[n++] = (tclod_array){(void **)&sel->prev_cut, sizeof(tclod_id), -1};
    out[n++] = (tclod_array){(void **)&sel->result, sizeof(tclod_id), -1};
    out[n++] = (tclod_array){(void **)&sel->scratch, sizeof(tclod_id), -1};
    out[n++] = (tclod_array){(void **)&sel->scratch_key, sizeof(double), -1};
    return n + tclod_greedy_buffers(&sel->greedy, out + n);
}

/* The result as the host's ids: only while the scene has self leaves (or had). */
static size_t drawn_buffers(tclod_selector *sel, tclod_array out[TCLOD_MAX_ARRAYS]) {
    out[0] = (tclod_array){(void **)&sel->drawn, sizeof(tclod_id), -1};
    return 1;
}

/* Every per-smooth-object buffer: the mixed solver's and the committed
 * groups. */
static size_t smooth_buffers(tclod_selector *sel, tclod_array out[TCLOD_MAX_ARRAYS]) {
    size_t n = tclod_mixed_buffers(&sel->mixed, out);
    out[n++] = (tclod_array){(void **)&sel->groups, sizeof(tclod_smooth_group), -1};
    return n;
}

tclod_status tclod_selector_create(const tclod_scene *s, const tclod_selector_desc *d,
                                   const tclod_allocator *a, tclod_selector **out) {
    tclod_allocator alloc;
    tclod_selector *sel;
    if (!s || !d || !out || !tclod_allocator_init(&alloc, a))
        return TCLOD_ERR_ARG;
    if (tclod_selector_desc_check(s, d))
        return TCLOD_ERR_ARG;
    sel = (tclod_selector *)tclod_mem_alloc(&alloc, sizeof *sel);
    if (!sel)
        return TCLOD_ERR_NOMEM;
    memset(sel, 0, sizeof *sel);
    /* the scene is only written through its lazy child index and its list of
     * users */
    sel->scene = (tclod_scene *)(uintptr_t)s;
    sel->alloc = alloc;
    sel->desc = selector_resolved(d);
    sel->holds = 1;
    if (tclod_batch_create(sel) != TCLOD_OK) {
        tclod_mem_free(&alloc, sel, sizeof *sel);
        return TCLOD_ERR_NOMEM;
    }
    if (tclod_scene_attach(sel->scene, &sel->user, d->solver == TCLOD_SOLVER_ROBIN_HOOD) !=
        TCLOD_OK) {
        tclod_batch_destroy(sel);
        tclod_mem_free(&alloc, sel, sizeof *sel);
        return TCLOD_ERR_NOMEM;
    }
    *out = sel;
    return TCLOD_OK;
}

void tclod_selector_destroy(tclod_selector *sel) {
    tclod_array buffers[TCLOD_MAX_ARRAYS];
    tclod_allocator alloc;
    if (!sel || sel->busy)
        return;
    alloc = sel->alloc;
    tclod_scene_detach(sel->scene, &sel->user, sel->desc.solver == TCLOD_SOLVER_ROBIN_HOOD);
    tclod_batch_destroy(sel);
    tclod_arrays_free(&alloc, buffers, node_buffers(sel, buffers), sel->cap);
    tclod_arrays_free(&alloc, buffers, drawn_buffers(sel, buffers), sel->drawn_cap);
    tclod_arrays_free(&alloc, buffers, smooth_buffers(sel, buffers), sel->smooth_cap);
    tclod_arrays_free(&alloc, buffers, tclod_rh_buffers(&sel->rh, buffers), sel->rh.cap);
    tclod_arrays_free(&alloc, buffers, tclod_stream_buffers(&sel->stream, buffers),
                      sel->stream.cap);
    tclod_mem_free(&alloc, sel, sizeof *sel);
}

/* The capacity a block grows to from cap for need elements (need > cap): the
 * first time need and a 32nd more (a scene edited between frames takes a few
 * new ids before the removed ones are given again), else half as much again,
 * so that a scene that keeps growing costs amortised constant copying. */
static uint32_t grown(uint32_t cap, uint32_t need) {
    uint32_t base = cap == 0 ? need : cap, more = cap == 0 ? need / 32u : cap / 2u;
    more = base > UINT32_MAX - more ? UINT32_MAX : base + more;
    return more < need ? need : more;
}

/* One block of buffers that may have to grow. */
typedef struct growth {
    tclod_array arrays[TCLOD_MAX_ARRAYS];
    void *fresh[TCLOD_MAX_ARRAYS];
    size_t count;
    uint32_t *cap; /* its capacity in the selector */
    uint32_t new_cap;
} growth;

/* Grows the per-node, per-smooth-object and Robin Hood buffers to the scene's
 * size, all or nothing. */
static tclod_status reserve(tclod_selector *sel, uint32_t nodes, uint32_t smooth) {
    growth g[5];
    int uses_smooth = sel->desc.solver != TCLOD_SOLVER_GREEDY;
    int i, k;
    if (nodes + smooth < nodes || nodes > UINT32_MAX - 3u || smooth > (UINT32_MAX - 2u) / 2u ||
        nodes + 2u * smooth > UINT32_MAX - 2u)
        return TCLOD_ERR_NOMEM; /* ids beyond 32 bits */
    g[0].cap = &sel->cap;
    /* three more entries than nodes: the heaps' alignment (tclod_greedy_bind) */
    g[0].new_cap = nodes + 3u > sel->cap ? grown(sel->cap, nodes + 3u) : sel->cap;
    g[1].cap = &sel->smooth_cap;
    g[1].new_cap =
        uses_smooth && smooth > sel->smooth_cap ? grown(sel->smooth_cap, smooth) : sel->smooth_cap;
    g[2].cap = &sel->rh.cap;
    /* one element more than nodes: rh.first's end */
    g[2].new_cap = sel->desc.solver == TCLOD_SOLVER_ROBIN_HOOD && nodes + smooth + 1u > sel->rh.cap
                       ? grown(sel->rh.cap, nodes + smooth + 1u)
                       : sel->rh.cap;
    g[3].cap = &sel->stream.cap;
    /* the plan's lists hold nodes and smooth objects, and its heap the smooth
     * quadtree's cells (fewer than 2 per object) */
    g[3].new_cap = tclod_stream_wanted(sel) && nodes + 2u * smooth + 2u > sel->stream.cap
                       ? grown(sel->stream.cap, nodes + 2u * smooth + 2u)
                       : sel->stream.cap;
    g[4].cap = &sel->drawn_cap;
    /* once the scene has self leaves: a result entry per node */
    g[4].new_cap = (sel->drawn_cap > 0 || sel->scene->self_count > 0) && nodes > sel->drawn_cap
                       ? grown(sel->drawn_cap, nodes)
                       : sel->drawn_cap;
    /* the arrays of the blocks that grow */
    g[0].count = g[0].new_cap != sel->cap ? node_buffers(sel, g[0].arrays) : 0;
    g[1].count = g[1].new_cap != sel->smooth_cap ? smooth_buffers(sel, g[1].arrays) : 0;
    g[2].count = g[2].new_cap != sel->rh.cap ? tclod_rh_buffers(&sel->rh, g[2].arrays) : 0;
    g[3].count =
        g[3].new_cap != sel->stream.cap ? tclod_stream_buffers(&sel->stream, g[3].arrays) : 0;
    g[4].count = g[4].new_cap != sel->drawn_cap ? drawn_buffers(sel, g[4].arrays) : 0;
    for (i = 0; i < 5; ++i) {
        if (g[i].new_cap == *g[i].cap)
            continue;
        if (tclod_arrays_alloc(&sel->alloc, g[i].arrays, g[i].count, g[i].new_cap, g[i].fresh) !=
            TCLOD_OK) {
            for (k = 0; k < i; ++k)
                if (g[k].new_cap != *g[k].cap)
                    tclod_arrays_discard(&sel->alloc, g[k].arrays, g[k].count, g[k].new_cap,
                                         g[k].fresh);
            return TCLOD_ERR_NOMEM;
        }
    }
    for (i = 0; i < 5; ++i) {
        if (g[i].new_cap == *g[i].cap)
            continue;
        tclod_arrays_commit(&sel->alloc, g[i].arrays, g[i].count, *g[i].cap, g[i].new_cap,
                            g[i].fresh);
        *g[i].cap = g[i].new_cap;
        if (i == 0)
            tclod_greedy_bind(&sel->greedy);
    }
    return TCLOD_OK;
}

int tclod_selector_scene_ok(const tclod_selector *sel) {
    /* the mixed solver without smooth callbacks solves like the greedy while
     * the scene has no smooth objects */
    return sel->desc.solver != TCLOD_SOLVER_MIXED || sel->scene->smooth_live == 0 ||
           (sel->desc.callbacks.smooth_benefit && tclod_smooth_priced(&sel->desc.callbacks));
}

tclod_status tclod_selector_reserve(tclod_selector *sel) {
    tclod_status status = tclod_scene_prepare(sel->scene);
    if (status != TCLOD_OK)
        return status;
    return reserve(sel, sel->scene->node_count, sel->scene->smooth_count);
}

void tclod_selector_keep(tclod_selector *sel, tclod_selector_saved *keep) {
    sel->keep = keep;
    if (!keep)
        return;
    keep->valid = 0;
    keep->closure_hint = sel->greedy.closure_hint; /* a solve writes it before its commit */
    keep->fallback = sel->greedy.fallback;
}

/* Copies the committed state into sel->keep, once, before a commit replaces
 * it. */
static void keep_committed(tclod_selector *sel) {
    tclod_selector_saved *k = sel->keep;
    if (!k || k->valid)
        return;
    if (sel->prev_count)
        memcpy(k->cut, sel->prev_cut, sizeof(tclod_id) * sel->prev_count);
    if (sel->result_count) {
        memcpy(k->result, sel->result, sizeof(tclod_id) * sel->result_count);
        if (!sel->drawn_is_result)
            memcpy(k->drawn, sel->drawn, sizeof(tclod_id) * sel->result_count);
    }
    k->drawn_is_result = sel->drawn_is_result;
    if (sel->group_count)
        memcpy(k->groups, sel->groups, sizeof(tclod_smooth_group) * sel->group_count);
    k->cut_count = sel->prev_count;
    k->result_count = sel->result_count;
    k->group_count = sel->group_count;
    k->scene_version = sel->scene_version;
    k->node_version = sel->node_version;
    k->smooth_version = sel->smooth_version;
    k->synced = sel->user.synced;
    k->log_seen = sel->user.log_seen;
    k->has_cut = sel->has_cut;
    k->valid = 1;
}

/* Checks a frame; on error records why under fn. */
static tclod_status check_frame(tclod_selector *sel, const tclod_frame *f, const char *fn) {
    const char *why;
    if (!(f->budget >= 0.0))
        return tclod_fail(sel->error, TCLOD_ERR_ARG, fn, "frame->budget must be >= 0 (not NaN)");
    if (!(f->solve_seconds >= 0.0))
        return tclod_fail(sel->error, TCLOD_ERR_ARG, fn,
                          "frame->solve_seconds must be >= 0 (not NaN)");
    why = f->view ? tclod_view_check(f->view) : NULL;
    if (why)
        return tclod_fail_in(sel->error, TCLOD_ERR_ARG, fn, "frame->", why);
    return TCLOD_OK;
}

/* Puts the committed cut back as the working cut after a failed solve. */
static void roll_back(tclod_selector *sel) {
    uint32_t i;
    for (i = 0; i < sel->cut_count; ++i) {
        sel->node[sel->cut[i]].cut_pos = TCLOD_NONE;
        sel->flags[sel->cut[i]] = 0;
    }
    if (sel->prev_count)
        memcpy(sel->cut, sel->prev_cut, sizeof(tclod_id) * sel->prev_count);
    sel->cut_count = sel->prev_count;
    for (i = 0; i < sel->cut_count; ++i)
        sel->node[sel->cut[i]].cut_pos = i;
}

void tclod_selector_restore(tclod_selector *sel, const tclod_selector_saved *k) {
    assert(!sel->pending && !sel->busy);
    sel->greedy.closure_hint = k->closure_hint;
    sel->greedy.fallback = k->fallback;
    if (!k->valid)
        return; /* nothing was committed since */
    if (k->cut_count)
        memcpy(sel->prev_cut, k->cut, sizeof(tclod_id) * k->cut_count);
    sel->prev_count = k->cut_count;
    roll_back(sel);
    if (k->result_count) {
        memcpy(sel->result, k->result, sizeof(tclod_id) * k->result_count);
        if (!k->drawn_is_result)
            memcpy(sel->drawn, k->drawn, sizeof(tclod_id) * k->result_count);
    }
    sel->drawn_is_result = k->drawn_is_result;
    if (k->group_count)
        memcpy(sel->groups, k->groups, sizeof(tclod_smooth_group) * k->group_count);
    sel->result_count = k->result_count;
    sel->group_count = k->group_count;
    sel->scene_version = k->scene_version;
    sel->node_version = k->node_version;
    sel->smooth_version = k->smooth_version;
    sel->user.synced = k->synced;
    sel->user.log_seen = k->log_seen;
    sel->has_cut = k->has_cut;
}

/* The working cut becomes the result: visible, kept nodes in cut order. */
static void commit(tclod_selector *sel) {
    const tclod_id *cut;
    const tclod_node_state *node;
    const uint8_t *flags;
    tclod_id *result;
    uint32_t i, n = 0, count;
    double benefit = 0.0, cost = 0.0;
    keep_committed(sel);
    /* in locals: the stores to result cannot change them */
    cut = sel->cut;
    node = sel->node;
    flags = sel->flags;
    result = sel->result;
    count = sel->cut_count;
    for (i = 0; i < count; ++i) {
        tclod_id id = cut[i];
        if (i + TCLOD_CUT_AHEAD < count)
            TCLOD_PREFETCH(&node[cut[i + TCLOD_CUT_AHEAD]]);
        if (!(node[id].benefit > 0.0) || (flags[id] & TCLOD_FLAG_DROPPED))
            continue;
        result[n++] = id;
        benefit += node[id].benefit;
        cost += node[id].cost;
    }
    /* the host's ids: a self leaf draws its additive node */
    sel->drawn_is_result = sel->scene->self_count == 0;
    if (!sel->drawn_is_result)
        for (i = 0; i < n; ++i)
            sel->drawn[i] = tclod_scene_owner(sel->scene, result[i]);
    sel->group_count = 0;
    for (i = 0; i < sel->mixed.vars.count; ++i) {
        tclod_smooth_group *g;
        if (!(sel->mixed.vars.r[i] > 0.0))
            continue;
        g = &sel->groups[sel->group_count++];
        g->first = sel->mixed.vars.first[i];
        g->count = sel->mixed.vars.size[i];
        g->resolution = sel->mixed.vars.r[i];
        g->benefit = sel->mixed.vars.b[i];
        g->cost = sel->mixed.vars.c[i];
        benefit += g->benefit;
        cost += g->cost;
    }
    assert(cost <= sel->frame->budget || sel->stats.over_budget);
    sel->result_count = n;
    if (sel->cut_count)
        memcpy(sel->prev_cut, sel->cut, sizeof(tclod_id) * sel->cut_count);
    sel->prev_count = sel->cut_count;
    sel->has_cut = 1;
    sel->scene_version = sel->scene->version;
    sel->node_version = sel->scene->node_version;
    sel->smooth_version = sel->scene->smooth_version;
    sel->user.synced = sel->begin_epoch; /* it names no node removed before that */
    sel->user.log_seen = sel->begin_log;
    sel->stats.benefit = benefit;
    sel->stats.cost = cost;
}

/* The selector's busy flag, which the scene sees too. */
static void set_busy(tclod_selector *sel, int busy) {
    sel->busy = busy;
    sel->user.busy = busy;
}

/* Whether a solve is pending, which holds the scene unless the selector is a
 * scheduler's. */
static void set_pending(tclod_selector *sel, int pending) {
    sel->pending = pending;
    sel->user.holding = pending && sel->holds;
}

/* tclod_select_begin, its errors named after fn. */
static tclod_status selector_begin(tclod_selector *sel, const tclod_frame *f, const char *fn) {
    tclod_status status;
    if (!sel)
        return TCLOD_ERR_ARG;
    if (!f)
        return tclod_fail(sel->error, TCLOD_ERR_ARG, fn, "frame is NULL");
    if (sel->busy)
        return tclod_fail(sel->error, TCLOD_ERR_STATE, fn, TCLOD_MSG_BUSY);
    if (sel->pending)
        return tclod_fail(sel->error, TCLOD_ERR_STATE, fn,
                          "a solve is pending: step, finish or cancel it first");
    status = check_frame(sel, f, fn);
    if (status != TCLOD_OK)
        return status;
    if (!tclod_selector_scene_ok(sel))
        return tclod_fail(sel->error, TCLOD_ERR_ARG, fn, TCLOD_MSG_SMOOTH);
    set_busy(sel, 1);
    status = tclod_scene_prepare(sel->scene);
    if (status == TCLOD_OK)
        status = reserve(sel, sel->scene->node_count, sel->scene->smooth_count);
    set_busy(sel, 0);
    if (status != TCLOD_OK)
        return tclod_fail(sel->error, status, fn, TCLOD_MSG_NOMEM);
    if (++sel->solve_id == UINT32_MAX) { /* the fill value of new records */
        uint32_t i;
        for (i = 0; i < sel->cap; ++i)
            sel->node[i].stamp = 0;
        for (i = 0; i < sel->stream.cap; ++i) /* the streaming stamps too */
            sel->stream.seen[i] = sel->stream.size_seen[i] = 0;
        sel->solve_id = 1;
    }
    memset(&sel->stats, 0, sizeof sel->stats);
    sel->stats.stop_reason = TCLOD_STOP_FINEST;
    sel->stats.resident_bytes = sel->scene->resident_bytes;
    sel->stream.absent_seen = 0;
    memset(&sel->resume, 0, sizeof sel->resume);
    sel->frame_data = *f;
    sel->has_view = f->view != NULL;
    if (sel->has_view) {
        sel->view_data = *f->view;
        sel->frame_data.view = &sel->view_data;
        tclod_view_cache_init(&sel->view, f->view);
    }
    sel->failed = 0;
    sel->stopped = 0;
    sel->elapsed = 0.0;
    sel->reserved = 0.0;
    sel->mixed.vars.count = 0;
    set_pending(sel, 1);
    sel->pending_version = sel->scene->version;
    sel->begin_epoch = sel->scene->epoch;
    sel->begin_log = sel->scene->log_base + sel->scene->log_count;
    return TCLOD_OK;
}

tclod_status tclod_select_begin(tclod_selector *sel, const tclod_frame *f) {
    return selector_begin(sel, f, "tclod_select_begin");
}

/* Ends the solve in progress without a result: the working cut goes back to
 * the committed one. */
static void abandon(tclod_selector *sel) {
    tclod_greedy_end(sel);
    roll_back(sel);
    set_pending(sel, 0);
}

/* What a solve that succeeded tells the host besides its result
 * (tclod_stats.notes). */
static void note(tclod_selector *sel) {
    const tclod_scene *s = sel->scene;
    const tclod_callbacks *cb = &sel->desc.callbacks;
    uint32_t notes = 0;
    if (sel->stats.invalid_values > 0)
        notes |= TCLOD_NOTE_INVALID_VALUES;
    if (!sel->has_view)
        notes |= TCLOD_NOTE_NO_VIEW;
    if (s->smooth_live > 0 && (sel->desc.solver == TCLOD_SOLVER_GREEDY || !cb->smooth_benefit ||
                               !tclod_smooth_priced(cb)))
        notes |= TCLOD_NOTE_SMOOTH_IGNORED;
    if (sel->result_count == 0 && sel->group_count == 0 &&
        (s->live_nodes > 0 || s->smooth_live > 0))
        notes |= TCLOD_NOTE_NOTHING_DRAWN;
    /* the plan's, the greedy's and the batches' */
    sel->stats.notes =
        notes | (sel->stats.notes & (TCLOD_NOTE_MEMORY_SHORT | TCLOD_NOTE_COLD_FALLBACK |
                                     TCLOD_NOTE_TASKS_MISSED | TCLOD_NOTE_TASKS_REPEATED));
}

/* Runs the begun solve until it finishes or the slice (slice_end on the
 * clock, slice_iterations more iterations; 0 = none) runs out. */
static tclod_status run(tclod_selector *sel, double slice_seconds, uint32_t slice_iterations,
                        int *done, tclod_stats *st, const char *fn) {
    tclod_status status;
    if (sel->busy)
        return tclod_fail(sel->error, TCLOD_ERR_STATE, fn, TCLOD_MSG_BUSY);
    if (!sel->pending)
        return tclod_fail(sel->error, TCLOD_ERR_STATE, fn, "no solve is pending");
    if (sel->pending_version != sel->scene->version) {
        abandon(sel); /* the scene changed under the solve */
        return tclod_fail(sel->error, TCLOD_ERR_STATE, fn,
                          "the scene changed since the solve began; it was cancelled");
    }
    set_busy(sel, 1);
    sel->start_time = tclod_now();
    sel->slice_end = slice_seconds > 0.0 ? sel->start_time + slice_seconds : 0.0;
    sel->slice_iterations = 0;
    sel->step_start = sel->stats.iterations;
    if (slice_iterations) {
        uint32_t it = sel->stats.iterations;
        sel->slice_iterations =
            it > UINT32_MAX - slice_iterations ? UINT32_MAX : it + slice_iterations;
    }
    sel->paused = 0;
    sel->frame = &sel->frame_data;
    sel->query.count = 1;
    sel->query.view = sel->frame->view;
    sel->query.members = NULL;
    switch (sel->desc.solver) {
    case TCLOD_SOLVER_MIXED:
        status = tclod_mixed_solve(sel);
        break;
    case TCLOD_SOLVER_ROBIN_HOOD:
        status = tclod_robin_hood_solve(sel);
        break;
    default:
        status = tclod_greedy_solve(sel);
        break;
    }
    sel->elapsed += tclod_now() - sel->start_time;
    if (status == TCLOD_OK && sel->pending_version != sel->scene->version)
        status = tclod_fail(sel->error, TCLOD_ERR_STATE, fn, /* it saw part of the scene */
                            "a callback changed the scene; the solve was cancelled");
    else if (status == TCLOD_ERR_CALLBACK)
        tclod_fail(sel->error, status, fn, TCLOD_MSG_STRICT);
    else if (status != TCLOD_OK)
        tclod_fail(sel->error, status, fn, tclod_status_string(status));
    if (status != TCLOD_OK) {
        abandon(sel);
    } else if (sel->paused) {
        *done = 0;
    } else {
        if (sel->stats.over_budget)
            sel->stats.stop_reason = TCLOD_STOP_OVER_BUDGET;
        else if (sel->stats.dropped_roots && (sel->stats.stop_reason == TCLOD_STOP_BUDGET ||
                                              sel->stats.stop_reason == TCLOD_STOP_FINEST))
            sel->stats.stop_reason = TCLOD_STOP_ROOTS_DROPPED;
        if (sel->stats.stop_reason == TCLOD_STOP_FINEST && sel->frame_data.budget == 0.0)
            sel->stats.stop_reason = TCLOD_STOP_BUDGET; /* nothing of any cost could fit */
        if (tclod_stream_plan(sel) != 0) {
            tclod_fail(sel->error, TCLOD_ERR_CALLBACK, fn, TCLOD_MSG_STRICT);
            abandon(sel);
            sel->frame = NULL;
            set_busy(sel, 0);
            return TCLOD_ERR_CALLBACK;
        }
        commit(sel);
        tclod_stream_commit(sel);
        note(sel);
        sel->stats.solve_seconds = sel->elapsed;
        set_pending(sel, 0);
        *done = 1;
        if (st)
            *st = sel->stats;
    }
    sel->frame = NULL;
    set_busy(sel, 0);
    return status;
}

tclod_status tclod_select_step(tclod_selector *sel, double slice_seconds, uint32_t slice_iterations,
                               int *done, tclod_stats *st) {
    static const char fn[] = "tclod_select_step";
    if (!sel)
        return TCLOD_ERR_ARG;
    if (!done)
        return tclod_fail(sel->error, TCLOD_ERR_ARG, fn, "done is NULL");
    if (!(slice_seconds >= 0.0))
        return tclod_fail(sel->error, TCLOD_ERR_ARG, fn, "slice_seconds must be >= 0 (not NaN)");
    return run(sel, slice_seconds, slice_iterations, done, st, fn);
}

tclod_status tclod_select_finish(tclod_selector *sel, tclod_stats *st) {
    static const char fn[] = "tclod_select_finish";
    int done = 0;
    if (!sel)
        return TCLOD_ERR_ARG;
    if (sel->busy)
        return tclod_fail(sel->error, TCLOD_ERR_STATE, fn, TCLOD_MSG_BUSY);
    if (!sel->pending)
        return tclod_fail(sel->error, TCLOD_ERR_STATE, fn, "no solve is pending");
    if (!sel->stopped) {
        sel->stopped = 1;
        sel->stats.stop_reason = TCLOD_STOP_FINISHED;
    }
    return run(sel, 0.0, 0, &done, st, fn);
}

tclod_status tclod_selector_set_coefficients(tclod_selector *sel, const double *coefficients) {
    static const char fn[] = "tclod_selector_set_coefficients";
    int bad;
    if (!sel)
        return TCLOD_ERR_ARG;
    if (sel->busy)
        return tclod_fail(sel->error, TCLOD_ERR_STATE, fn, TCLOD_MSG_BUSY);
    if (sel->pending)
        return tclod_fail(sel->error, TCLOD_ERR_STATE, fn,
                          "a solve is pending: its nodes are priced with the coefficients "
                          "it began with");
    if (!coefficients)
        return tclod_fail(sel->error, TCLOD_ERR_ARG, fn, "coefficients is NULL");
    if (sel->desc.feature_count == 0)
        return tclod_fail(sel->error, TCLOD_ERR_ARG, fn,
                          "the selector has no features (desc.feature_count 0)");
    bad = coefficient_bad(coefficients, sel->desc.feature_count);
    if (bad >= 0) {
        char msg[80];
        snprintf(msg, sizeof msg, "coefficients[%d] must be finite and >= 0", bad);
        return tclod_fail(sel->error, TCLOD_ERR_ARG, fn, msg);
    }
    memcpy(sel->desc.coefficients, coefficients, sel->desc.feature_count * sizeof *coefficients);
    return TCLOD_OK;
}

tclod_status tclod_select_cancel(tclod_selector *sel) {
    if (!sel)
        return TCLOD_ERR_ARG;
    if (sel->busy)
        return tclod_fail(sel->error, TCLOD_ERR_STATE, "tclod_select_cancel", TCLOD_MSG_BUSY);
    if (sel->pending)
        abandon(sel);
    return TCLOD_OK;
}

int tclod_select_pending(const tclod_selector *sel) {
    return sel && sel->pending;
}

tclod_status tclod_select(tclod_selector *sel, const tclod_frame *f, tclod_stats *st) {
    int done = 0;
    tclod_status status = selector_begin(sel, f, "tclod_select");
    if (status != TCLOD_OK)
        return status;
    return run(sel, 0.0, 0, &done, st, "tclod_select");
}

tclod_status tclod_selector_cut(const tclod_selector *sel, const tclod_id **ids, size_t *n) {
    if (!sel || !ids || !n)
        return TCLOD_ERR_ARG;
    if (sel->busy)
        return TCLOD_ERR_STATE;
    *ids = sel->drawn_is_result ? sel->result : sel->drawn;
    *n = sel->result_count;
    return TCLOD_OK;
}

tclod_status tclod_selector_smooth_groups(const tclod_selector *sel,
                                          const tclod_smooth_group **groups, size_t *n) {
    if (!sel || !groups || !n)
        return TCLOD_ERR_ARG;
    if (sel->busy)
        return TCLOD_ERR_STATE;
    *groups = sel->groups;
    *n = sel->group_count;
    return TCLOD_OK;
}

double tclod_selector_resolution(const tclod_selector *sel, tclod_id smooth) {
    const tclod_scene *s;
    uint32_t pos, lo = 0, hi;
    if (!sel || sel->busy || sel->group_count == 0)
        return 0.0;
    s = sel->scene;
    /* positions belong to the quadtree the result was made with */
    if (smooth >= s->smooth_count || sel->smooth_version != s->smooth_version ||
        s->qt_version != s->smooth_version)
        return 0.0;
    pos = s->smooth_pos[smooth];
    if (pos == TCLOD_NONE)
        return 0.0;
    hi = sel->group_count;
    while (hi - lo > 1u) { /* the last group with first <= pos */
        uint32_t mid = lo + (hi - lo) / 2u;
        if (sel->groups[mid].first <= pos)
            lo = mid;
        else
            hi = mid;
    }
    if (sel->groups[lo].first > pos || pos - sel->groups[lo].first >= sel->groups[lo].count)
        return 0.0;
    return sel->groups[lo].resolution;
}

const char *tclod_selector_last_error(const tclod_selector *sel) {
    return sel ? sel->error : "";
}
