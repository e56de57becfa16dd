/*
 * test_guarantees — what every selection keeps (DESIGN.md §5), exercised
 * through the greedy solver, the selector and the allocator hooks
 * (src/selector.c, src/alloc.c): the exact budget guarantee under floating
 * point absorption, bad callback values (sanitised or, in strict mode,
 * reported), bad arguments, determinism, no allocation per frame,
 * TCLOD_ERR_NOMEM without leaks or changes, and refusal of re-entry from
 * callbacks.
 */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include <tclod/tclod.h>

#include "exact.h"
#include "helpers.h"
#include "table_scene.h"
#include "test_alloc.h"

#define FIXTURE_TEST(name) \
    cmocka_unit_test_setup_teardown(name, helper_fixture_setup, helper_fixture_teardown)

/* A copy of a selector's result, to check that a failing call left it alone. */
typedef struct snapshot {
    tclod_id ids[4096];
    size_t n;
} snapshot;

static void take_snapshot(const tclod_selector *sel, snapshot *s) {
    const tclod_id *ids = NULL;
    assert_int_equal(tclod_selector_cut(sel, &ids, &s->n), TCLOD_OK);
    assert_true(s->n <= 4096);
    if (s->n > 0)
        memcpy(s->ids, ids, s->n * sizeof *ids);
}

/* Asserts the current result is the snapshot, same ids in the same order. */
static void assert_snapshot(const tclod_selector *sel, const snapshot *s) {
    const tclod_id *ids = NULL;
    size_t n = 0;
    assert_int_equal(tclod_selector_cut(sel, &ids, &n), TCLOD_OK);
    assert_int_equal(n, s->n);
    if (n > 0)
        assert_memory_equal(ids, s->ids, n * sizeof *ids);
}

/* Stats filled with a byte pattern: a failing call must not write them. */
static void poison_stats(tclod_stats *st) {
    memset(st, 0xa5, sizeof *st);
}

static void assert_stats_untouched(const tclod_stats *st) {
    tclod_stats pattern;
    poison_stats(&pattern);
    assert_memory_equal(st, &pattern, sizeof pattern);
}

static void select_ok(tclod_selector *sel, double budget, tclod_stats *st) {
    tclod_frame f = helper_frame(NULL, budget);
    assert_int_equal(tclod_select(sel, &f, st), TCLOD_OK);
}

/* ---- budget ------------------------------------------------------------ */

static void budget_holds_when_tiny_costs_are_absorbed(void **state) {
    helper_fixture *f = (helper_fixture *)*state;
    /* 100 roots with costs 1e-17 .. 1e-16 (sum 5.5e-15), then X (b 1, c 0.5)
     * with child X1 (b 3, c 1). Taking X1 costs 1 + 5.5e-15 exactly, more
     * than the budget 1, yet a running sum that starts from 0.5 absorbs every
     * tiny cost (each is below half an ulp of 0.5) and reaches exactly 1.
     * Summed in result order the total must not exceed the budget, whatever
     * order the library lists the nodes in; likewise with budget 0.5, which
     * the roots themselves exceed by 5.5e-15. */
    static const double budgets[] = {1.0, 0.5, 0.5 + 1e-16, 1.0 - 1e-16};
    tclod_selector *cold, *warm;
    uint32_t i;
    size_t b;
    for (i = 0; i < 100; ++i)
        helper_add(f, TCLOD_NONE, 1.0, 1e-17 * (double)(1u + i % 10u));
    helper_add(f, TCLOD_NONE, 1.0, 0.5);
    helper_add(f, 100, 3.0, 1.0);
    cold = helper_selector(f->scene, &f->model, 0);
    warm = helper_selector(f->scene, &f->model, 1);
    for (b = 0; b < sizeof budgets / sizeof budgets[0]; ++b) {
        tclod_stats st;
        select_ok(cold, budgets[b], &st);
        helper_check_result(cold, &f->model, &st, budgets[b], 1);
        select_ok(warm, budgets[b], &st);
        helper_check_result(warm, &f->model, &st, budgets[b], 1);
    }
    tclod_selector_destroy(warm);
    tclod_selector_destroy(cold);
}

static void budget_holds_when_tiny_costs_are_absorbed_inside_an_increment(void **state) {
    helper_fixture *f = (helper_fixture *)*state;
    /* Root Y (b 1, c 0.25) with children Y1 (b 2, c 0.75) and 100 children of
     * cost 1e-17 .. 1e-16; root Z (b 1, c 0.25). Y's increment costs
     * 0.75 + 5.5e-15 - 0.25: with budget 1 it fits only if the tiny costs are
     * lost to rounding. */
    tclod_selector *sel;
    tclod_stats st;
    uint32_t i;
    helper_add(f, TCLOD_NONE, 1.0, 0.25);
    for (i = 0; i < 50; ++i)
        helper_add(f, 0, 0.01, 1e-17 * (double)(1u + i % 10u));
    helper_add(f, 0, 2.0, 0.75);
    for (i = 0; i < 50; ++i)
        helper_add(f, 0, 0.01, 1e-17 * (double)(1u + i % 10u));
    helper_add(f, TCLOD_NONE, 1.0, 0.25);
    sel = helper_selector(f->scene, &f->model, 1);
    select_ok(sel, 1.0, &st);
    helper_check_result(sel, &f->model, &st, 1.0, 1);
    select_ok(sel, 1.0, &st);
    helper_check_result(sel, &f->model, &st, 1.0, 1);
    select_ok(sel, 0.5, &st);
    helper_check_result(sel, &f->model, &st, 0.5, 1);
    tclod_selector_destroy(sel);
}

/* Cost of a random cut of m, summed in the order it is built: every node of
 * the growing list is replaced by its children with probability 1/2. Used as
 * a budget, it puts the boundary exactly on a reachable total. */
static double random_cut_cost(const table_model *m, table_rng *rng) {
    tclod_id *list = (tclod_id *)malloc(m->count * sizeof *list);
    size_t n = 0, i;
    double sum = 0.0;
    tclod_id v;
    assert_non_null(list);
    for (v = 0; v < m->count; ++v)
        if (m->parent[v] == TCLOD_NONE)
            list[n++] = v;
    for (i = 0; i < n; ++i) {
        tclod_id c;
        int has_child = 0;
        for (c = list[i] + 1; c < m->count; ++c)
            has_child |= m->parent[c] == list[i];
        if (has_child && table_rng_below(rng, 2) == 0) {
            for (c = list[i] + 1; c < m->count; ++c)
                if (m->parent[c] == list[i])
                    list[n++] = c;
            list[i] = TCLOD_NONE;
        }
    }
    for (i = 0; i < n; ++i)
        if (list[i] != TCLOD_NONE && m->benefit[list[i]] > 0.0)
            sum += m->cost[list[i]];
    free(list);
    return sum;
}

