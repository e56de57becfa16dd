/*
 * test_allocation — out-of-memory loops in the manner of SQLite's: every
 * public entry point that allocates is called with its k-th allocation
 * failing, k = 1, 2, 3, ... until the call succeeds, once with that single
 * allocation failing (transient) and once with every allocation from the
 * k-th on failing (persistent). Each failure must return TCLOD_ERR_NOMEM,
 * leak nothing and change nothing: the scene, the previous result and the
 * outputs stay as they were (docs/api.md, "Allocators": a failed
 * allocation is TCLOD_ERR_NOMEM, with nothing leaked and nothing changed).
 *
 * The allocating entry points: tclod_scene_create, tclod_scene_add_node,
 * tclod_scene_add_node_desc, tclod_scene_add_smooth, tclod_scene_set_node_bounds
 * (a box where there was none), tclod_scene_prepare, tclod_scene_smooth_order,
 * tclod_selector_create, tclod_select and tclod_select_begin (each solver),
 * tclod_scheduler_create, tclod_scheduler_update (each solver) and
 * tclod_calib_create.
 * A selector that saw failures must then go on exactly like one that never
 * did. Streaming: nodes added not resident with sizes, residency and sizes
 * changed (calls that allocate nothing, so they succeed with every
 * allocation failing), and selects with a stream desc set or nodes not
 * resident, whose first such select grows the streaming buffers.
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

#include "table_scene.h"
#include "test_alloc.h"

/* Upper bound on the allocations one call may make before it succeeds. */
#define MAX_ALLOCATIONS_PER_CALL 200u

typedef enum failure_mode {
    TRANSIENT = 0, /* only the k-th allocation fails */
    PERSISTENT = 1 /* the k-th and every later one fail */
} failure_mode;

static const char *const mode_name[2] = {"transient", "persistent"};

static void arm(test_alloc *t, failure_mode mode, size_t k) {
    if (mode == TRANSIENT)
        test_alloc_fail_at(t, k);
    else
        test_alloc_fail_from(t, k);
}

/* A test run once per failure mode (MODE_TEST below). */
typedef struct mode_test {
    void (*run)(failure_mode mode);
} mode_test;

static void in_both_modes(void **state) {
    const mode_test *m = (const mode_test *)*state;
    m->run(TRANSIENT);
    m->run(PERSISTENT);
}

static void assert_nothing_left(const test_alloc *t) {
    assert_int_equal(t->outstanding_bytes, 0);
    assert_int_equal(t->outstanding_blocks, 0);
    assert_int_equal(t->bad_frees, 0);
}

/* ---- a selector's result, copied ------------------------------------------ */

typedef struct outcome {
    tclod_id *ids;
    size_t n, cap;
    tclod_smooth_group *groups;
    size_t groups_n, groups_cap;
    double *resolution; /* per smooth id */
    uint32_t smooth;
} outcome;

static void outcome_init(outcome *o, size_t nodes, uint32_t smooth) {
    memset(o, 0, sizeof *o);
    o->cap = nodes;
    o->groups_cap = smooth;
    o->ids = (tclod_id *)malloc((nodes ? nodes : 1) * sizeof *o->ids);
    o->groups = (tclod_smooth_group *)malloc((smooth ? smooth : 1) * sizeof *o->groups);
    o->resolution = (double *)malloc((smooth ? smooth : 1) * sizeof *o->resolution);
    assert_non_null(o->ids);
    assert_non_null(o->groups);
    assert_non_null(o->resolution);
}

static void outcome_free(outcome *o) {
    free(o->ids);
    free(o->groups);
    free(o->resolution);
}

static void take_outcome(const tclod_selector *sel, uint32_t smooth, outcome *o) {
    const tclod_id *ids = NULL;
    const tclod_smooth_group *groups = NULL;
    uint32_t i;
    assert_int_equal(tclod_selector_cut(sel, &ids, &o->n), TCLOD_OK);
    assert_true(o->n <= o->cap);
    if (o->n)
        memcpy(o->ids, ids, o->n * sizeof *ids);
    assert_int_equal(tclod_selector_smooth_groups(sel, &groups, &o->groups_n), TCLOD_OK);
    assert_true(o->groups_n <= o->groups_cap);
    if (o->groups_n)
        memcpy(o->groups, groups, o->groups_n * sizeof *groups);
    assert_true(smooth <= o->groups_cap);
    o->smooth = smooth;
    for (i = 0; i < smooth; ++i)
        o->resolution[i] = tclod_selector_resolution(sel, i);
}

/* Asserts that two results are the same bit for bit. */
static void assert_same_outcome(const outcome *a, const outcome *b, const char *what) {
    if (a->n != b->n || a->groups_n != b->groups_n || a->smooth != b->smooth ||
        (a->n && memcmp(a->ids, b->ids, a->n * sizeof *a->ids) != 0) ||
        (a->groups_n && memcmp(a->groups, b->groups, a->groups_n * sizeof *a->groups) != 0) ||
        (a->smooth && memcmp(a->resolution, b->resolution, a->smooth * sizeof(double)) != 0))
        fail_msg("%s: results differ (%lu/%lu nodes, %lu/%lu groups)", what, (unsigned long)a->n,
                 (unsigned long)b->n, (unsigned long)a->groups_n, (unsigned long)b->groups_n);
}

static void poison_stats(tclod_stats *st) {
    memset(st, 0xa5, sizeof *st);
}

static void assert_stats_untouched(const tclod_stats *st) {
    tclod_stats pattern;
    poison_stats(&pattern);
    assert_memory_equal(st, &pattern, sizeof pattern);
}

static void assert_same_stats(const tclod_stats *a, const tclod_stats *b) {
    assert_memory_equal(&a->benefit, &b->benefit, sizeof a->benefit);
    assert_memory_equal(&a->cost, &b->cost, sizeof a->cost);
    assert_int_equal(a->iterations, b->iterations);
    assert_int_equal(a->increments, b->increments);
    assert_int_equal(a->decrements, b->decrements);
    assert_int_equal(a->line_searches, b->line_searches);
    assert_int_equal(a->variables, b->variables);
    assert_int_equal(a->dropped_roots, b->dropped_roots);
    assert_int_equal(a->invalid_values, b->invalid_values);
    assert_int_equal(a->evaluations, b->evaluations);
    assert_int_equal(a->stop_reason, b->stop_reason);
}

/* ---- scenes ------------------------------------------------------------------- */

/* Smooth objects with square-root benefits and linear costs, half of them
 * with a setup cost, at random places in [-extent, extent)². */
static void add_smooth_objects(table_model *m, tclod_scene *s, table_rng *rng, uint32_t n,
                               float extent) {
    uint32_t i;
    for (i = 0; i < n; ++i) {
        float b[4];
        double k = table_rng_uniform(rng, 0.5, 2.0);
        b[0] = (float)table_rng_uniform(rng, -extent, extent);
        b[1] = 0.0f;
        b[2] = (float)table_rng_uniform(rng, -extent, extent);
        b[3] = 1.0f;
        assert_int_equal(table_add_smooth(m, s, b, TABLE_POWER, table_rng_uniform(rng, 1.0, 10.0),
                                          0.5, k, i % 2 ? 4.0 * k : k, i % 2 ? 0.1 : 0.0, NULL),
                         TCLOD_OK);
    }
}

/* A scene of chains with bounds, a random hierarchy and smooth objects. */
static void build_scene(table_model *m, tclod_scene *s, uint64_t seed, uint32_t chains,
                        uint32_t random_nodes, uint32_t smooth) {
    table_rng rng;
    table_rng_seed(&rng, seed);
    assert_int_equal(table_chains(m, s, &rng, chains, 4, 40.0f), TCLOD_OK);
    if (random_nodes)
        assert_int_equal(table_random_hierarchy(m, s, &rng, random_nodes, 1 + random_nodes / 20,
                                                TABLE_DIMINISHING),
                         TCLOD_OK);
    add_smooth_objects(m, s, &rng, smooth, 40.0f);
}

static double total_cost(const table_model *m) {
    double c = table_leaves_cost(m);
    uint32_t i;
    for (i = 0; i < m->smooth.count; ++i)
        c += table_smooth_cost_of(m, i, 1.0, NULL);
    return c;
}

static void selector_desc(tclod_selector_desc *d, tclod_solver solver, table_model *m) {
    tclod_selector_desc_default(d);
    d->solver = solver;
    table_mixed_callbacks(m, &d->callbacks);
}

