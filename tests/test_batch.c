/*
 * Batch evaluation and the host's worker threads (docs/api.md, batch
 * evaluation; worker threads): the batch callbacks and the task system change
 * how nodes are asked for, never what is selected. The reference is the
 * per-node path on the same world and frames: the same cut, bit for bit the
 * same benefit and cost, the same evaluations and bad values counted.
 */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include <tclod/tclod.h>

#include "helpers.h"
#include "task_pool.h"
#include "world_scene.h"

#define OBJECTS 1500u
#define FRAMES 24u

/* ---- a host: the world's callbacks, counted, with bad values on demand ------- */

typedef struct host {
    world_scene w;
    /* asks per node in the current select (benefit, cost), and the benefit
     * last given: a cost may be asked only of a node given a benefit > 0 */
    uint32_t *benefit_asks, *cost_asks;
    double *given;
    int bad;         /* 1: some benefits NaN or inf, some costs negative or NaN */
    int sparse;      /* 1: the batch forms leave some entries unwritten, the per-node
                        ones return NaN for them (sparse_benefit, sparse_cost) */
    int twice;       /* a node asked twice in one select */
    int cost_unseen; /* a cost asked of a node whose benefit was not > 0 */
    uint32_t batch_calls;
    /* the task system: a task_pool, or inline (enqueue runs the task itself) */
    task_pool *pool;
    uint32_t enqueues, finishes, ranges, covered, inline_workers, inline_enqueues;
    int bad_range;
    /* the inline system breaking its contract: FAULT_SKIP leaves every other
     * range out, FAULT_WORKER gives every other range the index worker_count,
     * FAULT_REPEAT runs every other range twice, FAULT_OVERLAP makes every
     * range reach half a range into the next; the notes the inline way's
     * selects returned */
    int fault;
    uint32_t inline_notes, other_notes;
    uint32_t lookahead; /* tclod_greedy_desc.lookahead of every way */
} host;

enum { FAULT_NONE = 0, FAULT_SKIP = 1, FAULT_WORKER = 2, FAULT_REPEAT = 3, FAULT_OVERLAP = 4 };

static host H;

/* The nodes whose values a sparse host's batch forms do not write. */
static int sparse_benefit(const host *h, tclod_id id) {
    return h->sparse && id % 7u == 2u;
}

static int sparse_cost(const host *h, tclod_id id) {
    return h->sparse && id % 7u == 3u;
}

static double host_benefit_of(const host *h, tclod_id id, double value) {
    if (sparse_benefit(h, id))
        return (double)NAN;
    if (h->bad && id % 97u == 3u)
        return (double)NAN;
    if (h->bad && id % 89u == 5u)
        return HUGE_VAL;
    return value;
}

static double host_cost_of(const host *h, tclod_id id, double value) {
    if (sparse_cost(h, id))
        return (double)NAN;
    if (h->bad && id % 83u == 7u)
        return -1.0;
    if (h->bad && id % 79u == 11u)
        return (double)NAN;
    return value;
}

static void count_benefit(host *h, tclod_id id, double b) {
    if (h->benefit_asks[id]++)
        __atomic_store_n(&h->twice, 1, __ATOMIC_RELAXED);
    h->given[id] = b;
}

static void count_cost(host *h, tclod_id id) {
    if (h->cost_asks[id]++)
        __atomic_store_n(&h->twice, 1, __ATOMIC_RELAXED);
    if (!(h->given[id] > 0.0 && h->given[id] < HUGE_VAL))
        __atomic_store_n(&h->cost_unseen, 1, __ATOMIC_RELAXED);
}

static double one_benefit(void *user, const tclod_query *q) {
    host *h = (host *)user;
    double b = host_benefit_of(h, q->id, world_benefit(&h->w, q));
    count_benefit(h, q->id, b);
    return b;
}

static double one_cost(void *user, const tclod_query *q) {
    host *h = (host *)user;
    count_cost(h, q->id);
    return host_cost_of(h, q->id, world_cost(&h->w, q));
}

/* The batch forms: the world's loops, then the same bad values and counts.
 * With workers they run at the same time on different nodes: the counters
 * of a node are written by one worker only. */
/* A sparse host's copy of out[] as the library filled it, so that the
 * entries it must leave unwritten can be put back; NULL when not sparse. */