static void budget_holds_on_random_scenes_with_mixed_magnitudes(void **state) {
    /* Costs spread over 17 orders of magnitude, some exactly 0.25, 0.5 or 1,
     * some nodes invisible; budgets from 0 to past the finest cut, half of
     * them exactly the total of a random cut. Cold and warm selectors. */
    uint64_t seed;
    (void)state;
    for (seed = 1; seed <= 150; ++seed) {
        tclod_scene *s = NULL;
        tclod_selector *sel[2];
        table_model m;
        table_rng rng;
        uint32_t i;
        int frame, w;
        table_rng_seed(&rng, seed);
        table_init(&m);
        assert_int_equal(tclod_scene_create(NULL, &s), TCLOD_OK);
        assert_int_equal(table_random_hierarchy(&m, s, &rng, 20 + table_rng_below(&rng, 100),
                                                1 + table_rng_below(&rng, 8), TABLE_ARBITRARY),
                         TCLOD_OK);
        for (i = 0; i < m.count; ++i) {
            uint32_t kind = table_rng_below(&rng, 10);
            if (kind < 3)
                m.cost[i] = ldexp(1.0, -(int)kind); /* 1, 0.5, 0.25 */
            else
                m.cost[i] = pow(10.0, table_rng_uniform(&rng, -17.0, 0.5));
            if (table_rng_below(&rng, 20) == 0)
                m.benefit[i] = 0.0;
        }
        sel[0] = helper_selector(s, &m, 0);
        sel[1] = helper_selector(s, &m, 1);
        for (frame = 0; frame < 8; ++frame) {
            double budget = frame % 2 == 0 ? random_cut_cost(&m, &rng)
                                           : table_rng_uniform(&rng, 0.0, 2.0 * m.count);
            for (w = 0; w < 2; ++w) {
                tclod_stats st;
                select_ok(sel[w], budget, &st);
                helper_check_result(sel[w], &m, &st, budget, 1);
            }
        }
        tclod_selector_destroy(sel[1]);
        tclod_selector_destroy(sel[0]);
        tclod_scene_destroy(s);
        table_free(&m);
    }
}

static void roots_are_dropped_one_at_a_time_when_their_costs_overflow(void **state) {
    helper_fixture *f = (helper_fixture *)*state;
    /* Roots 0 (b 1, c 1e308) and 1 (b 2, c 1e308), budget DBL_MAX = 1.797e308.
     * Together they cost 2e308, which overflows to inf > budget; each alone
     * fits. Values 1e-308 < 2e-308: root 0 is left out, root 1 kept:
     * listed {1}, benefit 2, cost 1e308, one root dropped. */
    static const tclod_id listed[] = {1};
    tclod_selector *sel;
    tclod_stats st;
    int w;
    helper_add(f, TCLOD_NONE, 1.0, 1e308);
    helper_add(f, TCLOD_NONE, 2.0, 1e308);
    for (w = 0; w < 2; ++w) {
        sel = helper_selector(f->scene, &f->model, w);
        select_ok(sel, DBL_MAX, &st);
        helper_check_result(sel, &f->model, &st, DBL_MAX, 1);
        helper_assert_cut(sel, listed, 1);
        assert_int_equal(st.dropped_roots, 1);
        tclod_selector_destroy(sel);
    }
}

/* ---- bad callback values ------------------------------------------------- */

static const double bad_values[] = {NAN, INFINITY, -INFINITY, -1.0};

static void bad_benefit_makes_the_node_invisible_and_is_counted(void **state) {
    helper_fixture *f = (helper_fixture *)*state;
    size_t v;
    /* Roots 0 (1, 1), 1 (bad, 1), 2 (2, 1); 2 has children 3 (bad, 1) and
     * 4 (3, 2). Node 1 is culled; 3 is an invisible child costing 0, so 2's
     * increment gains 0 + 3 - 2 = 1 for 0 + 2 - 1 = 1 and is taken.
     * Listed {0, 4}: benefit 1 + 3 = 4, cost 1 + 2 = 3; two bad values. */
    static const tclod_id listed[] = {0, 4};
    helper_add(f, TCLOD_NONE, 1.0, 1.0);
    helper_add(f, TCLOD_NONE, 0.0, 1.0);
    helper_add(f, TCLOD_NONE, 2.0, 1.0);
    helper_add(f, 2, 0.0, 1.0);
    helper_add(f, 2, 3.0, 2.0);
    for (v = 0; v < sizeof bad_values / sizeof bad_values[0]; ++v) {
        tclod_selector *sel = helper_selector(f->scene, &f->model, 0);
        tclod_stats st;
        f->model.benefit[1] = bad_values[v];
        f->model.benefit[3] = bad_values[v];
        select_ok(sel, INFINITY, &st);
        helper_assert_cut(sel, listed, 2);
        assert_true(st.benefit == 4.0);
        assert_true(st.cost == 3.0);
        assert_int_equal(st.invalid_values, 2);
        assert_int_equal(st.dropped_roots, 0);
        tclod_selector_destroy(sel);
    }
}

/* Checks a frame in which *slot holds `bad`: on a fresh cold selector, and on
 * a warm one whose previous frame saw the good value (so the node was selected
 * or priced before turning bad). Listed ids, totals and the bad-value count
 * must be as given. */
static void assert_sanitised(helper_fixture *f, double *slot, double bad, double budget,
                             const tclod_id *listed, size_t n, double benefit, double cost) {
    const double good = *slot;
    tclod_selector *sel[2];
    tclod_stats st;
    int w;
    sel[0] = helper_selector(f->scene, &f->model, 0);
    sel[1] = helper_selector(f->scene, &f->model, 1);
    select_ok(sel[1], budget, &st);
    *slot = bad;
    for (w = 0; w < 2; ++w) {
        select_ok(sel[w], budget, &st);
        helper_assert_cut(sel[w], listed, n);
        if (st.benefit != benefit || st.cost != cost)
            fail_msg("%s, value %g, budget %g: benefit %g cost %g, expected %g and %g",
                     w ? "warm" : "cold", bad, budget, st.benefit, st.cost, benefit, cost);
        assert_int_equal(st.invalid_values, 1);
    }
    *slot = good;
    tclod_selector_destroy(sel[1]);
    tclod_selector_destroy(sel[0]);
}