/* A view from the side of the scene, looking at its middle. */
static void side_view(tclod_view *v, int frame) {
    memset(v, 0, sizeof *v);
    v->eye[0] = -60.0f + 10.0f * (float)frame;
    v->eye[1] = 20.0f;
    v->eye[2] = 60.0f;
    v->forward[0] = 60.0f - 10.0f * (float)frame;
    v->forward[1] = -20.0f;
    v->forward[2] = -60.0f;
    v->up[1] = 1.0f;
    v->fov_y = 1.2f;
    v->aspect = 1.5f;
    v->near_z = 0.5f;
    v->far_z = 500.0f;
    v->viewport_height = 800.0f;
}

/* ---- scene calls ----------------------------------------------------------------- */

/* tclod_scene_create with its k-th allocation failing (mode), k = 1, 2, ...:
 * NOMEM, *out untouched and nothing held until it succeeds. */
static void scene_create_under_failure(failure_mode mode) {
    test_alloc t;
    tclod_allocator hooks;
    tclod_scene *const sentinel = (tclod_scene *)(void *)&t;
    size_t k;
    test_alloc_init(&t);
    hooks = test_alloc_hooks(&t);
    for (k = 1; k <= MAX_ALLOCATIONS_PER_CALL; ++k) {
        tclod_scene *s = sentinel;
        tclod_status st;
        arm(&t, mode, k);
        st = tclod_scene_create(&hooks, &s);
        if (st == TCLOD_OK) {
            tclod_scene_destroy(s);
            break;
        }
        assert_int_equal(st, TCLOD_ERR_NOMEM);
        assert_ptr_equal(s, sentinel);
        assert_nothing_left(&t);
    }
    assert_true(k > 1 && k <= MAX_ALLOCATIONS_PER_CALL);
    assert_nothing_left(&t);
}

/* A mixed selector over s and m that has selected once within half the
 * model's total cost; asserts that the select succeeds and fits. */
static tclod_selector *select_half_budget(tclod_scene *s, table_model *m) {
    tclod_selector *sel = NULL;
    tclod_selector_desc d;
    tclod_frame frame;
    tclod_stats st;
    selector_desc(&d, TCLOD_SOLVER_MIXED, m);
    assert_int_equal(tclod_selector_create(s, &d, NULL, &sel), TCLOD_OK);
    frame.view = NULL;
    frame.budget = 0.5 * total_cost(m);
    frame.solve_seconds = 0.0;
    frame.max_iterations = 0;
    assert_int_equal(tclod_select(sel, &frame, &st), TCLOD_OK);
    assert_true(st.cost <= frame.budget);
    return sel;
}

static void add_under_failure(failure_mode mode) {
    /* 700 nodes (roots, and children of random earlier nodes, with and
     * without bounds) and 300 smooth objects, each add retried until it
     * succeeds with its k-th allocation failing (mode). A failed add
     * leaves the counts, the memory and the out id as they were; an add that
     * needs no memory succeeds at once. At the end the parents are those
     * asked for, and the scene selects within its budget. */
    test_alloc t;
    tclod_allocator hooks;
    tclod_scene *s = NULL;
    tclod_selector *sel = NULL;
    table_model m;
    table_rng rng;
    tclod_id parents[700];
    size_t failures = 0, first_try = 0;
    uint32_t i;
    test_alloc_init(&t);
    hooks = test_alloc_hooks(&t);
    table_init(&m);
    table_rng_seed(&rng, 81);
    assert_int_equal(tclod_scene_create(&hooks, &s), TCLOD_OK);
    for (i = 0; i < 700; ++i) {
        const float bounds[4] = {(float)i, 0.0f, -(float)(i % 50u), 1.5f};
        size_t k;
        parents[i] = i < 4 ? TCLOD_NONE : table_rng_below(&rng, i);
        for (k = 1; k <= MAX_ALLOCATIONS_PER_CALL; ++k) {
            size_t bytes = t.outstanding_bytes;
            tclod_id id = 777777;
            tclod_status status;
            arm(&t, mode, k);
            status = table_add_node(&m, s, parents[i], (i % 3u) ? bounds : NULL, 1.0, 1.0, &id);
            if (status == TCLOD_OK) {
                assert_int_equal(id, i);
                break;
            }
            assert_int_equal(status, TCLOD_ERR_NOMEM);
            assert_int_equal(id, 777777);
            assert_int_equal(tclod_scene_node_count(s), i);
            assert_int_equal(t.outstanding_bytes, bytes);
            failures++;
        }
        assert_true(k <= MAX_ALLOCATIONS_PER_CALL);
        first_try += k == 1;
    }
    assert_true(failures > 0);    /* the arrays grew ... */
    assert_true(first_try > 600); /* ... but only now and then */
    failures = 0;
    for (i = 0; i < 300; ++i) {
        const float bounds[4] = {(float)(i % 17u) * 3.0f, 0.0f, (float)(i / 17u) * 3.0f, 1.0f};
        size_t k;
        for (k = 1; k <= MAX_ALLOCATIONS_PER_CALL; ++k) {
            size_t bytes = t.outstanding_bytes;
            tclod_id id = 777777;
            tclod_status status;
            arm(&t, mode, k);
            status = table_add_smooth(&m, s, bounds, TABLE_POWER, 2.0, 0.5, 1.0, 1.0, 0.0, &id);
            if (status == TCLOD_OK) {
                assert_int_equal(id, i);
                break;
            }
            assert_int_equal(status, TCLOD_ERR_NOMEM);
            assert_int_equal(id, 777777);
            assert_int_equal(tclod_scene_smooth_count(s), i);
            assert_int_equal(t.outstanding_bytes, bytes);
            failures++;
        }
        assert_true(k <= MAX_ALLOCATIONS_PER_CALL);
    }
    assert_true(failures > 0);
    test_alloc_fail_from(&t, 0);
    assert_int_equal(tclod_scene_node_count(s), 700);
    assert_int_equal(tclod_scene_smooth_count(s), 300);
    for (i = 0; i < 700; ++i)
        assert_int_equal(tclod_scene_parent(s, i), parents[i]);
    sel = select_half_budget(s, &m);
    tclod_selector_destroy(sel);
    tclod_scene_destroy(s);
    assert_nothing_left(&t);
    table_free(&m);
}

/* A box for the k-th node: axis-aligned or turned 30 degrees about y. */
static tclod_bounds some_box(uint32_t k) {
    const double c[3] = {(double)k, 0.0, -10.0}, half[3] = {1.0, 2.0, 0.5};
    const double a = 0.5235987755982988, co = cos(a), si = sin(a);
    const double axes[9] = {co, 0.0, -si, 0.0, 2.0, 0.0, 0.5 * si, 0.0, 0.5 * co};
    return (k % 2u) ? tclod_bounds_aabb(c, half) : tclod_bounds_obb(c, axes);
}