static double *entries_before(const host *h, const tclod_batch *b, const double *out) {
    double *before;
    if (!h->sparse)
        return NULL;
    before = (double *)malloc(b->count * sizeof(double) + 1u);
    assert_non_null(before);
    memcpy(before, out, b->count * sizeof(double));
    return before;
}

static void many_benefits(void *user, const tclod_batch *b, double *out) {
    host *h = (host *)user;
    double *before = entries_before(h, b, out);
    uint32_t i;
    world_benefit_batch(&h->w, b, out);
    for (i = 0; i < b->count; ++i) {
        out[i] = host_benefit_of(h, b->ids[i], out[i]);
        count_benefit(h, b->ids[i], out[i]);
        if (sparse_benefit(h, b->ids[i]))
            out[i] = before[i]; /* as if never written */
    }
    free(before);
    __atomic_fetch_add(&h->batch_calls, 1u, __ATOMIC_RELAXED);
}

static void many_costs(void *user, const tclod_batch *b, double *out) {
    host *h = (host *)user;
    double *before = entries_before(h, b, out);
    uint32_t i;
    world_cost_batch(&h->w, b, out);
    for (i = 0; i < b->count; ++i) {
        count_cost(h, b->ids[i]);
        out[i] = host_cost_of(h, b->ids[i], out[i]);
        if (sparse_cost(h, b->ids[i]))
            out[i] = before[i];
    }
    free(before);
    __atomic_fetch_add(&h->batch_calls, 1u, __ATOMIC_RELAXED);
}

/* A task system that runs every task on the calling thread at once, in
 * ranges of min_range given to workers 0, 1, ... in turn, and returns NULL
 * (finish must then not be called); it checks that the ranges tile the items. */
static void *inline_enqueue(tclod_task_fn *task, uint32_t count, uint32_t min_range, void *ctx,
                            void *user) {
    host *h = (host *)user;
    uint32_t start = 0, k = 0;
    h->enqueues++;
    h->inline_enqueues++;
    if (min_range == 0 || count < min_range)
        h->bad_range = 1;
    while (start < count) {
        uint32_t end = count - start > min_range ? start + min_range : count;
        uint32_t worker = k % h->inline_workers;
        if (h->fault == FAULT_WORKER && k % 2u == 1u)
            worker = h->inline_workers;
        if (h->fault == FAULT_OVERLAP)
            task(start, end + min_range / 2u < count ? end + min_range / 2u : count, worker, ctx);
        else if (!(h->fault == FAULT_SKIP && k % 2u == 1u))
            task(start, end, worker, ctx);
        if (h->fault == FAULT_REPEAT && k % 2u == 1u)
            task(start, end, worker, ctx);
        k++;
        h->ranges++;
        h->covered += end - start;
        start = end;
    }
    return NULL;
}

static void inline_finish(void *task, void *user) {
    (void)task;
    ((host *)user)->finishes++;
}

/* The pool's, counted. */
static void *pool_enqueue_counted(tclod_task_fn *task, uint32_t count, uint32_t min_range,
                                  void *ctx, void *user) {
    host *h = (host *)user;
    tclod_tasks t = task_pool_tasks(h->pool);
    h->enqueues++;
    return t.enqueue(task, count, min_range, ctx, t.user);
}

static void pool_finish_counted(void *task, void *user) {
    host *h = (host *)user;
    tclod_tasks t = task_pool_tasks(h->pool);
    h->finishes++;
    t.finish(task, t.user);
}

/* How a selector asks. */
enum { PER_NODE = 0, BATCH = 1, BATCH_POOL = 2, PER_NODE_POOL = 3, BATCH_INLINE = 4, WAYS = 5 };

static tclod_selector_desc desc_for(int way, int warm, int strict) {
    tclod_selector_desc d;
    tclod_selector_desc_default(&d);
    d.cold_start = !warm;
    d.strict = strict;
    d.greedy.lookahead = H.lookahead;
    d.callbacks.benefit = one_benefit;
    d.callbacks.cost = one_cost;
    d.callbacks.user = &H;
    if (way == BATCH || way == BATCH_POOL || way == BATCH_INLINE) {
        d.callbacks.benefit_batch = many_benefits;
        d.callbacks.cost_batch = many_costs;
    }
    if (way == BATCH_POOL || way == PER_NODE_POOL) {
        d.tasks.worker_count = 2;
        d.tasks.enqueue = pool_enqueue_counted;
        d.tasks.finish = pool_finish_counted;
        d.tasks.user = &H;
    }
    if (way == BATCH_INLINE) {
        d.tasks.worker_count = H.inline_workers;
        d.tasks.enqueue = inline_enqueue;
        d.tasks.finish = inline_finish;
        d.tasks.user = &H;
    }
    return d;
}