static void bad_cost_on_a_root_makes_it_unaffordable_and_is_counted(void **state) {
    helper_fixture *f = (helper_fixture *)*state;
    /* Root 0 (1, bad) can never be selected, whatever the budget, even an
     * unlimited one; root 1 (1, 1) is. Listed {1}: benefit 1, cost 1, one bad
     * value. With its good cost 1, root 0 was selected the frame before. */
    static const tclod_id listed[] = {1};
    static const double budgets[] = {10.0, INFINITY};
    size_t v, b;
    helper_add(f, TCLOD_NONE, 1.0, 1.0);
    helper_add(f, TCLOD_NONE, 1.0, 1.0);
    for (v = 0; v < sizeof bad_values / sizeof bad_values[0]; ++v)
        for (b = 0; b < 2; ++b)
            assert_sanitised(f, &f->model.cost[0], bad_values[v], budgets[b], listed, 1, 1.0, 1.0);
}

static void bad_cost_on_a_child_keeps_its_parent_and_is_counted(void **state) {
    helper_fixture *f = (helper_fixture *)*state;
    /* Root 0 (1, 1) has children 1 (3, bad) and 2 (1, 1): its increment
     * would need 1, so 0 stays. Listed {0}: benefit 1, cost 1, one bad value.
     * With its good cost 0.5 the increment (Δb 3, Δc 0.5) was taken the frame
     * before. */
    static const tclod_id listed[] = {0};
    static const double budgets[] = {10.0, INFINITY};
    size_t v, b;
    helper_add(f, TCLOD_NONE, 1.0, 1.0);
    helper_add(f, 0, 3.0, 0.5);
    helper_add(f, 0, 1.0, 1.0);
    for (v = 0; v < sizeof bad_values / sizeof bad_values[0]; ++v)
        for (b = 0; b < 2; ++b)
            assert_sanitised(f, &f->model.cost[1], bad_values[v], budgets[b], listed, 1, 1.0, 1.0);
}

static void strict_mode_fails_the_call_and_keeps_the_previous_result(void **state) {
    helper_fixture *f = (helper_fixture *)*state;
    /* Roots 0 (1, 1) and 1 (2, 1) -> child 2 (4, 2): unlimited budget gives
     * {0, 2}. Then one value at a time turns bad: the call fails with
     * TCLOD_ERR_CALLBACK and the result stays {0, 2}, stats unwritten.
     * A cold solve must ask every value (both roots, and node 2 to price
     * root 1's increment); a warm one at least those of the cut {0, 2}. */
    static const tclod_id listed[] = {0, 2};
    static const int asked[2][3] = {{1, 1, 1}, {1, 0, 1}};
    int warm;
    helper_add(f, TCLOD_NONE, 1.0, 1.0);
    helper_add(f, TCLOD_NONE, 2.0, 1.0);
    helper_add(f, 1, 4.0, 2.0);
    for (warm = 0; warm < 2; ++warm) {
        tclod_selector_desc d;
        tclod_selector *sel = NULL;
        tclod_stats st;
        snapshot before;
        size_t v;
        int node, which;
        tclod_selector_desc_default(&d);
        table_callbacks(&f->model, &d.callbacks);
        d.strict = 1;
        d.warm_start = warm;
        assert_int_equal(tclod_selector_create(f->scene, &d, NULL, &sel), TCLOD_OK);
        select_ok(sel, INFINITY, &st);
        helper_assert_cut(sel, listed, 2);
        take_snapshot(sel, &before);
        for (v = 0; v < sizeof bad_values / sizeof bad_values[0]; ++v)
            for (node = 0; node < 3; ++node)
                for (which = 0; which < 2; ++which) {
                    double *slot = which ? &f->model.cost[node] : &f->model.benefit[node];
                    double saved = *slot;
                    tclod_frame frame = helper_frame(NULL, INFINITY);
                    if (!asked[warm][node])
                        continue;
                    *slot = bad_values[v];
                    poison_stats(&st);
                    if (tclod_select(sel, &frame, &st) != TCLOD_ERR_CALLBACK)
                        fail_msg("%s: node %d %s = %g accepted in strict mode",
                                 warm ? "warm" : "cold", node, which ? "cost" : "benefit",
                                 bad_values[v]);
                    assert_snapshot(sel, &before);
                    assert_stats_untouched(&st);
                    *slot = saved;
                }
        /* Good values again: the selector carries on. */
        select_ok(sel, INFINITY, &st);
        helper_assert_cut(sel, listed, 2);
        assert_int_equal(st.invalid_values, 0);
        tclod_selector_destroy(sel);
    }
}

/* ---- bad arguments ------------------------------------------------------- */

static void select_rejects_bad_arguments_and_keeps_the_previous_result(void **state) {
    helper_fixture *f = (helper_fixture *)*state;
    tclod_selector *sel;
    tclod_view good_view, bad_fov, nan_eye;
    tclod_stats st;
    snapshot before;
    tclod_frame frames[8];
    size_t i;
    helper_add(f, TCLOD_NONE, 1.0, 1.0);
    helper_add(f, 0, 3.0, 2.0);
    helper_add(f, TCLOD_NONE, 2.0, 1.0);
    sel = helper_selector(f->scene, &f->model, 1);
    helper_view(&good_view);
    bad_fov = good_view;
    bad_fov.fov_y = 0.0f;
    nan_eye = good_view;
    nan_eye.eye[1] = NAN;
    select_ok(sel, 3.0, &st); /* {1, 2}: 2 + 1 = 3 */
    take_snapshot(sel, &before);
    for (i = 0; i < 8; ++i)
        frames[i] = helper_frame(&good_view, 100.0);
    frames[0].budget = NAN;
    frames[1].budget = -1.0;
    frames[2].budget = -INFINITY;
    frames[3].solve_seconds = NAN;
    frames[4].solve_seconds = -1.0;
    frames[5].solve_seconds = -INFINITY;
    frames[6].view = &bad_fov;
    frames[7].view = &nan_eye;
    for (i = 0; i < 8; ++i) {
        poison_stats(&st);
        if (tclod_select(sel, &frames[i], &st) != TCLOD_ERR_ARG)
            fail_msg("bad frame %u accepted", (unsigned)i);
        assert_snapshot(sel, &before);
        assert_stats_untouched(&st);
    }
    poison_stats(&st);
    assert_int_equal(tclod_select(NULL, &frames[0], &st), TCLOD_ERR_ARG);
    assert_int_equal(tclod_select(sel, NULL, &st), TCLOD_ERR_ARG);
    assert_stats_untouched(&st);
    assert_snapshot(sel, &before);
    /* st may be NULL on success. */
    {
        tclod_frame ok = helper_frame(&good_view, 100.0);
        assert_int_equal(tclod_select(sel, &ok, NULL), TCLOD_OK);
    }
    tclod_selector_destroy(sel);
}