static void edits_under_failure(failure_mode mode) {
    /* 600 nodes with boxes, a third of them additive (a second id each),
     * added with their k-th allocation failing until they succeed; then every
     * tenth node moved from its box to a sphere and back to a box, and
     * hierarchies removed and added again until the slab of children is made
     * again, each call retried the same way. A failed call returns
     * TCLOD_ERR_NOMEM and changes nothing: the counts, the memory, the bounds
     * read back. The scene then selects within its budget, every node drawn
     * live. */
    test_alloc t;
    tclod_allocator hooks;
    tclod_scene *s = NULL;
    tclod_selector *sel = NULL;
    tclod_selector_desc d;
    table_model m;
    table_rng rng;
    tclod_frame frame;
    tclod_stats st;
    size_t failures = 0, n, k;
    const tclod_id *ids;
    uint32_t i, round;
    test_alloc_init(&t);
    hooks = test_alloc_hooks(&t);
    table_init(&m);
    table_rng_seed(&rng, 83);
    assert_int_equal(tclod_scene_create(&hooks, &s), TCLOD_OK);
    for (i = 0; i < 600; ++i) {
        tclod_node_desc nd;
        tclod_node_desc_default(&nd);
        nd.parent = i < 6 || m.count == 0 ? TCLOD_NONE : table_rng_below(&rng, m.count);
        while (nd.parent != TCLOD_NONE && m.kind[nd.parent] == TABLE_NONE)
            nd.parent = nd.parent == 0u ? TCLOD_NONE : nd.parent - 1u;
        nd.bounds = some_box(i);
        nd.refine = i % 3u == 0u ? TCLOD_REFINE_ADD : TCLOD_REFINE_REPLACE;
        for (k = 1; k <= MAX_ALLOCATIONS_PER_CALL; ++k) {
            size_t bytes = t.outstanding_bytes;
            uint32_t count = tclod_scene_node_count(s);
            tclod_id id = 777777;
            tclod_status status;
            arm(&t, mode, k);
            status = table_add_node_desc(&m, s, &nd, 1.0, 1.0, &id);
            if (status == TCLOD_OK)
                break;
            assert_int_equal(status, TCLOD_ERR_NOMEM);
            assert_int_equal(id, 777777);
            assert_int_equal(tclod_scene_node_count(s), count);
            assert_int_equal(t.outstanding_bytes, bytes);
            failures++;
        }
        assert_true(k <= MAX_ALLOCATIONS_PER_CALL);
    }
    assert_true(failures > 0);
    for (i = 0; i < m.count; i += 10) {
        tclod_bounds sphere = tclod_bounds_sphere((double)i, 1.0, 2.0, 3.0), box = some_box(i + 1u);
        tclod_bounds before, after;
        if (m.kind[i] == TABLE_NONE)
            continue;
        test_alloc_fail_from(&t, 0);
        assert_int_equal(tclod_scene_set_node_bounds(s, i, &sphere), TCLOD_OK);
        for (k = 1; k <= MAX_ALLOCATIONS_PER_CALL; ++k) {
            size_t bytes = t.outstanding_bytes;
            tclod_status status;
            assert_int_equal(tclod_scene_node_bounds(s, i, &before), TCLOD_OK);
            arm(&t, mode, k);
            status = tclod_scene_set_node_bounds(s, i, &box);
            if (status == TCLOD_OK)
                break;
            assert_int_equal(status, TCLOD_ERR_NOMEM);
            assert_int_equal(tclod_scene_node_bounds(s, i, &after), TCLOD_OK);
            assert_memory_equal(&before, &after, sizeof before);
            assert_int_equal(t.outstanding_bytes, bytes);
        }
        assert_true(k <= MAX_ALLOCATIONS_PER_CALL);
    }
    /* remove hierarchies and add nodes again: the slab fills with moved
     * blocks and is made again */
    for (round = 0; round < 40; ++round) {
        tclod_node_desc nd;
        test_alloc_fail_from(&t, 0);
        for (i = 0; i < m.count; ++i)
            if (m.kind[i] != TABLE_NONE && m.parent[i] != TCLOD_NONE &&
                table_rng_below(&rng, 8) == 0)
                assert_int_equal(table_remove_node(&m, s, i), TCLOD_OK);
        for (i = 0; i < 40; ++i) {
            uint32_t pick = table_rng_below(&rng, m.count);
            tclod_node_desc_default(&nd);
            while (m.kind[pick] == TABLE_NONE)
                pick = (pick + 1u) % m.count;
            nd.parent = pick;
            nd.refine = i % 4u == 0u ? TCLOD_REFINE_ADD : TCLOD_REFINE_REPLACE;
            for (k = 1; k <= MAX_ALLOCATIONS_PER_CALL; ++k) {
                size_t bytes = t.outstanding_bytes;
                uint32_t count = tclod_scene_node_count(s);
                tclod_status status;
                arm(&t, mode, k);
                status = table_add_node_desc(&m, s, &nd, 1.0, 1.0, NULL);
                if (status == TCLOD_OK)
                    break;
                assert_int_equal(status, TCLOD_ERR_NOMEM);
                assert_int_equal(tclod_scene_node_count(s), count);
                assert_int_equal(t.outstanding_bytes, bytes);
            }
            assert_true(k <= MAX_ALLOCATIONS_PER_CALL);
        }
    }
    test_alloc_fail_from(&t, 0);
    selector_desc(&d, TCLOD_SOLVER_GREEDY, &m);
    assert_int_equal(tclod_selector_create(s, &d, NULL, &sel), TCLOD_OK);
    frame.view = NULL;
    frame.budget = 0.5 * total_cost(&m);
    frame.solve_seconds = 0.0;
    frame.max_iterations = 0;
    assert_int_equal(tclod_select(sel, &frame, &st), TCLOD_OK);
    assert_true(st.cost <= frame.budget);
    assert_int_equal(tclod_selector_cut(sel, &ids, &n), TCLOD_OK);
    for (k = 0; k < n; ++k)
        assert_true(tclod_scene_node_live(s, ids[k]));
    tclod_selector_destroy(sel);
    tclod_scene_destroy(s);
    assert_nothing_left(&t);
    table_free(&m);
}

static void prepare_under_failure(failure_mode mode) {
    /* A scene of 400 nodes and 250 smooth objects, never prepared: first
     * tclod_scene_smooth_order, then (after 100 more of each)
     * tclod_scene_prepare, each retried with its k-th allocation failing
     * (mode). Failures write nothing and hold no memory; afterwards the
     * order is a permutation and a prepared scene needs no allocation to be
     * prepared again. */
    test_alloc t;
    tclod_allocator hooks;
    tclod_scene *s = NULL;
    table_model m;
    table_rng rng;
    const tclod_id *order = NULL;
    unsigned char seen[350];
    uint32_t count = 0, i;
    size_t k;
    test_alloc_init(&t);
    hooks = test_alloc_hooks(&t);
    table_init(&m);
    assert_int_equal(tclod_scene_create(&hooks, &s), TCLOD_OK);
    build_scene(&m, s, 82, 50, 200, 250);
    for (k = 1; k <= MAX_ALLOCATIONS_PER_CALL; ++k) {
        const tclod_id *const sentinel = (const tclod_id *)(void *)&t;
        size_t bytes = t.outstanding_bytes;
        tclod_status status;
        order = sentinel;
        count = 77;
        arm(&t, mode, k);
        status = tclod_scene_smooth_order(s, &order, &count);
        if (status == TCLOD_OK)
            break;
        assert_int_equal(status, TCLOD_ERR_NOMEM);
        assert_ptr_equal(order, sentinel);
        assert_int_equal(count, 77);
        assert_int_equal(t.outstanding_bytes, bytes);
    }
    assert_true(k > 1 && k <= MAX_ALLOCATIONS_PER_CALL);
    test_alloc_fail_from(&t, 0);
    assert_int_equal(count, 250);

    table_rng_seed(&rng, 83);
    assert_int_equal(table_chains(&m, s, &rng, 25, 4, 40.0f), TCLOD_OK);
    add_smooth_objects(&m, s, &rng, 100, 40.0f);
    for (k = 1; k <= MAX_ALLOCATIONS_PER_CALL; ++k) {
        size_t bytes = t.outstanding_bytes;
        tclod_status status;
        arm(&t, mode, k);
        status = tclod_scene_prepare(s);
        if (status == TCLOD_OK)
            break;
        assert_int_equal(status, TCLOD_ERR_NOMEM);
        assert_int_equal(t.outstanding_bytes, bytes);
        assert_int_equal(tclod_scene_node_count(s), 500);
        assert_int_equal(tclod_scene_smooth_count(s), 350);
    }
    assert_true(k > 1 && k <= MAX_ALLOCATIONS_PER_CALL);
    /* prepared: asking again allocates nothing */
    test_alloc_fail_from(&t, 1);
    assert_int_equal(tclod_scene_prepare(s), TCLOD_OK);
    assert_int_equal(tclod_scene_smooth_order(s, &order, &count), TCLOD_OK);
    test_alloc_fail_from(&t, 0);
    assert_int_equal(count, 350);
    memset(seen, 0, sizeof seen);
    for (i = 0; i < count; ++i) {
        assert_true(order[i] < count && !seen[order[i]]);
        seen[order[i]] = 1;
    }
    tclod_scene_destroy(s);
    assert_nothing_left(&t);
    table_free(&m);
}

/* ---- selectors --------------------------------------------------------------- */