static int setup(void **state) {
    world_random_desc d;
    (void)state;
    memset(&H, 0, sizeof H);
    world_random_desc_default(&d);
    d.objects = OBJECTS;
    if (world_build_random(&d, &H.w) != TCLOD_OK)
        return -1;
    H.benefit_asks = (uint32_t *)calloc(H.w.node_count, sizeof(uint32_t));
    H.cost_asks = (uint32_t *)calloc(H.w.node_count, sizeof(uint32_t));
    H.given = (double *)calloc(H.w.node_count, sizeof(double));
    H.pool = task_pool_create(2);
    H.inline_workers = 3;
    return H.benefit_asks && H.cost_asks && H.given && H.pool ? 0 : -1;
}

static int teardown(void **state) {
    (void)state;
    task_pool_destroy(H.pool);
    free(H.benefit_asks);
    free(H.cost_asks);
    free(H.given);
    world_scene_free(&H.w);
    return 0;
}

static void reset_asks(void) {
    memset(H.benefit_asks, 0, sizeof(uint32_t) * H.w.node_count);
    memset(H.cost_asks, 0, sizeof(uint32_t) * H.w.node_count);
    memset(H.given, 0, sizeof(double) * H.w.node_count);
    H.twice = H.cost_unseen = 0;
}

/* One select of every way on frame f; the outputs of way k in st[k], ids[k]. */
static void select_all(tclod_selector *sel[WAYS], uint32_t f, double budget, tclod_stats st[WAYS],
                       tclod_status status[WAYS]) {
    tclod_view view;
    tclod_frame fr;
    int k;
    world_camera_at(&H.w.path, (double)f / (double)FRAMES, &view);
    memset(&fr, 0, sizeof fr);
    fr.view = &view;
    fr.budget = budget;
    for (k = 0; k < WAYS; ++k) {
        reset_asks();
        status[k] = tclod_select(sel[k], &fr, &st[k]);
        if (H.twice)
            fail_msg("way %d asked a node twice in frame %u", k, (unsigned)f);
        assert_false(H.cost_unseen);
    }
}

/* Every way selects what the per-node way selects, frame after frame. */
static void check_ways(int warm, int strict, double budget) {
    tclod_selector *sel[WAYS];
    uint32_t f;
    int k;
    for (k = 0; k < WAYS; ++k) {
        tclod_selector_desc d = desc_for(k, warm, strict);
        assert_int_equal(tclod_selector_create(H.w.scene, &d, NULL, &sel[k]), TCLOD_OK);
    }
    for (f = 0; f < FRAMES; ++f) {
        tclod_stats st[WAYS];
        tclod_status status[WAYS];
        const tclod_id *ids0, *ids;
        size_t n0, n;
        select_all(sel, f, budget, st, status);
        for (k = 0; k < WAYS; ++k) {
            if (k == BATCH_INLINE)
                H.inline_notes |= st[k].notes;
            else
                H.other_notes |= st[k].notes;
        }
        for (k = 1; k < WAYS; ++k) {
            assert_int_equal(status[k], status[0]);
            if (status[0] != TCLOD_OK)
                continue;
            assert_memory_equal(&st[k].benefit, &st[0].benefit, sizeof(double));
            assert_memory_equal(&st[k].cost, &st[0].cost, sizeof(double));
            assert_int_equal(st[k].evaluations, st[0].evaluations);
            assert_int_equal(st[k].invalid_values, st[0].invalid_values);
            assert_int_equal(st[k].increments, st[0].increments);
            assert_int_equal(st[k].decrements, st[0].decrements);
            assert_int_equal(tclod_selector_cut(sel[0], &ids0, &n0), TCLOD_OK);
            assert_int_equal(tclod_selector_cut(sel[k], &ids, &n), TCLOD_OK);
            assert_int_equal(n, n0);
            assert_memory_equal(ids, ids0, n * sizeof(tclod_id));
        }
    }
    for (k = 0; k < WAYS; ++k)
        tclod_selector_destroy(sel[k]);
}