static void selector_create_rejects_bad_descriptions(void **state) {
    helper_fixture *f = (helper_fixture *)*state;
    tclod_selector *const sentinel = (tclod_selector *)(void *)f;
    tclod_selector *out = sentinel;
    tclod_selector_desc good, d;
    helper_add(f, TCLOD_NONE, 1.0, 1.0);
    tclod_selector_desc_default(&good);
    table_callbacks(&f->model, &good.callbacks);

    assert_int_equal(tclod_selector_create(NULL, &good, NULL, &out), TCLOD_ERR_ARG);
    assert_int_equal(tclod_selector_create(f->scene, NULL, NULL, &out), TCLOD_ERR_ARG);
    assert_int_equal(tclod_selector_create(f->scene, &good, NULL, NULL), TCLOD_ERR_ARG);
    d = good;
    d.callbacks.benefit = NULL;
    assert_int_equal(tclod_selector_create(f->scene, &d, NULL, &out), TCLOD_ERR_ARG);
    d = good;
    d.callbacks.cost = NULL;
    assert_int_equal(tclod_selector_create(f->scene, &d, NULL, &out), TCLOD_ERR_ARG);
    d = good;
    d.split_threshold = NAN;
    assert_int_equal(tclod_selector_create(f->scene, &d, NULL, &out), TCLOD_ERR_ARG);
    d = good;
    d.split_threshold = -0.5;
    assert_int_equal(tclod_selector_create(f->scene, &d, NULL, &out), TCLOD_ERR_ARG);
    assert_ptr_equal(out, sentinel);
}

/* Smooth callbacks for selectors that need them but solve no smooth object. */
static double linear_smooth(void *user, const tclod_query *q, double r, double *d_dr) {
    (void)user;
    (void)q;
    *d_dr = 1.0;
    return r;
}

static void only_available_solvers_can_be_created(void **state) {
    helper_fixture *f = (helper_fixture *)*state;
    const tclod_solver solvers[] = {TCLOD_SOLVER_GREEDY, TCLOD_SOLVER_MIXED,
                                    TCLOD_SOLVER_ROBIN_HOOD, (tclod_solver)3, (tclod_solver)42};
    tclod_selector_desc d;
    size_t i;
    helper_add(f, TCLOD_NONE, 1.0, 1.0);
    assert_int_equal(tclod_solver_available(TCLOD_SOLVER_GREEDY), 1);
    assert_int_equal(tclod_solver_available(TCLOD_SOLVER_MIXED), 1);
    assert_int_equal(tclod_solver_available((tclod_solver)3), 0);
    assert_int_equal(tclod_solver_available((tclod_solver)42), 0);
    for (i = 0; i < sizeof solvers / sizeof solvers[0]; ++i) {
        tclod_selector *const sentinel = (tclod_selector *)(void *)f;
        tclod_selector *out = sentinel;
        tclod_status st;
        tclod_selector_desc_default(&d);
        table_callbacks(&f->model, &d.callbacks);
        d.callbacks.smooth_benefit = d.callbacks.smooth_cost = linear_smooth;
        d.solver = solvers[i];
        st = tclod_selector_create(f->scene, &d, NULL, &out);
        if (tclod_solver_available(solvers[i])) {
            assert_int_equal(st, TCLOD_OK);
            tclod_selector_destroy(out);
        } else {
            assert_int_equal(st, TCLOD_ERR_ARG);
            assert_ptr_equal(out, sentinel);
        }
    }
}

static void *only_alloc(size_t size, void *ctx) {
    (void)ctx;
    return malloc(size);
}

static void only_free(void *ptr, size_t size, void *ctx) {
    (void)size;
    (void)ctx;
    free(ptr);
}

static void allocators_need_both_hooks_or_none(void **state) {
    helper_fixture *f = (helper_fixture *)*state;
    tclod_allocator half_alloc = {only_alloc, NULL, NULL};
    tclod_allocator half_free = {NULL, only_free, NULL};
    tclod_allocator none = {NULL, NULL, NULL};
    tclod_scene *const scene_sentinel = (tclod_scene *)(void *)f;
    tclod_selector *const selector_sentinel = (tclod_selector *)(void *)f;
    tclod_scene *s = scene_sentinel;
    tclod_selector *sel = selector_sentinel;
    tclod_selector_desc d;
    helper_add(f, TCLOD_NONE, 1.0, 1.0);
    tclod_selector_desc_default(&d);
    table_callbacks(&f->model, &d.callbacks);
    assert_int_equal(tclod_scene_create(&half_alloc, &s), TCLOD_ERR_ARG);
    assert_int_equal(tclod_scene_create(&half_free, &s), TCLOD_ERR_ARG);
    assert_ptr_equal(s, scene_sentinel);
    assert_int_equal(tclod_selector_create(f->scene, &d, &half_alloc, &sel), TCLOD_ERR_ARG);
    assert_int_equal(tclod_selector_create(f->scene, &d, &half_free, &sel), TCLOD_ERR_ARG);
    assert_ptr_equal(sel, selector_sentinel);
    /* Both NULL means malloc/free. */
    assert_int_equal(tclod_scene_create(&none, &s), TCLOD_OK);
    tclod_scene_destroy(s);
    assert_int_equal(tclod_selector_create(f->scene, &d, &none, &sel), TCLOD_OK);
    tclod_selector_destroy(sel);
}

static void cut_rejects_null_arguments_and_is_empty_before_the_first_select(void **state) {
    helper_fixture *f = (helper_fixture *)*state;
    tclod_selector *sel;
    const tclod_id *ids = NULL;
    size_t n = 99;
    helper_add(f, TCLOD_NONE, 1.0, 1.0);
    sel = helper_selector(f->scene, &f->model, 1);
    assert_int_equal(tclod_selector_cut(sel, &ids, &n), TCLOD_OK);
    assert_int_equal(n, 0);
    assert_int_equal(tclod_selector_cut(NULL, &ids, &n), TCLOD_ERR_ARG);
    assert_int_equal(tclod_selector_cut(sel, NULL, &n), TCLOD_ERR_ARG);
    assert_int_equal(tclod_selector_cut(sel, &ids, NULL), TCLOD_ERR_ARG);
    assert_true(tclod_selector_resolution(NULL, 0) == 0.0);
    assert_true(tclod_selector_resolution(sel, 12345) == 0.0);
    tclod_selector_destroy(sel);
    tclod_selector_destroy(NULL);
}