static void selector_create_reports_nomem_for_every_solver(void **state) {
    /* Every solver, both failure modes: each failure leaves *out alone and
     * holds no memory; the selector made in the end selects. */
    static const tclod_solver solvers[3] = {TCLOD_SOLVER_GREEDY, TCLOD_SOLVER_MIXED,
                                            TCLOD_SOLVER_ROBIN_HOOD};
    tclod_scene *s = NULL;
    table_model m;
    int solver, mode;
    (void)state;
    table_init(&m);
    assert_int_equal(tclod_scene_create(NULL, &s), TCLOD_OK);
    build_scene(&m, s, 84, 20, 0, 20);
    for (solver = 0; solver < 3; ++solver)
        for (mode = TRANSIENT; mode <= PERSISTENT; ++mode) {
            test_alloc t;
            tclod_allocator hooks;
            tclod_selector *const sentinel = (tclod_selector *)(void *)&t;
            tclod_selector *sel = sentinel;
            tclod_selector_desc d;
            tclod_frame frame;
            tclod_stats st;
            size_t k;
            test_alloc_init(&t);
            hooks = test_alloc_hooks(&t);
            selector_desc(&d, solvers[solver], &m);
            for (k = 1; k <= MAX_ALLOCATIONS_PER_CALL; ++k) {
                tclod_status status;
                sel = sentinel;
                arm(&t, (failure_mode)mode, k);
                status = tclod_selector_create(s, &d, &hooks, &sel);
                if (status == TCLOD_OK)
                    break;
                assert_int_equal(status, TCLOD_ERR_NOMEM);
                assert_ptr_equal(sel, sentinel);
                assert_nothing_left(&t);
            }
            if (k == 1 || k > MAX_ALLOCATIONS_PER_CALL)
                fail_msg("solver %d, %s: created after %lu tries", solver, mode_name[mode],
                         (unsigned long)k);
            test_alloc_fail_from(&t, 0);
            frame.view = NULL;
            frame.budget = 0.5 * total_cost(&m);
            frame.solve_seconds = 0.0;
            frame.max_iterations = 0;
            assert_int_equal(tclod_select(sel, &frame, &st), TCLOD_OK);
            assert_true(st.cost <= frame.budget);
            tclod_selector_destroy(sel);
            assert_nothing_left(&t);
        }
    tclod_scene_destroy(s);
    table_free(&m);
}

/* The resident bytes a model of sizes and residency says (ids the table
 * model has as nodes; smooth objects apart). */
static double resident_sum(const table_model *m, const uint8_t *resident, const double *bytes) {
    double sum = 0.0;
    uint32_t i;
    for (i = 0; i < m->count; ++i)
        if (m->kind[i] != TABLE_NONE && resident[i])
            sum += bytes[i];
    return sum;
}

static void streaming_scene_under_failure(failure_mode mode) {
    /* 500 nodes, every third added not resident, each with a size of its id
     * in bytes (whole numbers: every sum is exact), every fifth additive,
     * each add retried with its k-th allocation failing until it succeeds;
     * between adds, with every allocation failing, a node's residency
     * flipped and another's size changed (calls that allocate nothing).
     * A failed add returns TCLOD_ERR_NOMEM and changes nothing: the count,
     * the memory, the resident bytes, the residency and size of every node.
     * Then 100 smooth objects the same way, sized and half of them unloaded
     * with every allocation failing, and subtrees removed likewise; at the
     * end the resident bytes are the model's and the scene selects within
     * its budget, drawing only resident nodes. */
    test_alloc t;
    tclod_allocator hooks;
    tclod_scene *s = NULL;
    tclod_selector *sel = NULL;
    table_model m;
    table_rng rng;
    uint8_t resident[1024];
    double bytes[1024], smooth_bytes = 0.0;
    const tclod_id *ids;
    size_t failures = 0, n, k;
    uint32_t i;
    test_alloc_init(&t);
    hooks = test_alloc_hooks(&t);
    table_init(&m);
    table_rng_seed(&rng, 221);
    memset(resident, 0, sizeof resident);
    memset(bytes, 0, sizeof bytes);
    assert_int_equal(tclod_scene_create(&hooks, &s), TCLOD_OK);
    for (i = 0; i < 500; ++i) {
        tclod_node_desc nd;
        tclod_id id = 777777;
        tclod_node_desc_default(&nd);
        nd.parent = i < 5 ? TCLOD_NONE : table_rng_below(&rng, m.count);
        while (nd.parent != TCLOD_NONE && m.kind[nd.parent] == TABLE_NONE)
            nd.parent = nd.parent == 0u ? TCLOD_NONE : nd.parent - 1u;
        nd.refine = i % 5u == 0u ? TCLOD_REFINE_ADD : TCLOD_REFINE_REPLACE;
        nd.not_resident = i % 3u == 0u;
        nd.bytes = (double)m.count;
        for (k = 1; k <= MAX_ALLOCATIONS_PER_CALL; ++k) {
            size_t held = t.outstanding_bytes;
            uint32_t count = tclod_scene_node_count(s), j;
            tclod_status status;
            arm(&t, mode, k);
            status = table_add_node_desc(&m, s, &nd, 1.0 + (double)(i % 7u), 1.0, &id);
            if (status == TCLOD_OK)
                break;
            assert_int_equal(status, TCLOD_ERR_NOMEM);
            assert_int_equal(id, 777777);
            assert_int_equal(tclod_scene_node_count(s), count);
            assert_int_equal(t.outstanding_bytes, held);
            assert_true(tclod_scene_resident_bytes(s) == resident_sum(&m, resident, bytes));
            for (j = 0; j < count; ++j)
                if (m.kind[j] != TABLE_NONE)
                    assert_true(tclod_scene_node_resident(s, j) == resident[j] &&
                                tclod_scene_node_bytes(s, j) == bytes[j]);
            failures++;
        }
        assert_true(k <= MAX_ALLOCATIONS_PER_CALL);
        assert_true(id < 1024);
        resident[id] = !nd.not_resident;
        bytes[id] = nd.bytes;
        if (i % 7u == 6u) {
            tclod_id a = table_rng_below(&rng, m.count), b = table_rng_below(&rng, m.count);
            test_alloc_fail_from(&t, 1);
            if (m.kind[a] != TABLE_NONE) {
                assert_int_equal(tclod_scene_set_resident(s, a, !resident[a]), TCLOD_OK);
                resident[a] = !resident[a];
            }
            if (m.kind[b] != TABLE_NONE) {
                assert_int_equal(tclod_scene_set_node_bytes(s, b, 3.0 * (double)b), TCLOD_OK);
                bytes[b] = 3.0 * (double)b;
            }
        }
        test_alloc_fail_from(&t, 0);
        assert_true(tclod_scene_resident_bytes(s) == resident_sum(&m, resident, bytes));
    }
    assert_true(failures > 0);
    for (i = 0; i < 100; ++i) {
        const float b[4] = {(float)(i % 10u) * 4.0f, 0.0f, (float)(i / 10u) * 4.0f, 1.0f};
        tclod_id id = 777777;
        for (k = 1; k <= MAX_ALLOCATIONS_PER_CALL; ++k) {
            size_t held = t.outstanding_bytes;
            tclod_status status;
            arm(&t, mode, k);
            status = table_add_smooth(&m, s, b, TABLE_POWER, 2.0, 0.5, 1.0, 1.0, 0.0, &id);
            if (status == TCLOD_OK)
                break;
            assert_int_equal(status, TCLOD_ERR_NOMEM);
            assert_int_equal(tclod_scene_smooth_count(s), i);
            assert_int_equal(t.outstanding_bytes, held);
            assert_true(tclod_scene_resident_bytes(s) ==
                        resident_sum(&m, resident, bytes) + smooth_bytes);
        }
        assert_true(k <= MAX_ALLOCATIONS_PER_CALL);
        test_alloc_fail_from(&t, 1);
        assert_int_equal(tclod_scene_set_smooth_bytes(s, id, 10.0), TCLOD_OK);
        if (i % 2u)
            assert_int_equal(tclod_scene_set_smooth_resident(s, id, 0), TCLOD_OK);
        else
            smooth_bytes += 10.0;
        test_alloc_fail_from(&t, 0);
        assert_true(tclod_scene_resident_bytes(s) ==
                    resident_sum(&m, resident, bytes) + smooth_bytes);
    }
    /* removals allocate nothing: subtrees of resident nodes and of nodes not
     * resident leave the sum as the model has it */
    test_alloc_fail_from(&t, 1);
    for (i = 0; i < 20; ++i) {
        tclod_id v = table_rng_below(&rng, m.count);
        if (m.kind[v] == TABLE_NONE)
            continue;
        assert_int_equal(table_remove_node(&m, s, v), TCLOD_OK);
        assert_true(tclod_scene_resident_bytes(s) ==
                    resident_sum(&m, resident, bytes) + smooth_bytes);
    }
    test_alloc_fail_from(&t, 0);
    sel = select_half_budget(s, &m);
    assert_int_equal(tclod_selector_cut(sel, &ids, &n), TCLOD_OK);
    for (k = 0; k < n; ++k)
        assert_true(tclod_scene_node_resident(s, ids[k]));
    tclod_selector_destroy(sel);
    tclod_scene_destroy(s);
    assert_nothing_left(&t);
    table_free(&m);
}