static void warm_selections_are_the_per_node_ones(void **state) {
    (void)state;
    H.enqueues = H.finishes = H.ranges = H.covered = H.inline_enqueues = 0;
    check_ways(1, 0, 40.0);
    /* the pool and the inline system were used: a batch is split when it
     * holds two ranges or more */
    assert_true(H.inline_enqueues > 0);
    assert_true(H.enqueues > H.inline_enqueues);
    assert_true(H.ranges >= 2u * H.inline_enqueues);
    assert_false(H.bad_range);
}

static void cold_selections_are_the_per_node_ones(void **state) {
    (void)state;
    check_ways(0, 0, 40.0);
}

static void tight_and_unlimited_budgets_select_as_per_node(void **state) {
    (void)state;
    check_ways(1, 0, 0.5);
    check_ways(1, 0, HUGE_VAL);
}

/* With a lookahead, whose increments reach below a node's children and
 * rewrite the cut nodes' flags as they are keyed. */
static void lookahead_selections_are_the_per_node_ones(void **state) {
    (void)state;
    H.lookahead = 2;
    check_ways(1, 0, 40.0);
    check_ways(0, 0, 40.0);
}

/* The other tests' ways have no lookahead, also after a failed test. */
static int no_lookahead(void **state) {
    (void)state;
    H.lookahead = 0;
    return 0;
}

static void bad_values_are_sanitised_and_counted_as_per_node(void **state) {
    (void)state;
    H.bad = 1;
    check_ways(1, 0, 40.0);
    check_ways(0, 0, 40.0);
    H.bad = 0;
}

/* Entries a batch callback leaves unwritten count as bad values, as the NaN
 * the per-node callbacks return for the same nodes: the same selections and
 * counts, warm and cold. */
static void unwritten_batch_entries_are_bad_values(void **state) {
    (void)state;
    H.sparse = 1;
    check_ways(1, 0, 40.0);
    check_ways(0, 0, 40.0);
    H.sparse = 0;
}

static void strict_mode_fails_on_a_bad_batch_value_as_per_node(void **state) {
    tclod_selector *sel;
    tclod_selector_desc d = desc_for(BATCH_POOL, 1, 1);
    tclod_view view;
    tclod_frame fr;
    tclod_stats st;
    const tclod_id *ids;
    size_t n;
    (void)state;
    assert_int_equal(tclod_selector_create(H.w.scene, &d, NULL, &sel), TCLOD_OK);
    world_camera_at(&H.w.path, 0.0, &view);
    memset(&fr, 0, sizeof fr);
    fr.view = &view;
    fr.budget = 40.0;
    reset_asks();
    assert_int_equal(tclod_select(sel, &fr, &st), TCLOD_OK);
    H.bad = 1;
    reset_asks();
    assert_int_equal(tclod_select(sel, &fr, &st), TCLOD_ERR_CALLBACK);
    H.bad = 0;
    /* nothing changed: the first selection is still the result */
    assert_int_equal(tclod_selector_cut(sel, &ids, &n), TCLOD_OK);
    assert_true(n > 0);
    tclod_selector_destroy(sel);
}

/* A task system that runs the ranges before enqueue returns gets no finish;
 * each range had a worker index below worker_count (the inline system's
 * indices go round its three workers, which the workspace must serve). */
static void an_inline_task_system_is_not_asked_to_finish(void **state) {
    (void)state;
    H.enqueues = H.finishes = H.ranges = H.covered = H.inline_enqueues = 0;
    check_ways(1, 0, 40.0);
    assert_true(H.inline_enqueues > 0);
    /* the pool's finishes only: one per enqueue of the pool's, which
     * returns a task; the inline system's enqueues returned NULL */
    assert_int_equal(H.finishes, H.enqueues - H.inline_enqueues);
    /* its ranges tiled what it was given: at least two chunks each */
    assert_true(H.covered >= 2u * 256u * H.inline_enqueues);
}

/* A task system that breaks its contract, leaving ranges out, giving them a
 * worker index out of range, running them twice or overlapping them, still
 * gets the per-node selections, each node asked once (select_all checks),
 * and the note that says which; a sound one never gets either. */