static void desc_default_fills_the_documented_values(void **state) {
    tclod_selector_desc d;
    (void)state;
    memset(&d, 0x5a, sizeof d);
    tclod_selector_desc_default(&d);
    assert_int_equal(d.solver, TCLOD_SOLVER_GREEDY);
    assert_null(d.callbacks.benefit);
    assert_null(d.callbacks.cost);
    assert_null(d.callbacks.smooth_benefit);
    assert_null(d.callbacks.smooth_cost);
    assert_null(d.callbacks.user);
    assert_int_equal(d.warm_start, 1);
    assert_int_equal(d.split_smooth, 0);
    assert_true(d.split_threshold == 0.01);
    assert_int_equal(d.strict, 0);
}

/* ---- determinism --------------------------------------------------------- */

/* A view-dependent benefit: culled outside the frustum, larger on screen. */
static double view_benefit(void *user, const tclod_query *q) {
    double b = table_benefit(user, q);
    if (q->screen_area == 0.0f)
        return 0.0;
    if (q->screen_area > 0.0f)
        b *= 1.0 + sqrt((double)q->screen_area) / 1000.0;
    return b;
}

/* Camera of frame i: at (0, 5, 0), turning 0.3 rad per frame, looking
 * slightly down over chains spread on [-50, 50]². */
static void frame_view(tclod_view *v, int i) {
    helper_view(v);
    v->eye[1] = 5.0f;
    v->forward[0] = (float)cos(0.3 * i);
    v->forward[1] = -0.1f;
    v->forward[2] = (float)sin(0.3 * i);
    v->far_z = 60.0f + (float)(i % 4) * 10.0f;
}

/* Frame i of the sequences below: varied budget, view, limits. */
static tclod_frame sequence_frame(int i, const tclod_view *view, double roots_cost) {
    tclod_frame f = helper_frame(i % 7 == 6 ? NULL : view, roots_cost * (0.4 + 0.3 * (i % 9)));
    if (i % 5 == 4)
        f.max_iterations = 20;
    if (i % 11 == 10)
        f.budget = INFINITY;
    return f;
}

static tclod_selector *view_selector(const tclod_scene *s, table_model *m, int warm,
                                     const tclod_allocator *a) {
    tclod_selector_desc d;
    tclod_selector *sel = NULL;
    tclod_selector_desc_default(&d);
    table_callbacks(m, &d.callbacks);
    d.callbacks.benefit = view_benefit;
    d.warm_start = warm;
    assert_int_equal(tclod_selector_create(s, &d, a, &sel), TCLOD_OK);
    return sel;
}

static void two_selectors_give_bit_identical_results(void **state) {
    helper_fixture *f = (helper_fixture *)*state;
    tclod_selector *sel[4];
    table_rng rng;
    double roots_cost;
    int i, pair;
    table_rng_seed(&rng, 31);
    assert_int_equal(table_chains(&f->model, f->scene, &rng, 300, 5, 50.0f), TCLOD_OK);
    roots_cost = table_roots_cost(&f->model);
    sel[0] = view_selector(f->scene, &f->model, 1, NULL);
    sel[1] = view_selector(f->scene, &f->model, 1, NULL);
    sel[2] = view_selector(f->scene, &f->model, 0, NULL);
    sel[3] = view_selector(f->scene, &f->model, 0, NULL);
    for (i = 0; i < 40; ++i) {
        tclod_view v;
        tclod_frame frame;
        frame_view(&v, i);
        frame = sequence_frame(i, &v, roots_cost);
        for (pair = 0; pair < 4; pair += 2) {
            tclod_stats a, b;
            const tclod_id *ids_a, *ids_b;
            size_t n_a, n_b;
            assert_int_equal(tclod_select(sel[pair], &frame, &a), TCLOD_OK);
            assert_int_equal(tclod_select(sel[pair + 1], &frame, &b), TCLOD_OK);
            assert_int_equal(tclod_selector_cut(sel[pair], &ids_a, &n_a), TCLOD_OK);
            assert_int_equal(tclod_selector_cut(sel[pair + 1], &ids_b, &n_b), TCLOD_OK);
            assert_int_equal(n_a, n_b);
            if (n_a > 0)
                assert_memory_equal(ids_a, ids_b, n_a * sizeof *ids_a);
            assert_memory_equal(&a.benefit, &b.benefit, sizeof a.benefit);
            assert_memory_equal(&a.cost, &b.cost, sizeof a.cost);
            assert_int_equal(a.iterations, b.iterations);
            assert_int_equal(a.increments, b.increments);
            assert_int_equal(a.decrements, b.decrements);
            assert_int_equal(a.dropped_roots, b.dropped_roots);
            assert_int_equal(a.evaluations, b.evaluations);
            assert_int_equal(a.stop_reason, b.stop_reason);
            assert_true(a.cost <= frame.budget);
        }
    }
    for (i = 0; i < 4; ++i)
        tclod_selector_destroy(sel[i]);
}

static void equal_increments_are_taken_in_id_order(void **state) {
    helper_fixture *f = (helper_fixture *)*state;
    /* Ten identical chains: roots 0..9 (b 1, c 1) created first, then their
     * children in reverse, so root r's child is 19 - r (b 2, c 2). Every
     * increment gains 1 for 1. Budget 13 = roots 10 + 3 increments: roots
     * 0, 1, 2 (lowest ids) are refined, to 19, 18, 17. */
    static const tclod_id listed[] = {3, 4, 5, 6, 7, 8, 9, 17, 18, 19};
    tclod_selector *sel[2];
    tclod_stats st;
    int r, w;
    for (r = 0; r < 10; ++r)
        helper_add(f, TCLOD_NONE, 1.0, 1.0);
    for (r = 9; r >= 0; --r)
        helper_add(f, (tclod_id)r, 2.0, 2.0);
    sel[0] = helper_selector(f->scene, &f->model, 0);
    sel[1] = helper_selector(f->scene, &f->model, 1);
    for (w = 0; w < 2; ++w) {
        select_ok(sel[w], 13.0, &st);
        helper_assert_cut(sel[w], listed, 10);
        assert_true(st.benefit == 13.0);
        assert_true(st.cost == 13.0);
    }
    /* Warm, same frame again: nothing to gain, the same cut. */
    select_ok(sel[1], 13.0, &st);
    helper_assert_cut(sel[1], listed, 10);
    tclod_selector_destroy(sel[1]);
    tclod_selector_destroy(sel[0]);
}

/* ---- memory ------------------------------------------------------------- */