/* Selects one frame on sel, whose allocations come from t, with the k-th
 * allocation failing (k = 1, 2, ...) in the given mode until it succeeds;
 * every failure must return TCLOD_ERR_NOMEM, leave the result and the stats
 * alone and hold no more memory than before. Returns the failures. */
static size_t select_through_failures(tclod_selector *sel, test_alloc *t, failure_mode mode,
                                      const tclod_frame *frame, uint32_t smooth, outcome *before,
                                      outcome *after, tclod_stats *st) {
    size_t k;
    take_outcome(sel, smooth, before);
    for (k = 1; k <= MAX_ALLOCATIONS_PER_CALL; ++k) {
        size_t bytes = t->outstanding_bytes;
        tclod_status status;
        poison_stats(st);
        arm(t, mode, k);
        status = tclod_select(sel, frame, st);
        if (status == TCLOD_OK)
            break;
        assert_int_equal(status, TCLOD_ERR_NOMEM);
        assert_stats_untouched(st);
        take_outcome(sel, smooth, after);
        assert_same_outcome(before, after, "a select that ran out of memory");
        assert_int_equal(t->outstanding_bytes, bytes);
    }
    assert_true(k <= MAX_ALLOCATIONS_PER_CALL);
    test_alloc_fail_from(t, 0);
    return k - 1;
}

/* A selector whose buffers come from a failing allocator beside a reference
 * selector that never fails, over a scene of malloc'd memory, and copies of
 * their outcomes. */
typedef struct rig {
    test_alloc t;
    tclod_allocator hooks;
    tclod_scene *s;
    tclod_selector *sel, *ref;
    table_model m;
    outcome before, after, expect;
} rig;

static void rig_open(rig *r, tclod_solver solver, int split, uint64_t seed, uint32_t chains,
                     uint32_t random_nodes, uint32_t smooth) {
    tclod_selector_desc d;
    memset(r, 0, sizeof *r);
    test_alloc_init(&r->t);
    r->hooks = test_alloc_hooks(&r->t);
    table_init(&r->m);
    assert_int_equal(tclod_scene_create(NULL, &r->s), TCLOD_OK);
    build_scene(&r->m, r->s, seed, chains, random_nodes, smooth);
    selector_desc(&d, solver, &r->m);
    d.mixed.split_smooth = split;
    assert_int_equal(tclod_selector_create(r->s, &d, &r->hooks, &r->sel), TCLOD_OK);
    assert_int_equal(tclod_selector_create(r->s, &d, NULL, &r->ref), TCLOD_OK);
    outcome_init(&r->before, 1000, 200);
    outcome_init(&r->after, 1000, 200);
    outcome_init(&r->expect, 1000, 200);
}

/* Frees the rig; the failing allocator must hold nothing. */
static void rig_close(rig *r) {
    outcome_free(&r->expect);
    outcome_free(&r->after);
    outcome_free(&r->before);
    tclod_selector_destroy(r->ref);
    tclod_selector_destroy(r->sel);
    assert_nothing_left(&r->t);
    tclod_scene_destroy(r->s);
    table_free(&r->m);
}

static void selects_that_run_out_of_memory_change_nothing_for_every_solver(void **state) {
    /* The scene uses malloc; only the selector's buffers come from the
     * failing allocator. Four frames per solver and failure mode, with a
     * reference selector that never fails beside it: frame 0 grows the
     * buffers, the scene then grows (more chains, nodes and smooth objects)
     * so that frame 1 must grow them again, frames 2 and 3 move the view and
     * need no memory at all (they succeed at once, even with every
     * allocation failing). After every failure the previous result is kept;
     * after every success the result and the stats are those of the
     * reference selector, bit for bit, warm start included. */
    static const tclod_solver solvers[3] = {TCLOD_SOLVER_GREEDY, TCLOD_SOLVER_MIXED,
                                            TCLOD_SOLVER_ROBIN_HOOD};
    int solver, mode;
    (void)state;
    for (solver = 0; solver < 3; ++solver)
        for (mode = TRANSIENT; mode <= PERSISTENT; ++mode) {
            rig r;
            table_rng rng;
            int frame;
            rig_open(&r, solvers[solver], solver == 1, 85, 40, 100, 40);
            for (frame = 0; frame < 4; ++frame) {
                tclod_view v;
                tclod_frame f;
                tclod_stats st, ref_st;
                size_t failures;
                if (frame == 1) {
                    table_rng_seed(&rng, 86);
                    assert_int_equal(table_chains(&r.m, r.s, &rng, 60, 4, 40.0f), TCLOD_OK);
                    assert_int_equal(
                        table_random_hierarchy(&r.m, r.s, &rng, 200, 10, TABLE_DIMINISHING),
                        TCLOD_OK);
                    add_smooth_objects(&r.m, r.s, &rng, 100, 40.0f);
                }
                side_view(&v, frame);
                f.view = frame == 0 ? NULL : &v;
                f.budget = (0.2 + 0.1 * frame) * total_cost(&r.m);
                f.solve_seconds = 0.0;
                f.max_iterations = 0;
                failures = select_through_failures(r.sel, &r.t, (failure_mode)mode, &f,
                                                   r.m.smooth.count, &r.before, &r.after, &st);
                if ((frame < 2) != (failures > 0))
                    fail_msg("solver %d, %s, frame %d: %lu failures", solver, mode_name[mode],
                             frame, (unsigned long)failures);
                assert_int_equal(tclod_select(r.ref, &f, &ref_st), TCLOD_OK);
                take_outcome(r.sel, r.m.smooth.count, &r.after);
                take_outcome(r.ref, r.m.smooth.count, &r.expect);
                assert_same_outcome(&r.after, &r.expect, "after failures, against the reference");
                assert_same_stats(&st, &ref_st);
                assert_true(st.cost <= f.budget);
            }
            rig_close(&r);
        }
}

static void selects_sharing_the_scene_allocator_leak_nothing_for_every_solver(void **state) {
    /* Scene and selector share one failing allocator and the scene is never
     * prepared, so the first select also builds the child index and the
     * smooth quadtree (which may stay built, a cache). Every failure returns
     * TCLOD_ERR_NOMEM with an empty result; the select that succeeds in the
     * end keeps the budget; once everything is destroyed no byte is left. */
    static const tclod_solver solvers[3] = {TCLOD_SOLVER_GREEDY, TCLOD_SOLVER_MIXED,
                                            TCLOD_SOLVER_ROBIN_HOOD};
    int solver, mode;
    (void)state;
    for (solver = 0; solver < 3; ++solver)
        for (mode = TRANSIENT; mode <= PERSISTENT; ++mode) {
            test_alloc t;
            tclod_allocator hooks;
            tclod_scene *s = NULL;
            tclod_selector *sel = NULL;
            tclod_selector_desc d;
            table_model m;
            tclod_frame f;
            tclod_stats st;
            size_t k;
            test_alloc_init(&t);
            hooks = test_alloc_hooks(&t);
            table_init(&m);
            assert_int_equal(tclod_scene_create(&hooks, &s), TCLOD_OK);
            build_scene(&m, s, 87, 30, 60, 30);
            selector_desc(&d, solvers[solver], &m);
            assert_int_equal(tclod_selector_create(s, &d, &hooks, &sel), TCLOD_OK);
            f.view = NULL;
            f.budget = 0.4 * total_cost(&m);
            f.solve_seconds = 0.0;
            f.max_iterations = 0;
            for (k = 1; k <= MAX_ALLOCATIONS_PER_CALL; ++k) {
                const tclod_id *ids = NULL;
                const tclod_smooth_group *groups = NULL;
                size_t n = 99, ng = 99;
                tclod_status status;
                arm(&t, (failure_mode)mode, k);
                status = tclod_select(sel, &f, &st);
                if (status == TCLOD_OK)
                    break;
                assert_int_equal(status, TCLOD_ERR_NOMEM);
                assert_int_equal(tclod_selector_cut(sel, &ids, &n), TCLOD_OK);
                assert_int_equal(tclod_selector_smooth_groups(sel, &groups, &ng), TCLOD_OK);
                assert_int_equal(n, 0);
                assert_int_equal(ng, 0);
            }
            if (k == 1 || k > MAX_ALLOCATIONS_PER_CALL)
                fail_msg("solver %d, %s: selected after %lu tries", solver, mode_name[mode],
                         (unsigned long)k);
            test_alloc_fail_from(&t, 0);
            assert_true(st.cost <= f.budget);
            tclod_selector_destroy(sel);
            tclod_scene_destroy(s);
            assert_nothing_left(&t);
            table_free(&m);
        }
}