static void a_faulty_task_system_changes_nothing_but_the_notes(void **state) {
    const uint32_t faults = TCLOD_NOTE_TASKS_MISSED | TCLOD_NOTE_TASKS_REPEATED;
    int fault;
    (void)state;
    H.inline_notes = H.other_notes = 0;
    check_ways(1, 0, 40.0);
    assert_false(H.inline_notes & faults);
    for (fault = FAULT_SKIP; fault <= FAULT_OVERLAP; ++fault) {
        uint32_t note = fault <= FAULT_WORKER ? TCLOD_NOTE_TASKS_MISSED : TCLOD_NOTE_TASKS_REPEATED;
        H.fault = fault;
        H.inline_notes = H.other_notes = 0;
        check_ways(1, 0, 40.0);
        check_ways(0, 0, 40.0);
        assert_int_equal(H.inline_notes & faults, note);
        assert_false(H.other_notes & faults);
    }
    H.fault = FAULT_NONE;
}

static void the_scheduler_asks_node_by_node(void **state) {
    tclod_selector_desc d = desc_for(BATCH_POOL, 1, 0);
    tclod_scheduler_desc sd;
    tclod_scheduler *sch;
    tclod_view view;
    uint32_t f;
    (void)state;
    tclod_scheduler_desc_default(&sd);
    assert_int_equal(tclod_scheduler_create(H.w.scene, &d, &sd, NULL, &sch), TCLOD_OK);
    H.batch_calls = 0;
    H.enqueues = 0;
    for (f = 0; f < 6; ++f) {
        world_camera_at(&H.w.path, (double)f / (double)FRAMES, &view);
        reset_asks();
        assert_int_equal(tclod_scheduler_update(sch, 0.05 * f, &view, 40.0, 0.0), TCLOD_OK);
    }
    assert_int_equal(H.batch_calls, 0);
    assert_int_equal(H.enqueues, 0);
    tclod_scheduler_destroy(sch);
}

static void task_descs_are_checked(void **state) {
    tclod_selector_desc d = desc_for(BATCH, 1, 0);
    tclod_selector *sel = NULL;
    const char *why;
    (void)state;
    d.tasks.worker_count = TCLOD_MAX_WORKERS + 1u;
    why = tclod_selector_desc_check(H.w.scene, &d);
    assert_non_null(why);
    assert_non_null(strstr(why, "desc.tasks.worker_count"));
    assert_int_equal(tclod_selector_create(H.w.scene, &d, NULL, &sel), TCLOD_ERR_ARG);
    assert_null(sel);
    d.tasks.worker_count = 2;
    why = tclod_selector_desc_check(H.w.scene, &d);
    assert_non_null(why);
    assert_non_null(strstr(why, "desc.tasks.enqueue"));
    d.tasks.enqueue = inline_enqueue;
    assert_non_null(tclod_selector_desc_check(H.w.scene, &d));
    d.tasks.finish = inline_finish;
    assert_null(tclod_selector_desc_check(H.w.scene, &d));
    /* one worker needs no task system */
    d = desc_for(BATCH, 1, 0);
    d.tasks.worker_count = 1;
    assert_null(tclod_selector_desc_check(H.w.scene, &d));
}

/* Residency: nodes not resident are evaluated the same way by every path. */
static void streaming_selections_are_the_per_node_ones(void **state) {
    uint32_t i;
    (void)state;
    for (i = 0; i < H.w.node_count; i += 7u)
        assert_int_equal(tclod_scene_set_resident(H.w.scene, i, 0), TCLOD_OK);
    check_ways(1, 0, 40.0);
    check_ways(0, 0, 40.0);
    for (i = 0; i < H.w.node_count; i += 7u)
        assert_int_equal(tclod_scene_set_resident(H.w.scene, i, 1), TCLOD_OK);
}

/* ---- boxes, nodes without bounds, frames without a view, additive nodes ----- */

/* A scene of every kind of volume: 240 roots, boxes (axis-aligned and
 * oriented, some reaching through the near plane) or spheres, each with four
 * children: one with its parent's volume, one sphere, one without bounds, one
 * empty node with a child; every eighth root refines additively. Benefit:
 * its weight times the screen area (its radius squared without a view or
 * bounds), cost its own. */
typedef struct mixed_host {
    tclod_scene *s;
    double *weight, *cost;
    uint32_t n;
} mixed_host;

static double mixed_value(const mixed_host *m, tclod_id id, float area) {
    return m->weight[id] * (area >= 0.0f ? (double)area : 4.0);
}