static void selects_after_the_first_allocate_nothing(void **state) {
    test_alloc counter;
    tclod_allocator hooks;
    tclod_scene *s = NULL;
    tclod_selector *warm, *cold;
    table_model m;
    table_rng rng;
    double roots_cost;
    size_t after_first;
    int i;
    (void)state;
    test_alloc_init(&counter);
    hooks = test_alloc_hooks(&counter);
    table_init(&m);
    table_rng_seed(&rng, 17);
    assert_int_equal(tclod_scene_create(&hooks, &s), TCLOD_OK);
    assert_int_equal(table_chains(&m, s, &rng, 200, 5, 50.0f), TCLOD_OK);
    roots_cost = table_roots_cost(&m);
    warm = view_selector(s, &m, 1, &hooks);
    cold = view_selector(s, &m, 0, &hooks);
    {
        tclod_view v;
        tclod_frame frame;
        frame_view(&v, 0);
        frame = helper_frame(&v, roots_cost);
        assert_int_equal(tclod_select(warm, &frame, NULL), TCLOD_OK);
        assert_int_equal(tclod_select(cold, &frame, NULL), TCLOD_OK);
    }
    after_first = counter.allocations;
    for (i = 1; i <= 50; ++i) {
        tclod_view v;
        tclod_frame frame;
        tclod_stats st;
        frame_view(&v, i);
        frame = sequence_frame(i, &v, roots_cost);
        if (i % 6 == 3)
            frame.solve_seconds = 1e-6;
        assert_int_equal(tclod_select(i % 2 ? warm : cold, &frame, &st), TCLOD_OK);
        if (counter.allocations != after_first)
            fail_msg("select %d allocated %u times", i,
                     (unsigned)(counter.allocations - after_first));
    }
    tclod_selector_destroy(cold);
    tclod_selector_destroy(warm);
    tclod_scene_destroy(s);
    assert_int_equal(counter.outstanding_bytes, 0);
    assert_int_equal(counter.outstanding_blocks, 0);
    assert_int_equal(counter.bad_frees, 0);
    table_free(&m);
}

/* Upper bound on the allocations one call may make before it succeeds. */
#define MAX_ALLOCATIONS_PER_CALL 200u

static void scene_create_reports_nomem_without_leaks(void **state) {
    test_alloc t;
    tclod_allocator hooks;
    tclod_scene *const sentinel = (tclod_scene *)(void *)&t;
    size_t k;
    (void)state;
    test_alloc_init(&t);
    hooks = test_alloc_hooks(&t);
    for (k = 1; k <= MAX_ALLOCATIONS_PER_CALL; ++k) {
        tclod_scene *s = sentinel;
        tclod_status st;
        test_alloc_fail_at(&t, k);
        st = tclod_scene_create(&hooks, &s);
        if (st == TCLOD_OK) {
            tclod_scene_destroy(s);
            break;
        }
        assert_int_equal(st, TCLOD_ERR_NOMEM);
        assert_ptr_equal(s, sentinel);
        assert_int_equal(t.outstanding_bytes, 0);
    }
    assert_true(k > 1); /* the scene itself comes from the hooks */
    assert_true(k <= MAX_ALLOCATIONS_PER_CALL);
    assert_int_equal(t.outstanding_bytes, 0);
    assert_int_equal(t.bad_frees, 0);
}

static void adding_nodes_reports_nomem_and_adds_nothing(void **state) {
    /* 5000 nodes and 1000 smooth objects through a failing allocator: every
     * add is retried with the k-th allocation failing, k = 1, 2, ... until it
     * succeeds; every failure must leave count, memory and out id as they
     * were. The arrays must have grown at least once. */
    test_alloc t;
    tclod_allocator hooks;
    tclod_scene *s = NULL;
    table_model m;
    table_rng rng;
    size_t growth_failures = 0;
    uint32_t i;
    (void)state;
    test_alloc_init(&t);
    hooks = test_alloc_hooks(&t);
    table_init(&m);
    table_rng_seed(&rng, 4);
    assert_int_equal(tclod_scene_create(&hooks, &s), TCLOD_OK);
    for (i = 0; i < 5000; ++i) {
        const float bounds[4] = {(float)i, 0.0f, 1.0f, 2.0f};
        tclod_id parent = i < 5 ? TCLOD_NONE : table_rng_below(&rng, i);
        size_t k;
        for (k = 1; k <= MAX_ALLOCATIONS_PER_CALL; ++k) {
            size_t bytes = t.outstanding_bytes;
            tclod_id id = 777777;
            tclod_status st;
            test_alloc_fail_at(&t, k);
            st = tclod_scene_add_node(s, parent, (i & 1) ? bounds : NULL, &id);
            if (st == TCLOD_OK) {
                assert_int_equal(id, i);
                break;
            }
            assert_int_equal(st, TCLOD_ERR_NOMEM);
            assert_int_equal(id, 777777);
            assert_int_equal(tclod_scene_node_count(s), i);
            assert_int_equal(t.outstanding_bytes, bytes);
            growth_failures++;
        }
        assert_true(k <= MAX_ALLOCATIONS_PER_CALL);
    }
    assert_true(growth_failures > 0);
    growth_failures = 0;
    for (i = 0; i < 1000; ++i) {
        const float bounds[4] = {(float)i, 0.0f, -(float)i, 1.0f};
        size_t k;
        for (k = 1; k <= MAX_ALLOCATIONS_PER_CALL; ++k) {
            size_t bytes = t.outstanding_bytes;
            tclod_id id = 777777;
            tclod_status st;
            test_alloc_fail_at(&t, k);
            st = tclod_scene_add_smooth(s, bounds, &id);
            if (st == TCLOD_OK) {
                assert_int_equal(id, i);
                break;
            }
            assert_int_equal(st, TCLOD_ERR_NOMEM);
            assert_int_equal(id, 777777);
            assert_int_equal(tclod_scene_smooth_count(s), i);
            assert_int_equal(t.outstanding_bytes, bytes);
            growth_failures++;
        }
        assert_true(k <= MAX_ALLOCATIONS_PER_CALL);
    }
    assert_true(growth_failures > 0);
    test_alloc_fail_at(&t, 0);
    assert_int_equal(tclod_scene_node_count(s), 5000);
    assert_int_equal(tclod_scene_smooth_count(s), 1000);
    /* The parents survived every failed growth. */
    table_rng_seed(&rng, 4);
    for (i = 5; i < 5000; ++i)
        assert_int_equal(tclod_scene_parent(s, i), table_rng_below(&rng, i));
    tclod_scene_destroy(s);
    assert_int_equal(t.outstanding_bytes, 0);
    assert_int_equal(t.bad_frees, 0);
    table_free(&m);
}