static void select_begin_reports_nomem_and_steps_allocate_nothing_for_every_solver(void **state) {
    /* The resumable selection: tclod_select_begin grows the buffers (its only
     * allocation) and is retried with the k-th allocation failing in both
     * modes; a failed begin leaves no solve pending and the previous result
     * alone. The steps that follow, in slices of 7 iterations, run with every
     * allocation failing and still succeed; the result equals that of
     * tclod_select on a selector that never failed. Frame 1 follows a grown
     * scene, so begin must grow the buffers again. */
    static const tclod_solver solvers[3] = {TCLOD_SOLVER_GREEDY, TCLOD_SOLVER_MIXED,
                                            TCLOD_SOLVER_ROBIN_HOOD};
    int solver, mode;
    (void)state;
    for (solver = 0; solver < 3; ++solver)
        for (mode = TRANSIENT; mode <= PERSISTENT; ++mode) {
            rig r;
            table_rng rng;
            int frame;
            rig_open(&r, solvers[solver], 0, 89, 30, 80, 30);
            for (frame = 0; frame < 2; ++frame) {
                tclod_frame f;
                tclod_stats st, ref_st;
                size_t k;
                int done = 0, steps = 0;
                if (frame == 1) {
                    table_rng_seed(&rng, 90);
                    assert_int_equal(table_chains(&r.m, r.s, &rng, 200, 4, 40.0f), TCLOD_OK);
                    add_smooth_objects(&r.m, r.s, &rng, 100, 40.0f);
                }
                f.view = NULL;
                f.budget = 0.3 * total_cost(&r.m);
                f.solve_seconds = 0.0;
                f.max_iterations = 0;
                take_outcome(r.sel, r.m.smooth.count, &r.before);
                for (k = 1; k <= MAX_ALLOCATIONS_PER_CALL; ++k) {
                    size_t bytes = r.t.outstanding_bytes;
                    tclod_status status;
                    arm(&r.t, (failure_mode)mode, k);
                    status = tclod_select_begin(r.sel, &f);
                    if (status == TCLOD_OK)
                        break;
                    assert_int_equal(status, TCLOD_ERR_NOMEM);
                    assert_int_equal(tclod_select_pending(r.sel), 0);
                    take_outcome(r.sel, r.m.smooth.count, &r.after);
                    assert_same_outcome(&r.before, &r.after, "a begin that ran out of memory");
                    assert_int_equal(r.t.outstanding_bytes, bytes);
                }
                if (k == 1 || k > MAX_ALLOCATIONS_PER_CALL)
                    fail_msg("solver %d, %s, frame %d: began after %lu tries", solver,
                             mode_name[mode], frame, (unsigned long)k);
                test_alloc_fail_from(&r.t, 1);
                while (!done) {
                    assert_int_equal(tclod_select_step(r.sel, 0.0, 7, &done, &st), TCLOD_OK);
                    assert_true(++steps < 100000);
                }
                test_alloc_fail_from(&r.t, 0);
                assert_int_equal(tclod_select(r.ref, &f, &ref_st), TCLOD_OK);
                take_outcome(r.sel, r.m.smooth.count, &r.after);
                take_outcome(r.ref, r.m.smooth.count, &r.expect);
                assert_same_outcome(&r.after, &r.expect,
                                    "resumed after failures, against tclod_select");
                assert_true(st.cost <= f.budget);
            }
            rig_close(&r);
        }
}

/* A selector's load requests and evictions, copied. */
typedef struct stream_lists {
    tclod_stream_item items[2][1200];
    size_t n[2];
} stream_lists;

static void take_lists(const tclod_selector *sel, stream_lists *l) {
    const tclod_stream_item *items = NULL;
    int k;
    for (k = 0; k < 2; ++k) {
        assert_int_equal(k == 0 ? tclod_selector_requests(sel, &items, &l->n[k])
                                : tclod_selector_evictions(sel, &items, &l->n[k]),
                         TCLOD_OK);
        assert_true(l->n[k] <= 1200);
        if (l->n[k])
            memcpy(l->items[k], items, l->n[k] * sizeof *items);
    }
}

static void assert_same_lists(const stream_lists *a, const stream_lists *b, const char *what) {
    int k;
    for (k = 0; k < 2; ++k)
        if (a->n[k] != b->n[k] ||
            (a->n[k] && memcmp(a->items[k], b->items[k], a->n[k] * sizeof a->items[k][0]) != 0))
            fail_msg("%s: the %s differ (%lu and %lu items)", what,
                     k == 0 ? "requests" : "evictions", (unsigned long)a->n[k],
                     (unsigned long)b->n[k]);
}

/* Flips the residency of about a tenth of the live nodes and smooth objects,
 * with every allocation of t failing (the calls allocate nothing). */
static void flip_some(table_model *m, tclod_scene *s, table_rng *rng, test_alloc *t) {
    uint32_t i;
    test_alloc_fail_from(t, 1);
    for (i = 0; i < m->count; ++i)
        if (m->kind[i] != TABLE_NONE && table_rng_below(rng, 10) == 0)
            assert_int_equal(tclod_scene_set_resident(s, i, !tclod_scene_node_resident(s, i)),
                             TCLOD_OK);
    for (i = 0; i < m->smooth.count; ++i)
        if (table_rng_below(rng, 10) == 0)
            assert_int_equal(
                tclod_scene_set_smooth_resident(s, i, !tclod_scene_smooth_resident(s, i)),
                TCLOD_OK);
    test_alloc_fail_from(t, 0);
}

static void streaming_selects_that_run_out_of_memory_change_nothing_for_every_solver(void **state) {
    /* As the test above, with streaming: a scene all resident and a
     * selector without a stream desc select first (the common buffers
     * grow); then the streaming buffers must grow, either because the
     * selector is given a stream desc (loads, a memory budget) or because
     * a tenth of the nodes become not resident; then the scene grows by
     * chains added not resident with sizes and flips again (everything
     * grows); then it only flips (no memory needed: the select succeeds at
     * once). A reference selector with the same desc, never failing, sees
     * the same frames. Each failure returns TCLOD_ERR_NOMEM and leaves the
     * result, the stats, the load requests and the evictions as they were;
     * each success matches the reference bit for bit and draws only
     * resident nodes. */
    static const tclod_solver solvers[3] = {TCLOD_SOLVER_GREEDY, TCLOD_SOLVER_MIXED,
                                            TCLOD_SOLVER_ROBIN_HOOD};
    static stream_lists lists_before, lists_after, lists_ref;
    int solver, mode, trigger;
    (void)state;
    for (solver = 0; solver < 3; ++solver)
        for (mode = TRANSIENT; mode <= PERSISTENT; ++mode)
            for (trigger = 0; trigger < 2; ++trigger) {
                rig r;
                table_rng rng;
                int frame;
                rig_open(&r, solvers[solver], solver == 1, 221, 40, 100, 40);
                table_rng_seed(&rng, 222);
                for (frame = 0; frame < 4; ++frame) {
                    tclod_frame f;
                    tclod_stats st, ref_st;
                    size_t failures = 0, k, i, n;
                    const tclod_id *ids;
                    if (frame == 1 && trigger == 0) {
                        tclod_stream_desc sd;
                        memset(&sd, 0, sizeof sd);
                        sd.max_requests = 16;
                        sd.memory_budget = 1e6;
                        assert_int_equal(tclod_selector_set_stream(r.sel, &sd), TCLOD_OK);
                        assert_int_equal(tclod_selector_set_stream(r.ref, &sd), TCLOD_OK);
                    } else if (frame == 1) {
                        flip_some(&r.m, r.s, &rng, &r.t);
                    } else if (frame == 2) {
                        uint32_t first = r.m.count;
                        assert_int_equal(table_chains(&r.m, r.s, &rng, 60, 4, 40.0f), TCLOD_OK);
                        for (i = first; i < r.m.count; ++i) {
                            assert_int_equal(
                                tclod_scene_set_node_bytes(r.s, (tclod_id)i, (double)(64u * i)),
                                TCLOD_OK);
                            if (i % 2u)
                                assert_int_equal(tclod_scene_set_resident(r.s, (tclod_id)i, 0),
                                                 TCLOD_OK);
                        }
                        flip_some(&r.m, r.s, &rng, &r.t);
                    } else if (frame == 3) {
                        flip_some(&r.m, r.s, &rng, &r.t);
                    }
                    f.view = NULL;
                    f.budget = (0.2 + 0.1 * frame) * total_cost(&r.m);
                    f.solve_seconds = 0.0;
                    f.max_iterations = 0;
                    take_outcome(r.sel, r.m.smooth.count, &r.before);
                    take_lists(r.sel, &lists_before);
                    for (k = 1; k <= MAX_ALLOCATIONS_PER_CALL; ++k) {
                        size_t held = r.t.outstanding_bytes;
                        tclod_status status;
                        poison_stats(&st);
                        arm(&r.t, (failure_mode)mode, k);
                        status = tclod_select(r.sel, &f, &st);
                        if (status == TCLOD_OK)
                            break;
                        assert_int_equal(status, TCLOD_ERR_NOMEM);
                        assert_stats_untouched(&st);
                        take_outcome(r.sel, r.m.smooth.count, &r.after);
                        assert_same_outcome(&r.before, &r.after,
                                            "a streaming select out of memory");
                        take_lists(r.sel, &lists_after);
                        assert_same_lists(&lists_before, &lists_after,
                                          "a streaming select out of memory");
                        assert_int_equal(r.t.outstanding_bytes, held);
                        failures++;
                    }
                    test_alloc_fail_from(&r.t, 0);
                    assert_true(k <= MAX_ALLOCATIONS_PER_CALL);
                    if ((frame < 3) != (failures > 0))
                        fail_msg("solver %d, %s, trigger %d, frame %d: %lu failures", solver,
                                 mode_name[mode], trigger, frame, (unsigned long)failures);
                    assert_int_equal(tclod_select(r.ref, &f, &ref_st), TCLOD_OK);
                    take_outcome(r.sel, r.m.smooth.count, &r.after);
                    take_outcome(r.ref, r.m.smooth.count, &r.expect);
                    assert_same_outcome(&r.after, &r.expect,
                                        "after failures, against the reference");
                    assert_same_stats(&st, &ref_st);
                    assert_int_equal(st.absent_roots, ref_st.absent_roots);
                    take_lists(r.sel, &lists_after);
                    take_lists(r.ref, &lists_ref);
                    assert_same_lists(&lists_after, &lists_ref, "against the reference");
                    assert_true(st.cost <= f.budget);
                    assert_int_equal(tclod_selector_cut(r.sel, &ids, &n), TCLOD_OK);
                    for (i = 0; i < n; ++i)
                        assert_true(tclod_scene_node_resident(r.s, ids[i]));
                }
                rig_close(&r);
            }
}