static double mixed_benefit(void *user, const tclod_query *q) {
    const mixed_host *m = (const mixed_host *)user;
    return mixed_value(m, q->id, q->screen_area);
}

static double mixed_cost(void *user, const tclod_query *q) {
    return ((const mixed_host *)user)->cost[q->id];
}

static void mixed_benefits(void *user, const tclod_batch *b, double *out) {
    const mixed_host *m = (const mixed_host *)user;
    uint32_t i;
    for (i = 0; i < b->count; ++i)
        out[i] = mixed_value(m, b->ids[i], b->screen_area[i]);
}

static void mixed_costs(void *user, const tclod_batch *b, double *out) {
    const mixed_host *m = (const mixed_host *)user;
    uint32_t i;
    for (i = 0; i < b->count; ++i)
        out[i] = m->cost[b->ids[i]];
}

static tclod_id mixed_add(mixed_host *m, const tclod_node_desc *d, double weight, double cost) {
    tclod_id id;
    assert_int_equal(tclod_scene_add_node_desc(m->s, d, &id), TCLOD_OK);
    assert_true(id < m->n);
    m->weight[id] = weight;
    m->cost[id] = cost;
    return id;
}

static void build_mixed(mixed_host *m) {
    uint32_t i;
    m->n = 240u * 8u;
    m->weight = (double *)calloc(m->n, sizeof(double));
    m->cost = (double *)calloc(m->n, sizeof(double));
    assert_non_null(m->weight);
    assert_non_null(m->cost);
    assert_int_equal(tclod_scene_create(NULL, &m->s), TCLOD_OK);
    for (i = 0; i < 240u; ++i) {
        tclod_node_desc d, c;
        double x = (double)(i % 16u) * 6.0 - 45.0, z = -(double)(i / 16u) * 6.0 - 0.5;
        double center[3], half[3] = {1.0, 0.5 + 0.1 * (double)(i % 5u), 1.5};
        double axes[9] = {0.8, 0.6, 0.0, -0.6, 0.8, 0.0, 0.0, 0.0, 1.2};
        tclod_id root, mid;
        center[0] = x;
        center[1] = 0.0;
        center[2] = z;
        memset(&d, 0, sizeof d);
        d.parent = TCLOD_NONE;
        d.refine = i % 8u == 7u ? TCLOD_REFINE_ADD : TCLOD_REFINE_REPLACE;
        d.bounds = i % 3u == 0u   ? tclod_bounds_aabb(center, half)
                   : i % 3u == 1u ? tclod_bounds_obb(center, axes)
                                  : tclod_bounds_sphere(x, 0.0, z, 1.2);
        root = mixed_add(m, &d, 1.0 + 0.01 * (double)i, 0.5);
        c = d;
        c.parent = root;
        c.refine = TCLOD_REFINE_REPLACE;
        mixed_add(m, &c, 1.6, 1.0); /* its parent's volume */
        c.bounds = tclod_bounds_sphere(x + 0.5, 0.2, z, 0.6);
        mixed_add(m, &c, 1.5 + 0.02 * (double)(i % 7u), 0.8);
        c.bounds.kind = TCLOD_BOUNDS_NONE; /* no bounds */
        mixed_add(m, &c, 0.4, 0.6);
        c.bounds = tclod_bounds_sphere(x - 0.5, 0.1, z, 0.7);
        c.empty = 1;
        mid = mixed_add(m, &c, 0.0, 0.0);
        c.empty = 0;
        c.parent = mid;
        mixed_add(m, &c, 1.3, 0.7);
    }
}

/* Per node, batch, and batch over the pool select the same on frames with
 * and without a view, warm and cold. */