static void prepare_reports_nomem_without_leaks(void **state) {
    test_alloc t;
    tclod_allocator hooks;
    tclod_scene *s = NULL;
    tclod_selector *sel;
    table_model m;
    table_rng rng;
    tclod_stats st;
    size_t k;
    (void)state;
    test_alloc_init(&t);
    hooks = test_alloc_hooks(&t);
    table_init(&m);
    table_rng_seed(&rng, 6);
    assert_int_equal(tclod_scene_create(&hooks, &s), TCLOD_OK);
    assert_int_equal(table_random_hierarchy(&m, s, &rng, 2000, 10, TABLE_DIMINISHING), TCLOD_OK);
    for (k = 1; k <= MAX_ALLOCATIONS_PER_CALL; ++k) {
        size_t bytes = t.outstanding_bytes;
        tclod_status status;
        test_alloc_fail_at(&t, k);
        status = tclod_scene_prepare(s);
        if (status == TCLOD_OK)
            break;
        assert_int_equal(status, TCLOD_ERR_NOMEM);
        assert_int_equal(t.outstanding_bytes, bytes);
        assert_int_equal(tclod_scene_node_count(s), 2000);
    }
    assert_true(k <= MAX_ALLOCATIONS_PER_CALL);
    test_alloc_fail_at(&t, 0);
    /* The prepared scene selects correctly. */
    sel = helper_selector(s, &m, 0);
    select_ok(sel, table_leaves_cost(&m) * 0.5, &st);
    helper_check_result(sel, &m, &st, table_leaves_cost(&m) * 0.5, 0);
    tclod_selector_destroy(sel);
    tclod_scene_destroy(s);
    assert_int_equal(t.outstanding_bytes, 0);
    assert_int_equal(t.bad_frees, 0);
    table_free(&m);
}

static void selector_create_reports_nomem_without_leaks(void **state) {
    helper_fixture *f = (helper_fixture *)*state;
    test_alloc t;
    tclod_allocator hooks;
    tclod_selector *const sentinel = (tclod_selector *)(void *)&t;
    tclod_selector_desc d;
    size_t k;
    test_alloc_init(&t);
    hooks = test_alloc_hooks(&t);
    helper_add(f, TCLOD_NONE, 1.0, 1.0);
    tclod_selector_desc_default(&d);
    table_callbacks(&f->model, &d.callbacks);
    for (k = 1; k <= MAX_ALLOCATIONS_PER_CALL; ++k) {
        tclod_selector *sel = sentinel;
        tclod_status st;
        test_alloc_fail_at(&t, k);
        st = tclod_selector_create(f->scene, &d, &hooks, &sel);
        if (st == TCLOD_OK) {
            tclod_selector_destroy(sel);
            break;
        }
        assert_int_equal(st, TCLOD_ERR_NOMEM);
        assert_ptr_equal(sel, sentinel);
        assert_int_equal(t.outstanding_bytes, 0);
    }
    assert_true(k > 1); /* the selector itself comes from the hooks */
    assert_true(k <= MAX_ALLOCATIONS_PER_CALL);
    assert_int_equal(t.outstanding_bytes, 0);
    assert_int_equal(t.bad_frees, 0);
}

/* Retries tclod_select with the k-th allocation of t failing, k = 1, 2, ...;
 * each failure must return TCLOD_ERR_NOMEM, leave the result as `before`,
 * the stats unwritten and t's outstanding bytes as they were. Returns the
 * number of failures before success. */
static size_t select_through_failures(tclod_selector *sel, test_alloc *t, double budget,
                                      const snapshot *before) {
    tclod_frame frame = helper_frame(NULL, budget);
    size_t k;
    for (k = 1; k <= MAX_ALLOCATIONS_PER_CALL; ++k) {
        size_t bytes = t->outstanding_bytes;
        tclod_stats st;
        tclod_status status;
        poison_stats(&st);
        test_alloc_fail_at(t, k);
        status = tclod_select(sel, &frame, &st);
        if (status == TCLOD_OK)
            break;
        assert_int_equal(status, TCLOD_ERR_NOMEM);
        assert_stats_untouched(&st);
        assert_snapshot(sel, before);
        assert_int_equal(t->outstanding_bytes, bytes);
    }
    assert_true(k <= MAX_ALLOCATIONS_PER_CALL);
    test_alloc_fail_at(t, 0);
    return k - 1;
}

static void select_reports_nomem_and_keeps_the_previous_result(void **state) {
    /* The scene uses malloc and is prepared; only the selector's buffers come
     * from the failing allocator. First select: the previous result is the
     * empty one. Then the scene grows from 50 to 3050 nodes, so the buffers
     * must grow again, and a failing select must keep the 50-node result. */
    helper_fixture *f = (helper_fixture *)*state;
    test_alloc t;
    tclod_allocator hooks;
    tclod_selector_desc d;
    tclod_selector *sel = NULL;
    table_rng rng;
    snapshot before;
    tclod_stats st;
    double budget;
    test_alloc_init(&t);
    hooks = test_alloc_hooks(&t);
    table_rng_seed(&rng, 12);
    assert_int_equal(table_random_hierarchy(&f->model, f->scene, &rng, 50, 5, TABLE_DIMINISHING),
                     TCLOD_OK);
    assert_int_equal(tclod_scene_prepare(f->scene), TCLOD_OK);
    tclod_selector_desc_default(&d);
    table_callbacks(&f->model, &d.callbacks);
    assert_int_equal(tclod_selector_create(f->scene, &d, &hooks, &sel), TCLOD_OK);
    budget = table_leaves_cost(&f->model) * 0.6;
    take_snapshot(sel, &before);
    assert_int_equal(before.n, 0);
    assert_true(select_through_failures(sel, &t, budget, &before) > 0);
    select_ok(sel, budget, &st);
    helper_check_result(sel, &f->model, &st, budget, 0);
    take_snapshot(sel, &before);

    assert_int_equal(table_random_hierarchy(&f->model, f->scene, &rng, 3000, 20, TABLE_DIMINISHING),
                     TCLOD_OK);
    assert_int_equal(tclod_scene_prepare(f->scene), TCLOD_OK);
    budget = table_leaves_cost(&f->model) * 0.6;
    assert_true(select_through_failures(sel, &t, budget, &before) > 0);
    select_ok(sel, budget, &st);
    helper_check_result(sel, &f->model, &st, budget, 0);
    tclod_selector_destroy(sel);
    assert_int_equal(t.outstanding_bytes, 0);
    assert_int_equal(t.bad_frees, 0);
}