static void robin_hood_selects_after_the_first_allocate_nothing(void **state) {
    /* docs/api.md, "No allocation per frame" once buffers have grown, for
     * the Robin Hood solver (test_guarantees.c checks the greedy and mixed
     * ones): after the first select of a scene, 30 frames with moving views,
     * changing budgets and both misfit policies allocate nothing. */
    test_alloc t;
    tclod_allocator hooks;
    tclod_scene *s = NULL;
    tclod_selector *sel[2];
    tclod_selector_desc d;
    table_model m;
    tclod_frame f;
    size_t after_first;
    int i, p;
    (void)state;
    test_alloc_init(&t);
    hooks = test_alloc_hooks(&t);
    table_init(&m);
    assert_int_equal(tclod_scene_create(NULL, &s), TCLOD_OK);
    build_scene(&m, s, 88, 100, 200, 80);
    f.view = NULL;
    f.budget = 0.3 * total_cost(&m);
    f.solve_seconds = 0.0;
    f.max_iterations = 0;
    for (p = 0; p < 2; ++p) {
        selector_desc(&d, TCLOD_SOLVER_ROBIN_HOOD, &m);
        d.robin_hood.misfit = p ? TCLOD_MISFIT_COARSEST : TCLOD_MISFIT_DROP;
        assert_int_equal(tclod_selector_create(s, &d, &hooks, &sel[p]), TCLOD_OK);
        assert_int_equal(tclod_select(sel[p], &f, NULL), TCLOD_OK);
    }
    after_first = t.allocations;
    test_alloc_fail_from(&t, 1);
    for (i = 0; i < 30; ++i) {
        tclod_view v;
        tclod_stats st;
        side_view(&v, i % 12);
        f.view = i % 3 ? &v : NULL;
        f.budget = (0.05 + 0.03 * (double)(i % 10)) * total_cost(&m);
        assert_int_equal(tclod_select(sel[i % 2], &f, &st), TCLOD_OK);
        assert_true(st.cost <= f.budget);
    }
    test_alloc_fail_from(&t, 0);
    assert_int_equal(t.allocations, after_first);
    tclod_selector_destroy(sel[1]);
    tclod_selector_destroy(sel[0]);
    assert_nothing_left(&t);
    tclod_scene_destroy(s);
    table_free(&m);
}

/* ---- the scheduler -------------------------------------------------------------- */

typedef struct draws_copy {
    tclod_draw items[2048];
    size_t n;
    double resolution[256];
} draws_copy;

static void take_draws(const tclod_scheduler *sch, uint32_t smooth, draws_copy *c) {
    const tclod_draw *items = NULL;
    uint32_t i;
    assert_int_equal(tclod_scheduler_draws(sch, &items, &c->n), TCLOD_OK);
    assert_true(c->n <= 2048 && smooth <= 256);
    if (c->n)
        memcpy(c->items, items, c->n * sizeof *items);
    for (i = 0; i < smooth; ++i)
        c->resolution[i] = tclod_scheduler_resolution(sch, i);
}

static void assert_same_draws(const draws_copy *a, const draws_copy *b, uint32_t smooth,
                              const char *what, int update) {
    size_t i;
    if (a->n != b->n)
        fail_msg("%s, update %d: %lu draws, then %lu", what, update, (unsigned long)a->n,
                 (unsigned long)b->n);
    for (i = 0; i < a->n; ++i)
        if (memcmp(&a->items[i], &b->items[i], sizeof a->items[i]) != 0)
            fail_msg("%s, update %d: draw %lu {%u %u %g} became {%u %u %g}", what, update,
                     (unsigned long)i, (unsigned)a->items[i].fine, (unsigned)a->items[i].coarse,
                     (double)a->items[i].weight, (unsigned)b->items[i].fine,
                     (unsigned)b->items[i].coarse, (double)b->items[i].weight);
    for (i = 0; i < smooth; ++i)
        if (memcmp(&a->resolution[i], &b->resolution[i], sizeof(double)) != 0)
            fail_msg("%s, update %d: smooth %lu at %.17g, then %.17g", what, update,
                     (unsigned long)i, a->resolution[i], b->resolution[i]);
}

/* Whether two scheduler stats are the same but for the time they measure. */
static int same_scheduler_stats(const tclod_scheduler_stats *a, const tclod_scheduler_stats *b) {
    return a->draw_cost == b->draw_cost && a->budget == b->budget && a->draws == b->draws &&
           a->morphing == b->morphing && a->selections == b->selections &&
           a->unfinished == b->unfinished && a->emergencies == b->emergencies &&
           a->changes == b->changes && a->morphs == b->morphs && a->pops == b->pops &&
           a->invalid_values == b->invalid_values && a->selection_benefit == b->selection_benefit &&
           a->selection_cost == b->selection_cost;
}