static void every_kind_of_volume_selects_as_per_node(void **state) {
    mixed_host m;
    tclod_selector *sel[3];
    tclod_view view;
    uint32_t f;
    int k, warm;
    (void)state;
    build_mixed(&m);
    helper_view(&view);
    for (warm = 0; warm < 2; ++warm) {
        for (k = 0; k < 3; ++k) {
            tclod_selector_desc d;
            tclod_selector_desc_default(&d);
            d.cold_start = !warm;
            d.callbacks.benefit = mixed_benefit;
            d.callbacks.cost = mixed_cost;
            d.callbacks.user = &m;
            if (k > 0) {
                d.callbacks.benefit_batch = mixed_benefits;
                d.callbacks.cost_batch = mixed_costs;
            }
            if (k == 2)
                d.tasks = task_pool_tasks(H.pool);
            assert_int_equal(tclod_selector_create(m.s, &d, NULL, &sel[k]), TCLOD_OK);
        }
        for (f = 0; f < 12; ++f) {
            tclod_frame fr = helper_frame(f % 4u == 3u ? NULL : &view, 60.0 + 25.0 * (f % 3u));
            tclod_stats st[3];
            const tclod_id *ids0, *ids;
            size_t n0, n;
            view.eye[0] = -20.0 + 3.0 * (double)f;
            view.eye[2] = 2.0 - 4.0 * (double)f;
            for (k = 0; k < 3; ++k)
                assert_int_equal(tclod_select(sel[k], &fr, &st[k]), TCLOD_OK);
            assert_int_equal(tclod_selector_cut(sel[0], &ids0, &n0), TCLOD_OK);
            assert_true(n0 > 0);
            for (k = 1; k < 3; ++k) {
                assert_memory_equal(&st[k].benefit, &st[0].benefit, sizeof(double));
                assert_memory_equal(&st[k].cost, &st[0].cost, sizeof(double));
                assert_int_equal(st[k].evaluations, st[0].evaluations);
                assert_int_equal(tclod_selector_cut(sel[k], &ids, &n), TCLOD_OK);
                assert_int_equal(n, n0);
                assert_memory_equal(ids, ids0, n * sizeof(tclod_id));
            }
        }
        for (k = 0; k < 3; ++k)
            tclod_selector_destroy(sel[k]);
    }
    tclod_scene_destroy(m.s);
    free(m.weight);
    free(m.cost);
}

/* The benchmark's dear host (tclod_bench --benefit-work) spends its rounds
 * and gives the world's values bit for bit, node by node and in batches. */
static void busy_benefits_are_the_world_ones(void **state) {
    enum { COUNT = 64 };
    tclod_id ids[COUNT];
    float area[COUNT], distance[COUNT];
    double plain[COUNT], busy[COUNT], one;
    tclod_batch b;
    tclod_query q;
    uint32_t i;
    (void)state;
    memset(&q, 0, sizeof q);
    for (i = 0; i < COUNT; ++i) {
        ids[i] = (tclod_id)((i * 7919u) % H.w.node_count);
        area[i] = i % 5u == 0u ? -1.0f : (float)i * 3.5f; /* -1: no view */
        distance[i] = (float)i;
    }
    memset(&b, 0, sizeof b);
    b.count = COUNT;
    b.ids = ids;
    b.screen_area = area;
    b.distance = distance;
    H.w.benefit_work = 0;
    world_benefit_batch(&H.w, &b, plain);
    H.w.benefit_work = 300;
    world_benefit_batch(&H.w, &b, busy);
    for (i = 0; i < COUNT; ++i) {
        q.id = ids[i];
        q.screen_area = area[i];
        q.distance = distance[i];
        one = world_benefit(&H.w, &q);
        assert_memory_equal(&busy[i], &plain[i], sizeof(double));
        assert_memory_equal(&one, &plain[i], sizeof(double));
        assert_true(plain[i] >= 0.0);
    }
    H.w.benefit_work = 0;
}

int main(void) {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(warm_selections_are_the_per_node_ones),
        cmocka_unit_test(cold_selections_are_the_per_node_ones),
        cmocka_unit_test(tight_and_unlimited_budgets_select_as_per_node),
        cmocka_unit_test_teardown(lookahead_selections_are_the_per_node_ones, no_lookahead),
        cmocka_unit_test(bad_values_are_sanitised_and_counted_as_per_node),
        cmocka_unit_test(unwritten_batch_entries_are_bad_values),
        cmocka_unit_test(strict_mode_fails_on_a_bad_batch_value_as_per_node),
        cmocka_unit_test(an_inline_task_system_is_not_asked_to_finish),
        cmocka_unit_test(a_faulty_task_system_changes_nothing_but_the_notes),
        cmocka_unit_test(the_scheduler_asks_node_by_node),
        cmocka_unit_test(task_descs_are_checked),
        cmocka_unit_test(streaming_selections_are_the_per_node_ones),
        cmocka_unit_test(every_kind_of_volume_selects_as_per_node),
        cmocka_unit_test(busy_benefits_are_the_world_ones),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