static void failed_selects_leak_nothing_with_a_shared_allocator(void **state) {
    /* Scene and selector share one failing allocator and the scene is not
     * prepared, so the first select also builds the child index. Every
     * failure returns TCLOD_ERR_NOMEM with an empty result; once everything
     * is destroyed no byte is left. */
    test_alloc t;
    tclod_allocator hooks;
    tclod_scene *s = NULL;
    tclod_selector *sel = NULL;
    tclod_selector_desc d;
    table_model m;
    table_rng rng;
    tclod_frame frame;
    size_t k;
    (void)state;
    test_alloc_init(&t);
    hooks = test_alloc_hooks(&t);
    table_init(&m);
    table_rng_seed(&rng, 13);
    assert_int_equal(tclod_scene_create(&hooks, &s), TCLOD_OK);
    assert_int_equal(table_random_hierarchy(&m, s, &rng, 400, 4, TABLE_DIMINISHING), TCLOD_OK);
    tclod_selector_desc_default(&d);
    table_callbacks(&m, &d.callbacks);
    assert_int_equal(tclod_selector_create(s, &d, &hooks, &sel), TCLOD_OK);
    frame = helper_frame(NULL, table_leaves_cost(&m) * 0.5);
    for (k = 1; k <= MAX_ALLOCATIONS_PER_CALL; ++k) {
        const tclod_id *ids;
        size_t n = 99;
        tclod_status status;
        test_alloc_fail_at(&t, k);
        status = tclod_select(sel, &frame, NULL);
        if (status == TCLOD_OK)
            break;
        assert_int_equal(status, TCLOD_ERR_NOMEM);
        assert_int_equal(tclod_selector_cut(sel, &ids, &n), TCLOD_OK);
        assert_int_equal(n, 0);
    }
    assert_true(k > 1);
    assert_true(k <= MAX_ALLOCATIONS_PER_CALL);
    test_alloc_fail_at(&t, 0);
    tclod_selector_destroy(sel);
    tclod_scene_destroy(s);
    assert_int_equal(t.outstanding_bytes, 0);
    assert_int_equal(t.bad_frees, 0);
    table_free(&m);
}

/* ---- re-entry ------------------------------------------------------------ */

typedef struct reentry {
    table_model *model;
    tclod_selector *sel;
    const tclod_frame *frame;
    int calls;
    tclod_status select_status;
    tclod_status cut_status;
} reentry;

/* On its first call, tries to use the selector that is solving. */
static double reentrant_benefit(void *user, const tclod_query *q) {
    reentry *r = (reentry *)user;
    if (r->calls++ == 0) {
        const tclod_id *ids = NULL;
        size_t n = 0;
        tclod_stats st;
        r->select_status = tclod_select(r->sel, r->frame, &st);
        r->cut_status = tclod_selector_cut(r->sel, &ids, &n);
        tclod_selector_destroy(r->sel); /* ignored while solving */
    }
    return table_benefit(r->model, q);
}

static double reentrant_cost(void *user, const tclod_query *q) {
    return table_cost(((reentry *)user)->model, q);
}

static void callbacks_cannot_reenter_their_selector(void **state) {
    helper_fixture *f = (helper_fixture *)*state;
    static const tclod_id listed[] = {1, 2};
    tclod_selector_desc d;
    tclod_frame frame = helper_frame(NULL, INFINITY);
    tclod_stats st;
    reentry r;
    /* Root 0 (1, 1) -> 1 (2, 1.5); root 2 (1, 1): unlimited budget gives
     * {1, 2}. */
    helper_add(f, TCLOD_NONE, 1.0, 1.0);
    helper_add(f, 0, 2.0, 1.5);
    helper_add(f, TCLOD_NONE, 1.0, 1.0);
    memset(&r, 0, sizeof r);
    r.model = &f->model;
    r.frame = &frame;
    r.select_status = TCLOD_OK;
    r.cut_status = TCLOD_OK;
    tclod_selector_desc_default(&d);
    d.callbacks.benefit = reentrant_benefit;
    d.callbacks.cost = reentrant_cost;
    d.callbacks.user = &r;
    assert_int_equal(tclod_selector_create(f->scene, &d, NULL, &r.sel), TCLOD_OK);
    assert_int_equal(tclod_select(r.sel, &frame, &st), TCLOD_OK);
    assert_true(r.calls > 0);
    assert_int_equal(r.select_status, TCLOD_ERR_STATE);
    assert_int_equal(r.cut_status, TCLOD_ERR_STATE);
    helper_assert_cut(r.sel, listed, 2);
    helper_check_result(r.sel, &f->model, &st, INFINITY, 0);
    /* The selector survived its callback's destroy and keeps working. */
    r.calls = 0;
    r.select_status = TCLOD_OK;
    assert_int_equal(tclod_select(r.sel, &frame, &st), TCLOD_OK);
    assert_int_equal(r.select_status, TCLOD_ERR_STATE);
    helper_assert_cut(r.sel, listed, 2);
    tclod_selector_destroy(r.sel);
}

int main(void) {
    const struct CMUnitTest tests[] = {
        FIXTURE_TEST(budget_holds_when_tiny_costs_are_absorbed),
        FIXTURE_TEST(budget_holds_when_tiny_costs_are_absorbed_inside_an_increment),
        cmocka_unit_test(budget_holds_on_random_scenes_with_mixed_magnitudes),
        FIXTURE_TEST(roots_are_dropped_one_at_a_time_when_their_costs_overflow),
        FIXTURE_TEST(bad_benefit_makes_the_node_invisible_and_is_counted),
        FIXTURE_TEST(bad_cost_on_a_root_makes_it_unaffordable_and_is_counted),
        FIXTURE_TEST(bad_cost_on_a_child_keeps_its_parent_and_is_counted),
        FIXTURE_TEST(strict_mode_fails_the_call_and_keeps_the_previous_result),
        FIXTURE_TEST(select_rejects_bad_arguments_and_keeps_the_previous_result),
        FIXTURE_TEST(selector_create_rejects_bad_descriptions),
        FIXTURE_TEST(only_available_solvers_can_be_created),
        FIXTURE_TEST(allocators_need_both_hooks_or_none),
        FIXTURE_TEST(cut_rejects_null_arguments_and_is_empty_before_the_first_select),
        cmocka_unit_test(desc_default_fills_the_documented_values),
        FIXTURE_TEST(two_selectors_give_bit_identical_results),
        FIXTURE_TEST(equal_increments_are_taken_in_id_order),
        cmocka_unit_test(selects_after_the_first_allocate_nothing),
        cmocka_unit_test(scene_create_reports_nomem_without_leaks),
        cmocka_unit_test(adding_nodes_reports_nomem_and_adds_nothing),
        cmocka_unit_test(prepare_reports_nomem_without_leaks),
        FIXTURE_TEST(selector_create_reports_nomem_without_leaks),
        FIXTURE_TEST(select_reports_nomem_and_keeps_the_previous_result),
        cmocka_unit_test(failed_selects_leak_nothing_with_a_shared_allocator),
        FIXTURE_TEST(callbacks_cannot_reenter_their_selector),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