/* The scheduler calls over `solver` under failure, in both modes (below). */
static void scheduler_calls_under_failure(tclod_solver solver) {
    int mode;
    for (mode = TRANSIENT; mode <= PERSISTENT; ++mode) {
        test_alloc t;
        tclod_allocator hooks;
        tclod_scene *s = NULL;
        tclod_scheduler *const sentinel = (tclod_scheduler *)(void *)&t;
        tclod_scheduler *sch = sentinel, *ref = NULL;
        tclod_selector_desc sd;
        tclod_scheduler_desc d;
        table_model m;
        table_rng rng;
        draws_copy *before = (draws_copy *)malloc(sizeof *before);
        draws_copy *after = (draws_copy *)malloc(sizeof *after);
        draws_copy *expect = (draws_copy *)malloc(sizeof *expect);
        tclod_scheduler_stats stats_before, stats_after;
        size_t k;
        int u, allocating = 0;
        assert_non_null(before);
        assert_non_null(after);
        assert_non_null(expect);
        test_alloc_init(&t);
        hooks = test_alloc_hooks(&t);
        table_init(&m);
        assert_int_equal(tclod_scene_create(NULL, &s), TCLOD_OK);
        build_scene(&m, s, 91, 40, 60, 30);
        selector_desc(&sd, solver, &m);
        tclod_scheduler_desc_default(&d);
        d.max_speed = 10.0;
        d.max_turn_rate = 0.5;
        for (k = 1; k <= MAX_ALLOCATIONS_PER_CALL; ++k) {
            tclod_status status;
            sch = sentinel;
            arm(&t, (failure_mode)mode, k);
            status = tclod_scheduler_create(s, &sd, &d, &hooks, &sch);
            if (status == TCLOD_OK)
                break;
            assert_int_equal(status, TCLOD_ERR_NOMEM);
            assert_ptr_equal(sch, sentinel);
            assert_nothing_left(&t);
        }
        assert_true(k > 1 && k <= MAX_ALLOCATIONS_PER_CALL);
        test_alloc_fail_from(&t, 0);
        assert_int_equal(tclod_scheduler_create(s, &sd, &d, NULL, &ref), TCLOD_OK);
        for (u = 0; u < 24; ++u) {
            tclod_view v;
            double now = 0.05 * u, budget = 0.3 * total_cost(&m);
            size_t failures = 0;
            if (u == 12) {
                table_rng_seed(&rng, 92);
                assert_int_equal(table_chains(&m, s, &rng, 300, 4, 40.0f), TCLOD_OK);
                add_smooth_objects(&m, s, &rng, 100, 40.0f);
                budget = 0.3 * total_cost(&m);
            }
            side_view(&v, u % 12);
            take_draws(sch, m.smooth.count, before);
            assert_int_equal(tclod_scheduler_get_stats(sch, &stats_before), TCLOD_OK);
            for (k = 1; k <= MAX_ALLOCATIONS_PER_CALL; ++k) {
                size_t bytes = t.outstanding_bytes, blocks = t.outstanding_blocks;
                tclod_status status;
                arm(&t, (failure_mode)mode, k);
                status = tclod_scheduler_update(sch, now, &v, budget, 0.0);
                if (status == TCLOD_OK)
                    break;
                assert_int_equal(status, TCLOD_ERR_NOMEM);
                if (t.outstanding_bytes != bytes || t.outstanding_blocks != blocks)
                    fail_msg("solver %d, %s, update %d, allocation %lu failing: %lu bytes in %lu "
                             "blocks held, %lu in %lu before",
                             solver, mode_name[mode], u, (unsigned long)k,
                             (unsigned long)t.outstanding_bytes,
                             (unsigned long)t.outstanding_blocks, (unsigned long)bytes,
                             (unsigned long)blocks);
                take_draws(sch, m.smooth.count, after);
                assert_same_draws(before, after, m.smooth.count, mode_name[mode], u);
                assert_int_equal(tclod_scheduler_get_stats(sch, &stats_after), TCLOD_OK);
                assert_true(same_scheduler_stats(&stats_before, &stats_after) &&
                            stats_before.select_seconds == stats_after.select_seconds);
                failures++;
            }
            test_alloc_fail_from(&t, 0);
            assert_true(k <= MAX_ALLOCATIONS_PER_CALL);
            if ((u == 0 || u == 12) != (failures > 0))
                fail_msg("%s, update %d: %lu failures", mode_name[mode], u,
                         (unsigned long)failures);
            allocating += failures > 0;
            assert_int_equal(tclod_scheduler_update(ref, now, &v, budget, 0.0), TCLOD_OK);
            take_draws(sch, m.smooth.count, after);
            take_draws(ref, m.smooth.count, expect);
            assert_same_draws(expect, after, m.smooth.count,
                              "against a scheduler that never failed", u);
            assert_int_equal(tclod_scheduler_get_stats(sch, &stats_after), TCLOD_OK);
            assert_int_equal(tclod_scheduler_get_stats(ref, &stats_before), TCLOD_OK);
            assert_true(same_scheduler_stats(&stats_before, &stats_after));
        }
        assert_int_equal(allocating, 2);
        tclod_scheduler_destroy(ref);
        tclod_scheduler_destroy(sch);
        assert_nothing_left(&t);
        tclod_scene_destroy(s);
        table_free(&m);
        free(expect);
        free(after);
        free(before);
    }
}

static void scheduler_calls_report_nomem_and_change_nothing_for_every_solver(void **state) {
    /* For each solver: tclod_scheduler_create, then 24 updates at 20 Hz over
     * three intervals of tau = 0.5 s, the scene growing before update 12:
     * create and the updates that must allocate (the first, and the one after
     * the growth) are retried with the k-th allocation failing, in both
     * modes. A failure returns TCLOD_ERR_NOMEM, holds no more memory than
     * before the call (the scheduler's buffers and its selector's grow
     * together or not at all) and keeps the draw list and the stats; the
     * other updates succeed with every allocation failing; after every
     * success the draw list and the stats are those of a scheduler that
     * never failed, given the same successful updates; at the end no byte is
     * left. */
    static const tclod_solver solvers[3] = {TCLOD_SOLVER_GREEDY, TCLOD_SOLVER_MIXED,
                                            TCLOD_SOLVER_ROBIN_HOOD};
    int solver;
    (void)state;
    for (solver = 0; solver < 3; ++solver)
        scheduler_calls_under_failure(solvers[solver]);
}

/* ---- calibration ------------------------------------------------------------ */

static void calib_create_reports_nomem_transient_and_persistent(void **state) {
    test_alloc t;
    tclod_allocator hooks;
    tclod_calib_desc d;
    int mode;
    (void)state;
    tclod_calib_desc_default(&d);
    for (mode = TRANSIENT; mode <= PERSISTENT; ++mode) {
        tclod_calib *const sentinel = (tclod_calib *)(void *)&t;
        tclod_calib *c = sentinel;
        double budget = 0.0;
        size_t k;
        test_alloc_init(&t);
        hooks = test_alloc_hooks(&t);
        for (k = 1; k <= MAX_ALLOCATIONS_PER_CALL; ++k) {
            tclod_status status;
            c = sentinel;
            arm(&t, (failure_mode)mode, k);
            status = tclod_calib_create(&d, &hooks, &c);
            if (status == TCLOD_OK)
                break;
            assert_int_equal(status, TCLOD_ERR_NOMEM);
            assert_ptr_equal(c, sentinel);
            assert_nothing_left(&t);
        }
        assert_true(k > 1 && k <= MAX_ALLOCATIONS_PER_CALL);
        /* a calibration that exists reports and budgets without memory: with
         * the defaults (scale 1, no logic, C = 1) the budget of a 20 ms frame
         * is 20 */
        test_alloc_fail_from(&t, 1);
        assert_int_equal(tclod_calib_budget(c, 20.0, &budget), TCLOD_OK);
        assert_true(budget == 20.0);
        assert_int_equal(tclod_calib_report(c, 10.0, 10.0, 0.0), TCLOD_OK);
        test_alloc_fail_from(&t, 0);
        tclod_calib_destroy(c);
        assert_nothing_left(&t);
    }
}

static mode_test scene_create = {scene_create_under_failure};
static mode_test add = {add_under_failure};
static mode_test prepare = {prepare_under_failure};
static mode_test edits = {edits_under_failure};
static mode_test streaming_scene = {streaming_scene_under_failure};

/* A cmocka test named `name` that runs mode_test m in both modes. */
#define MODE_TEST(name, m) \
    { name, in_both_modes, NULL, NULL, m }

int main(void) {
    const struct CMUnitTest tests[] = {
        MODE_TEST("scene_create_reports_nomem_and_holds_nothing", &scene_create),
        MODE_TEST("adding_nodes_and_smooth_objects_under_failure_adds_nothing", &add),
        MODE_TEST("prepare_and_smooth_order_under_failure_change_nothing", &prepare),
        MODE_TEST("boxes_additive_nodes_and_edits_under_failure_change_nothing", &edits),
        MODE_TEST("a_streaming_scene_under_failure_changes_nothing", &streaming_scene),
        cmocka_unit_test(selector_create_reports_nomem_for_every_solver),
        cmocka_unit_test(selects_that_run_out_of_memory_change_nothing_for_every_solver),
        cmocka_unit_test(selects_sharing_the_scene_allocator_leak_nothing_for_every_solver),
        cmocka_unit_test(streaming_selects_that_run_out_of_memory_change_nothing_for_every_solver),
        cmocka_unit_test(select_begin_reports_nomem_and_steps_allocate_nothing_for_every_solver),
        cmocka_unit_test(robin_hood_selects_after_the_first_allocate_nothing),
        cmocka_unit_test(scheduler_calls_report_nomem_and_change_nothing_for_every_solver),
        cmocka_unit_test(calib_create_reports_nomem_transient_and_persistent),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
