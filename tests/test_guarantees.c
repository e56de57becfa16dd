/*
 * test_guarantees — what every selection keeps (docs/api.md), exercised
 * through the greedy solver, the selector and the allocator hooks
 * (src/select/selector.c, src/core/alloc.c): the exact budget guarantee under floating
 * point absorption, bad callback values (sanitised or, in strict mode,
 * reported), bad arguments, determinism, no allocation per frame, and
 * refusal of re-entry from callbacks (allocation failure: test_allocation.c). The same guarantees
 * for the mixed solver (src/solve/mixed.c, src/solve/split.c) over 10,000 random instances of discrete
 * hierarchies and smooth objects, with every group's cost recomputed member by member from the
 * table, and the smooth order that groups and queries refer to.
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
    /* Root Y = 0 (b 1, c 0.5) with children Y1 = 1 (b 2, c 0.25) and Y2 = 2
     * (b 2, c 0.75), then 100 roots 3 .. 102 with costs 3e-17, 4e-17, 5e-17,
     * 3e-17, ... (sum 3.99e-15). A running sum that starts from Y's 0.5
     * absorbs every tiny cost (each is below half an ulp of 0.5, 5.55e-17):
     * the roots seem to cost 0.5 and Y's increment (Δc 0.5) seems to reach
     * exactly 1. But it costs 1 + 3.99e-15 with the roots, more than the
     * budget 1, and a cut that lists the tiny roots after a node of 0.25 (each
     * then rounds up to a whole ulp of 0.25) and before Y2 sums to 1 + 4e-15:
     * only summing again in result order catches it. The total in result
     * order must not exceed the budget, whatever order the library lists the
     * nodes in; likewise with budgets just around 1 and with 0.5, which the
     * roots themselves exceed by 3.99e-15. */
    static const double budgets[] = {1.0, 0.5, 0.5 + 1e-16, 1.0 - 1e-16, 1.0 + 1e-16};
    tclod_selector *cold, *warm;
    uint32_t i;
    size_t b;
    helper_add(f, TCLOD_NONE, 1.0, 0.5);
    helper_add(f, 0, 2.0, 0.25);
    helper_add(f, 0, 2.0, 0.75);
    for (i = 0; i < 100; ++i)
        helper_add(f, TCLOD_NONE, 1.0, 1e-17 * (double)(3u + i % 3u));
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

/* The small roots of absorbing_scene: enough that a solve that takes their
 * increments and gives them back one sum at a time (O(n^2)) takes seconds. */
#define ABSORB_ROOTS 20000u

/* Root 0 (b 1, c 2^53), then ABSORB_ROOTS roots 2i + 1 (b 1, c 1), each with a
 * child 2i + 2 (b 2, c 2): replacing a root by its child gains 1 for 1. */
static void absorbing_scene(helper_fixture *f) {
    uint32_t i;
    helper_add(f, TCLOD_NONE, 1.0, ldexp(1.0, 53));
    for (i = 0; i < ABSORB_ROOTS; ++i)
        helper_add(f, helper_add(f, TCLOD_NONE, 1.0, 1.0), 2.0, 2.0);
}

/* A selector over the fixture: greedy, or mixed (table callbacks with the
 * smooth ones). */
static tclod_selector *absorbing_selector(helper_fixture *f, tclod_solver solver, int warm) {
    tclod_selector_desc d;
    tclod_selector *sel = NULL;
    tclod_selector_desc_default(&d);
    table_mixed_callbacks(&f->model, &d.callbacks);
    d.solver = solver;
    d.cold_start = !(warm);
    assert_int_equal(tclod_selector_create(f->scene, &d, NULL, &sel), TCLOD_OK);
    return sel;
}

/* The selection absorbing_roots_leave_no_room works out: the roots alone, in
 * id order (0 first), no increment taken or given back, nothing dropped. */
static void assert_only_the_roots(const tclod_selector *sel, helper_fixture *f,
                                  const tclod_stats *st) {
    const tclod_id *ids = NULL;
    size_t n = 0, i;
    if (st->increments != 0 || st->decrements != 0 || st->dropped_roots != 0)
        fail_msg("%u increments and %u decrements taken, %u roots dropped",
                 (unsigned)st->increments, (unsigned)st->decrements, (unsigned)st->dropped_roots);
    assert_int_equal(tclod_selector_cut(sel, &ids, &n), TCLOD_OK);
    assert_int_equal(n, ABSORB_ROOTS + 1u);
    for (i = 0; i < n; ++i)
        if (ids[i] != (i == 0 ? 0u : 2u * (tclod_id)i - 1u))
            fail_msg("listed[%u] = %u, expected root %u", (unsigned)i, (unsigned)ids[i],
                     (unsigned)(i == 0 ? 0u : 2u * (tclod_id)i - 1u));
    helper_check_result(sel, &f->model, st, ldexp(1.0, 53), 0);
    assert_true(st->cost == ldexp(1.0, 53));
    assert_true(st->benefit == (double)(ABSORB_ROOTS + 1u));
}

static void absorbing_roots_leave_no_room(void **state) {
    /* absorbing_scene, budget 2^53. Summed in result order, root 0 first, the
     * roots fit: 2^53 + 1 lies halfway between 2^53 and 2^53 + 2, the next
     * double, and rounds to the even 2^53, again and again, so they sum to
     * 2^53 as the guarantee sums them. Their exact total is 2^53 + 20 000,
     * and each increment (Δc 1) adds 1 more: none fits. A running sum that
     * starts at 2^53 absorbs every Δc of 1 and would take all 20 000, which
     * the final sum then finds over the budget (2^53 + 2 listed after root 0
     * is exact) and gives back. So the result is the 20 001 roots in id order,
     * benefit 20 001 and cost 2^53 (both exact), with no increment taken and
     * none given back, and the solve stops because an increment did not fit.
     * The same from a warm start, with a time limit (unless it runs out), in
     * slices of 1000 iterations, and for the mixed solver, also with a smooth
     * object (b r^0.5, c r): its line search keeps 10^-9 of the budget
     * (9.0e6) free, which the roots' 2^53 leaves no room in, so it is not
     * drawn. */
    static const tclod_solver solvers[] = {TCLOD_SOLVER_GREEDY, TCLOD_SOLVER_MIXED};
    helper_fixture *f = (helper_fixture *)*state;
    float sphere[4] = {0.0f, 0.0f, -10.0f, 1.0f};
    const double budget = ldexp(1.0, 53);
    size_t k;
    int warm, smooth;
    absorbing_scene(f);
    for (smooth = 0; smooth < 2; ++smooth) {
        if (smooth)
            assert_int_equal(table_add_smooth(&f->model, f->scene, sphere, TABLE_POWER, 1.0, 0.5,
                                              1.0, 1.0, 0.0, NULL),
                             TCLOD_OK);
        for (k = 0; k < sizeof solvers / sizeof solvers[0]; ++k) {
            if (smooth && solvers[k] != TCLOD_SOLVER_MIXED)
                continue;
            for (warm = 0; warm < 2; ++warm) {
                tclod_selector *sel = absorbing_selector(f, solvers[k], warm);
                tclod_frame fr = helper_frame(NULL, budget);
                const tclod_smooth_group *groups;
                tclod_stats st;
                size_t n_groups;
                int frame, done = 0;
                for (frame = 0; frame < 2; ++frame) {
                    select_ok(sel, budget, &st);
                    assert_only_the_roots(sel, f, &st);
                    assert_int_equal(st.stop_reason, TCLOD_STOP_BUDGET);
                    assert_int_equal(st.variables, (uint32_t)smooth); /* the mixed loop ran */
                }
                fr.solve_seconds = 0.05;
                assert_int_equal(tclod_select(sel, &fr, &st), TCLOD_OK);
                assert_only_the_roots(sel, f, &st);
                assert_true(st.stop_reason == TCLOD_STOP_BUDGET ||
                            st.stop_reason == TCLOD_STOP_TIME);
                fr.solve_seconds = 0.0;
                assert_int_equal(tclod_select_begin(sel, &fr), TCLOD_OK);
                while (!done)
                    assert_int_equal(tclod_select_step(sel, 0.0, 1000, &done, &st), TCLOD_OK);
                assert_only_the_roots(sel, f, &st);
                assert_int_equal(tclod_selector_smooth_groups(sel, &groups, &n_groups), TCLOD_OK);
                assert_int_equal(n_groups, 0);
                tclod_selector_destroy(sel);
            }
        }
    }
}

static void absorbed_costs_are_not_spent_twice(void **state) {
    /* absorbing_scene. A first frame with budget 2^54 refines every root
     * (2^53 + 40 000 in all); a second frame has 2^53 + 30 000. Its exact
     * total with k roots refined is 2^53 + 20 000 + k: 10 000 fit. The
     * fit tests see the running sum plus what it absorbed, each of the two
     * additions exact to half an ulp (1 here), so they take from 9 999 to
     * 10 002; the sum in result order absorbs the roots' 1s after root 0, so
     * that total is within the budget. A cold solve takes them and gives none
     * back; a warm one collapses refined roots until its running total fits
     * and ends with as many refined. (A solve that trusts the absorbed
     * running sum takes about 15 000, which the final sum then finds over the
     * budget.) */
    helper_fixture *f = (helper_fixture *)*state;
    const double budget = ldexp(1.0, 53) + 30000.0;
    int warm;
    absorbing_scene(f);
    for (warm = 0; warm < 2; ++warm) {
        tclod_selector *sel = absorbing_selector(f, TCLOD_SOLVER_GREEDY, warm);
        const tclod_id *ids = NULL;
        tclod_stats st;
        size_t n = 0, i, refined = 0;
        select_ok(sel, ldexp(1.0, 54), &st);
        assert_int_equal(st.increments, ABSORB_ROOTS);
        select_ok(sel, budget, &st);
        helper_check_result(sel, &f->model, &st, budget, 0);
        assert_int_equal(tclod_selector_cut(sel, &ids, &n), TCLOD_OK);
        for (i = 0; i < n; ++i)
            refined += ids[i] != 0 && ids[i] % 2u == 0;
        if (refined < 9999u || refined > 10002u)
            fail_msg("%u roots refined, expected 9 999 .. 10 002", (unsigned)refined);
        if (!warm && st.decrements != 0)
            fail_msg("cold: %u increments taken, %u given back", (unsigned)st.increments,
                     (unsigned)st.decrements);
        tclod_selector_destroy(sel);
    }
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

/* Values at the edges of the callbacks' ranges, under the greedy and the
 * Robin Hood solvers with an unlimited budget. Roots 0 (b0, 1), 1 (1, c1) and
 * 2 (1, 1), all leaves. -0 is a benefit of 0 (root 0 invisible, not a bad
 * value) and a cost of 0; the smallest subnormal benefit makes root 0 visible
 * and DBL_MAX is a finite cost, so both are drawn; a NaN with its sign bit set
 * and -DBL_MIN are bad (root 0 invisible; root 1 unaffordable, so dropped).
 * The Robin Hood solver takes each instance's complexity from the cost of
 * its finest level (here the root itself), which its frame asks once: a bad
 * cost is counted once, as by the greedy. */
static void edge_values_are_told_apart_from_bad_ones(void **state) {
    static const struct {
        double b0, c1;
        unsigned drawn;       /* bit i: root i is listed */
        unsigned invalid[2];  /* bad values counted by either solver */
        double benefit, cost; /* of the selection */
    } cases[] = {
        {-0.0, 1.0, 6u, {0, 0}, 2.0, 2.0},
        {4.9406564584124654e-324, 1.0, 7u, {0, 0}, 2.0, 3.0}, /* the benefit sum absorbs it */
        {1.0, -0.0, 7u, {0, 0}, 3.0, 2.0},
        {1.0, DBL_MAX, 7u, {0, 0}, 3.0, DBL_MAX},
        {-NAN, 1.0, 6u, {1, 1}, 2.0, 2.0},
        {1.0, -DBL_MIN, 5u, {1, 1}, 2.0, 2.0},
    };
    static const tclod_solver solvers[] = {TCLOD_SOLVER_GREEDY, TCLOD_SOLVER_ROBIN_HOOD};
    helper_fixture *f = (helper_fixture *)*state;
    size_t c, k;
    helper_add(f, TCLOD_NONE, 1.0, 1.0);
    helper_add(f, TCLOD_NONE, 1.0, 1.0);
    helper_add(f, TCLOD_NONE, 1.0, 1.0);
    for (k = 0; k < sizeof solvers / sizeof solvers[0]; ++k)
        for (c = 0; c < sizeof cases / sizeof cases[0]; ++c) {
            tclod_selector_desc d;
            tclod_selector *sel = NULL;
            tclod_stats st;
            tclod_id listed[3];
            size_t n = 0;
            tclod_id i;
            f->model.benefit[0] = cases[c].b0;
            f->model.cost[1] = cases[c].c1;
            tclod_selector_desc_default(&d);
            table_callbacks(&f->model, &d.callbacks);
            d.solver = solvers[k];
            assert_int_equal(tclod_selector_create(f->scene, &d, NULL, &sel), TCLOD_OK);
            select_ok(sel, INFINITY, &st);
            for (i = 0; i < 3; ++i)
                if (cases[c].drawn & (1u << i))
                    listed[n++] = i;
            helper_assert_cut(sel, listed, n);
            if (st.invalid_values != cases[c].invalid[k] || st.benefit != cases[c].benefit ||
                st.cost != cases[c].cost)
                fail_msg("solver %d, case %u: %u bad values, benefit %g, cost %g", (int)solvers[k],
                         (unsigned)c, (unsigned)st.invalid_values, st.benefit, st.cost);
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
        d.cold_start = !(warm);
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
    d.mixed.split_threshold = NAN;
    assert_int_equal(tclod_selector_create(f->scene, &d, NULL, &out), TCLOD_ERR_ARG);
    d = good;
    d.mixed.split_threshold = -0.5;
    assert_int_equal(tclod_selector_create(f->scene, &d, NULL, &out), TCLOD_ERR_ARG);
    d = good;
    d.greedy.lookahead = TCLOD_MAX_LOOKAHEAD + 1u;
    assert_int_equal(tclod_selector_create(f->scene, &d, NULL, &out), TCLOD_ERR_ARG);
    assert_ptr_equal(out, sentinel);
    d = good;
    d.greedy.restarts = TCLOD_MAX_RESTARTS + 1u;
    assert_int_equal(tclod_selector_create(f->scene, &d, NULL, &out), TCLOD_ERR_ARG);
    assert_ptr_equal(out, sentinel);
    {
        /* on/off fields take 0 or 1 only: 2 or -1 is a caller's mistake */
        static const int bad_flags[] = {2, -1};
        size_t i;
        for (i = 0; i < 2u; ++i) {
            d = good;
            d.cold_start = bad_flags[i];
            assert_int_equal(tclod_selector_create(f->scene, &d, NULL, &out), TCLOD_ERR_ARG);
            d = good;
            d.mixed.split_smooth = bad_flags[i];
            assert_int_equal(tclod_selector_create(f->scene, &d, NULL, &out), TCLOD_ERR_ARG);
            d = good;
            d.strict = bad_flags[i];
            assert_int_equal(tclod_selector_create(f->scene, &d, NULL, &out), TCLOD_ERR_ARG);
            d = good;
            d.mixed.plain_gradient = bad_flags[i];
            assert_int_equal(tclod_selector_create(f->scene, &d, NULL, &out), TCLOD_ERR_ARG);
        }
        assert_ptr_equal(out, sentinel);
    }
    d = good;
    d.greedy.lookahead = TCLOD_MAX_LOOKAHEAD;
    d.greedy.restarts = TCLOD_MAX_RESTARTS;
    assert_int_equal(tclod_selector_create(f->scene, &d, NULL, &out), TCLOD_OK);
    tclod_selector_destroy(out);
}

/* Smooth callbacks for selectors that need them but solve no smooth object. */
static double linear_smooth(void *user, const tclod_query *q, double r, double *d_dr) {
    (void)user;
    (void)q;
    *d_dr = 1.0;
    return r;
}

static void only_the_three_solvers_can_be_created(void **state) {
    helper_fixture *f = (helper_fixture *)*state;
    const tclod_solver solvers[] = {TCLOD_SOLVER_GREEDY, TCLOD_SOLVER_MIXED,
                                    TCLOD_SOLVER_ROBIN_HOOD, (tclod_solver)3, (tclod_solver)42};
    tclod_selector_desc d;
    size_t i;
    helper_add(f, TCLOD_NONE, 1.0, 1.0);
    for (i = 0; i < sizeof solvers / sizeof solvers[0]; ++i) {
        tclod_selector *const sentinel = (tclod_selector *)(void *)f;
        tclod_selector *out = sentinel;
        tclod_status st;
        tclod_selector_desc_default(&d);
        table_callbacks(&f->model, &d.callbacks);
        d.callbacks.smooth_benefit = d.callbacks.smooth_cost = linear_smooth;
        d.solver = solvers[i];
        st = tclod_selector_create(f->scene, &d, NULL, &out);
        if (i < 3) {
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
    assert_int_equal(d.cold_start, 0);
    assert_int_equal(d.mixed.split_smooth, 0);
    assert_true(d.mixed.split_threshold == 0.1);
    assert_int_equal(d.strict, 0);
    assert_int_equal(d.greedy.lookahead, 0);
    assert_int_equal(d.greedy.restarts, 32);
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
    d.cold_start = !(warm);
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

/* A host that breaks the contract: its first benefit call tries every edit
 * of the scene, and keeps what each returned. */
typedef struct editing_host {
    helper_fixture *f;
    int armed;
    tclod_status status[6];
} editing_host;

static double editing_benefit(void *user, const tclod_query *q) {
    editing_host *h = (editing_host *)user;
    if (h->armed) {
        tclod_scene *s = h->f->scene;
        tclod_bounds b = tclod_bounds_sphere(0.0, 0.0, 0.0, 1.0);
        const float sphere[4] = {0.0f, 0.0f, 0.0f, 1.0f};
        tclod_id id;
        h->armed = 0;
        h->status[0] = tclod_scene_add_node(s, TCLOD_NONE, NULL, &id);
        h->status[1] = tclod_scene_remove_node(s, 0);
        h->status[2] = tclod_scene_set_node_bounds(s, 1, &b);
        h->status[3] = tclod_scene_add_smooth(s, sphere, &id);
        h->status[4] = tclod_scene_remove_smooth(s, 0);
        h->status[5] = tclod_scene_set_smooth_bounds(s, 0, sphere);
    }
    return table_benefit(&h->f->model, q);
}

static double editing_cost(void *user, const tclod_query *q) {
    return table_cost(&((editing_host *)user)->f->model, q);
}

/* Roots 0 and 1 (b 1, c 1) and a smooth object 0, unlimited budget: {0, 1}.
 * During the next (warm) solve a callback tries to add, remove and move
 * nodes and smooth objects: each is refused with TCLOD_ERR_STATE and changes
 * nothing, and the solve goes on to {0, 1}, benefit 2, cost 2. After it, the
 * same edits are accepted. */
static void scene_edited_by_a_callback(helper_fixture *f, tclod_solver solver) {
    static const tclod_id before[] = {0, 1};
    const float sphere[4] = {0.0f, 0.0f, 0.0f, 1.0f};
    tclod_frame frame = helper_frame(NULL, INFINITY);
    editing_host h;
    tclod_selector_desc d;
    tclod_selector *sel;
    tclod_stats st;
    tclod_bounds b;
    tclod_id smooth;
    int i;
    helper_add(f, TCLOD_NONE, 1.0, 1.0);
    helper_add(f, TCLOD_NONE, 1.0, 1.0);
    assert_int_equal(tclod_scene_add_smooth(f->scene, sphere, &smooth), TCLOD_OK);
    h.f = f;
    h.armed = 0;
    tclod_selector_desc_default(&d);
    d.solver = solver;
    d.callbacks.benefit = editing_benefit;
    d.callbacks.cost = editing_cost;
    d.callbacks.user = &h;
    assert_int_equal(tclod_selector_create(f->scene, &d, NULL, &sel), TCLOD_OK);
    assert_int_equal(tclod_select(sel, &frame, &st), TCLOD_OK);
    helper_assert_cut(sel, before, 2);
    h.armed = 1;
    assert_int_equal(tclod_select(sel, &frame, &st), TCLOD_OK);
    assert_int_equal(h.armed, 0);
    for (i = 0; i < 6; ++i)
        assert_int_equal(h.status[i], TCLOD_ERR_STATE);
    helper_assert_cut(sel, before, 2);
    assert_true(st.benefit == 2.0 && st.cost == 2.0);
    assert_int_equal(tclod_scene_node_count(f->scene), 2);
    assert_int_equal(tclod_scene_smooth_count(f->scene), 1);
    assert_true(tclod_scene_node_live(f->scene, 0) && tclod_scene_smooth_live(f->scene, 0));
    assert_int_equal(tclod_scene_node_bounds(f->scene, 1, &b), TCLOD_OK);
    assert_int_equal(b.kind, TCLOD_BOUNDS_NONE);
    /* outside the solve the same edits go through */
    assert_int_equal(tclod_scene_remove_smooth(f->scene, 0), TCLOD_OK);
    assert_int_equal(tclod_scene_remove_node(f->scene, 0), TCLOD_OK);
    tclod_selector_destroy(sel);
}

static void an_edit_from_a_greedy_callback_is_refused_and_the_solve_goes_on(void **state) {
    scene_edited_by_a_callback((helper_fixture *)*state, TCLOD_SOLVER_GREEDY);
}

static void an_edit_from_a_robin_hood_callback_is_refused_and_the_solve_goes_on(void **state) {
    scene_edited_by_a_callback((helper_fixture *)*state, TCLOD_SOLVER_ROBIN_HOOD);
}

/* ---- the mixed solver ---------------------------------------------------- *
 *
 * The same guarantees for TCLOD_SOLVER_MIXED, whose result is the cut
 * followed by the smooth groups. The checks recompute what the callbacks
 * returned from the table_model itself: a group's cost is table_smooth_cost_of
 * of its members (positions first .. first + count - 1 of
 * tclod_scene_smooth_order) at the group's resolution, added in that order
 * from 0.0, which is what table_smooth_cost returns for the group. */

/* Largest smooth scene whose result a mixed_snapshot can hold. */
#define SNAPSHOT_SMOOTH 1024u

/* A copy of a mixed selection: cut, groups and every object's resolution. */
typedef struct mixed_snapshot {
    snapshot cut;
    tclod_smooth_group groups[SNAPSHOT_SMOOTH];
    size_t group_count;
    double resolution[SNAPSHOT_SMOOTH];
    uint32_t smooth_count;
} mixed_snapshot;

static void take_mixed_snapshot(const tclod_selector *sel, const tclod_scene *s,
                                mixed_snapshot *ms) {
    const tclod_smooth_group *groups = NULL;
    uint32_t i;
    take_snapshot(sel, &ms->cut);
    assert_int_equal(tclod_selector_smooth_groups(sel, &groups, &ms->group_count), TCLOD_OK);
    assert_true(ms->group_count <= SNAPSHOT_SMOOTH);
    if (ms->group_count > 0)
        memcpy(ms->groups, groups, ms->group_count * sizeof *groups);
    ms->smooth_count = tclod_scene_smooth_count(s);
    assert_true(ms->smooth_count <= SNAPSHOT_SMOOTH);
    for (i = 0; i < ms->smooth_count; ++i)
        ms->resolution[i] = tclod_selector_resolution(sel, i);
}

/* 1 when two group lists are bit-identical, field by field. */
static int groups_identical(const tclod_smooth_group *a, const tclod_smooth_group *b, size_t n) {
    size_t i;
    for (i = 0; i < n; ++i)
        if (a[i].first != b[i].first || a[i].count != b[i].count ||
            memcmp(&a[i].resolution, &b[i].resolution, sizeof(double)) != 0 ||
            memcmp(&a[i].benefit, &b[i].benefit, sizeof(double)) != 0 ||
            memcmp(&a[i].cost, &b[i].cost, sizeof(double)) != 0)
            return 0;
    return 1;
}

/* Asserts the current result is the snapshot, bit for bit. */
static void assert_mixed_snapshot(const tclod_selector *sel, const mixed_snapshot *ms) {
    const tclod_smooth_group *groups = NULL;
    size_t n = 0;
    uint32_t i;
    assert_snapshot(sel, &ms->cut);
    assert_int_equal(tclod_selector_smooth_groups(sel, &groups, &n), TCLOD_OK);
    assert_int_equal(n, ms->group_count);
    assert_true(groups_identical(groups, ms->groups, n));
    for (i = 0; i < ms->smooth_count; ++i) {
        double r = tclod_selector_resolution(sel, i);
        if (memcmp(&r, &ms->resolution[i], sizeof r) != 0)
            fail_msg("resolution of smooth object %u changed: %.17g, was %.17g", (unsigned)i, r,
                     ms->resolution[i]);
    }
}

/* Asserts what a mixed selection over a table_model promises (docs/api.md,
 * tclod_select): the costs of the listed cut nodes, then those of the drawn
 * groups recomputed member by member, summed in double in that order, are
 * <= budget and are st->cost exactly; every group is a non-empty range of the
 * smooth order, after the one before it, at a resolution in (0, 1], with the
 * cost the callback returns for it; every member's resolution is its group's
 * and every other object's 0. With exact_values (the callbacks return the
 * table's values unchanged) also: the listed nodes form a cut, every group's
 * benefit is the callback's and st->benefit is the sum in result order. */
static void check_mixed_result(const tclod_selector *sel, tclod_scene *s, const table_model *m,
                               const tclod_stats *st, double budget, int exact_values,
                               unsigned long long tag) {
    const tclod_id *ids = NULL, *order = NULL;
    const tclod_smooth_group *groups = NULL;
    size_t n = 0, ng = 0, g;
    uint32_t count = 0, i;
    double cost, benefit, *res;
    assert_int_equal(tclod_selector_cut(sel, &ids, &n), TCLOD_OK);
    if (exact_values && !exact_check_cut(m, ids, n, 1))
        fail_msg("case %llu: the listed nodes are not a cut", tag);
    cost = table_sum_cost(m, ids, n);
    benefit = table_sum_benefit(m, ids, n);
    assert_int_equal(tclod_scene_smooth_order(s, &order, &count), TCLOD_OK);
    assert_int_equal(count, m->smooth.count);
    assert_int_equal(tclod_selector_smooth_groups(sel, &groups, &ng), TCLOD_OK);
    res = (double *)calloc(count ? count : 1u, sizeof *res);
    assert_non_null(res);
    for (g = 0; g < ng; ++g) {
        const tclod_smooth_group *G = &groups[g];
        double gc = 0.0, gb = 0.0;
        if (!(G->resolution > 0.0 && G->resolution <= 1.0))
            fail_msg("case %llu: group %u has resolution %.17g", tag, (unsigned)g, G->resolution);
        if (G->count == 0 || G->first >= count || G->count > count - G->first)
            fail_msg("case %llu: group %u = [%u, +%u) outside the %u objects", tag, (unsigned)g,
                     (unsigned)G->first, (unsigned)G->count, (unsigned)count);
        if (g > 0 && G->first < groups[g - 1].first + groups[g - 1].count)
            fail_msg("case %llu: group %u overlaps or precedes the one before", tag, (unsigned)g);
        for (i = G->first; i < G->first + G->count; ++i) {
            gc += table_smooth_cost_of(m, order[i], G->resolution, NULL);
            gb += table_smooth_benefit_of(m, order[i], G->resolution, NULL);
            res[order[i]] = G->resolution;
        }
        if (G->cost != gc)
            fail_msg("case %llu: group %u reports cost %.17g, its members cost %.17g", tag,
                     (unsigned)g, G->cost, gc);
        if (!(G->benefit >= 0.0) || isinf(G->benefit))
            fail_msg("case %llu: group %u reports benefit %g", tag, (unsigned)g, G->benefit);
        if (exact_values && G->benefit != gb)
            fail_msg("case %llu: group %u reports benefit %.17g, its members give %.17g", tag,
                     (unsigned)g, G->benefit, gb);
        cost += gc;
        benefit += G->benefit;
    }
    if (!(cost <= budget))
        fail_msg("case %llu: cost %.17g in result order exceeds budget %.17g", tag, cost, budget);
    if (st->cost != cost)
        fail_msg("case %llu: stats.cost %.17g != %.17g summed in result order", tag, st->cost,
                 cost);
    if (exact_values && st->benefit != benefit)
        fail_msg("case %llu: stats.benefit %.17g != %.17g summed in result order", tag, st->benefit,
                 benefit);
    for (i = 0; i < count; ++i) {
        double r = tclod_selector_resolution(sel, i);
        if (r != res[i])
            fail_msg("case %llu: smooth object %u has resolution %.17g, its group %.17g", tag,
                     (unsigned)i, r, res[i]);
    }
    free(res);
}

/* Adds a smooth object with random parameters (table_add_smooth): power
 * (p in (0, 1]) or log (p in [0.5, 50)) benefit, weight in [0.1, 10) or
 * (1 in 16) 0; half with a linear cost k r, half kinked (steep in 1.5 to 40
 * times k, kink in (0, 0.2)); k in [0.05, 5) or (1 in 16) 0. It lies at a
 * random place in [-extent, extent]² on the ground, radius in [0.05, 3), or
 * (1 in 4) at place[], the place of the object before, so that quadtree
 * leaves hold several objects. */
static void random_smooth(table_model *m, tclod_scene *s, table_rng *rng, float extent,
                          float place[4]) {
    table_shape shape = table_rng_below(rng, 2) ? TABLE_LOG : TABLE_POWER;
    double w = table_rng_below(rng, 16) == 0 ? 0.0 : table_rng_uniform(rng, 0.1, 10.0);
    double p = shape == TABLE_POWER ? 1.0 - table_rng_uniform(rng, 0.0, 1.0)
                                    : table_rng_uniform(rng, 0.5, 50.0);
    double k = table_rng_below(rng, 16) == 0 ? 0.0 : table_rng_uniform(rng, 0.05, 5.0);
    double steep = k, kink = 0.0;
    if (table_rng_below(rng, 2)) {
        steep = (k > 0.0 ? k : 0.5) * table_rng_uniform(rng, 1.5, 40.0);
        kink = table_rng_uniform(rng, 0.001, 0.2);
    }
    if (m->smooth.count == 0 || table_rng_below(rng, 4) != 0) {
        place[0] = (float)table_rng_uniform(rng, -extent, extent);
        place[1] = (float)table_rng_uniform(rng, -1.0, 1.0);
        place[2] = (float)table_rng_uniform(rng, -extent, extent);
        place[3] = (float)table_rng_uniform(rng, 0.05, 3.0);
    }
    assert_int_equal(table_add_smooth(m, s, place, shape, w, p, k, steep, kink, NULL), TCLOD_OK);
}

/* A view from a random place in the scene's square at a random height,
 * turned to a random heading and tilted down, with a random field of view and
 * far plane: some objects lie behind it, beyond it or project tiny. */
static void random_view(tclod_view *v, table_rng *rng, float extent) {
    double heading = table_rng_uniform(rng, 0.0, 6.283185307179586);
    helper_view(v);
    v->eye[0] = (float)table_rng_uniform(rng, -extent, extent);
    v->eye[1] = (float)table_rng_uniform(rng, 0.5, 10.0);
    v->eye[2] = (float)table_rng_uniform(rng, -extent, extent);
    v->forward[0] = (float)cos(heading);
    v->forward[1] = (float)table_rng_uniform(rng, -0.5, 0.0);
    v->forward[2] = (float)sin(heading);
    v->fov_y = (float)table_rng_uniform(rng, 0.3, 1.5);
    v->far_z = extent * (float)table_rng_uniform(rng, 0.5, 3.0) + 1.0f;
}

/* A mixed-solver description over m's table callbacks. */
static void mixed_desc(tclod_selector_desc *d, table_model *m, int precondition, int split) {
    tclod_selector_desc_default(d);
    d->solver = TCLOD_SOLVER_MIXED;
    table_mixed_callbacks(m, &d->callbacks);
    d->mixed.plain_gradient = !(precondition);
    d->mixed.split_smooth = split;
}

/* Sum of every node's cost and every smooth object's cost at full
 * resolution: no selection costs more. */
static double full_cost(const table_model *m) {
    double sum = 0.0;
    uint32_t i;
    for (i = 0; i < m->count; ++i)
        sum += m->cost[i];
    for (i = 0; i < m->smooth.count; ++i)
        sum += table_smooth_cost_of(m, i, 1.0, NULL);
    return sum;
}

static void mixed_budget_holds_on_ten_thousand_random_mixed_instances(void **state) {
    /* Per instance: a random hierarchy of 0-8 nodes (diminishing or
     * arbitrary values), 0-12 random smooth objects in a square of side 1,
     * 40 or 400, both precondition modes, splitting on or off with thresholds
     * from 0 to 10, small-detail culling off to 5000 px², sometimes other
     * barrier and tolerance values. Two frames each: budget 0, unlimited, or
     * uniform up to 1.25 times the full cost; a random view in 2 of 3 frames;
     * an iteration limit of 1-6 in 1 of 8. Coverage counters make sure
     * groups are drawn, shared and culled, so that the checks bite. */
    static const float extents[] = {0.5f, 20.0f, 200.0f};
    static const double cull_areas[] = {0.0, 1.0, 50.0, 5000.0};
    static const double thresholds[] = {0.0, 0.01, 0.3, 10.0};
    uint32_t drawn = 0, shared = 0, culled = 0, limited = 0, kinked_drawn = 0;
    uint64_t seed;
    (void)state;
    for (seed = 1; seed <= 10000; ++seed) {
        tclod_scene *s = NULL;
        tclod_selector *sel = NULL;
        tclod_selector_desc d;
        table_model m;
        table_rng rng;
        float place[4] = {0.0f, 0.0f, 0.0f, 1.0f}, extent;
        uint32_t nodes, smooth, i;
        double full;
        int frame;
        table_rng_seed(&rng, seed);
        table_init(&m);
        assert_int_equal(tclod_scene_create(NULL, &s), TCLOD_OK);
        nodes = table_rng_below(&rng, 9);
        if (nodes > 0)
            assert_int_equal(table_random_hierarchy(
                                 &m, s, &rng, nodes,
                                 1 + table_rng_below(&rng, nodes < 3 ? nodes : 3),
                                 table_rng_below(&rng, 2) ? TABLE_ARBITRARY : TABLE_DIMINISHING),
                             TCLOD_OK);
        smooth = table_rng_below(&rng, 13);
        extent = extents[table_rng_below(&rng, 3)];
        for (i = 0; i < smooth; ++i)
            random_smooth(&m, s, &rng, extent, place);
        full = full_cost(&m);
        mixed_desc(&d, &m, (int)table_rng_below(&rng, 2), (int)table_rng_below(&rng, 2));
        d.mixed.split_threshold = thresholds[table_rng_below(&rng, 4)];
        d.smooth_cull_area = cull_areas[table_rng_below(&rng, 4)];
        if (table_rng_below(&rng, 4) == 0) {
            d.mixed.smooth_epsilon = table_rng_uniform(&rng, 0.0, 0.5);
            d.mixed.smooth_tolerance = table_rng_uniform(&rng, 0.0, 0.9);
        }
        assert_int_equal(tclod_selector_create(s, &d, NULL, &sel), TCLOD_OK);
        for (frame = 0; frame < 2; ++frame) {
            uint32_t kind = table_rng_below(&rng, 20);
            double budget =
                kind == 0 ? 0.0
                          : (kind == 1 ? INFINITY : table_rng_uniform(&rng, 0.0, 1.25 * full));
            tclod_view view;
            tclod_frame f;
            tclod_stats st;
            const tclod_smooth_group *groups;
            size_t ng, g;
            int has_view = table_rng_below(&rng, 3) != 0;
            if (has_view)
                random_view(&view, &rng, extent);
            f = helper_frame(has_view ? &view : NULL, budget);
            if (table_rng_below(&rng, 8) == 0) {
                f.max_iterations = 1 + table_rng_below(&rng, 6);
                limited++;
            }
            if (tclod_select(sel, &f, &st) != TCLOD_OK)
                fail_msg("case %llu: select failed", (unsigned long long)seed);
            check_mixed_result(sel, s, &m, &st, budget, 1, (unsigned long long)seed);
            assert_int_equal(st.invalid_values, 0);
            assert_int_equal(tclod_selector_smooth_groups(sel, &groups, &ng), TCLOD_OK);
            drawn += ng > 0;
            for (g = 0; g < ng; ++g) {
                const tclod_id *order;
                uint32_t count;
                assert_int_equal(tclod_scene_smooth_order(s, &order, &count), TCLOD_OK);
                shared += groups[g].count > 1;
                kinked_drawn += m.smooth.kink[order[groups[g].first]] > 0.0;
            }
            culled += has_view && !d.mixed.split_smooth && st.variables < smooth;
        }
        tclod_selector_destroy(sel);
        tclod_scene_destroy(s);
        table_free(&m);
    }
    if (drawn < 5000 || shared < 500 || culled < 1000 || limited < 1000 || kinked_drawn < 1000)
        fail_msg("coverage: %u frames drew groups, %u groups shared, %u frames culled, "
                 "%u frames limited, %u kinked groups drawn",
                 (unsigned)drawn, (unsigned)shared, (unsigned)culled, (unsigned)limited,
                 (unsigned)kinked_drawn);
}

/* What part of a smooth callback's answer a fault makes bad. */
enum fault_part {
    FAULT_BOTH = 0,      /* value and derivative (table_smooth.bad_after for benefits) */
    FAULT_VALUE = 1,     /* the value; the derivative stays good */
    FAULT_DERIVATIVE = 2 /* the derivative; the value stays good */
};

/* Table callbacks that hand out bad smooth values on request and count them:
 * from the bad_after-th call of the chosen callback on, every call answers
 * with bad_value in the chosen part. Benefit faults on both parts go through
 * table_smooth.bad_after, the table's own mechanism. */
typedef struct smooth_faults {
    table_model *model;
    int which;          /* 0: smooth_benefit, 1: smooth_cost */
    int part;           /* an enum fault_part */
    uint32_t bad_after; /* 0 = no fault (wrapper faults only) */
    double bad_value;
    uint32_t bad_calls;   /* calls that answered with a bad value or derivative */
    uint32_t bad_numbers; /* bad values and derivatives handed out */
} smooth_faults;

static int value_is_bad(double v) {
    return !(v >= 0.0) || isinf(v);
}

static double faulty_benefit(void *user, const tclod_query *q) {
    return table_benefit(((smooth_faults *)user)->model, q);
}

static double faulty_cost(void *user, const tclod_query *q) {
    return table_cost(((smooth_faults *)user)->model, q);
}

/* Applies a wrapper fault of callback `which` to a good answer (v, *d_dr). */
static double apply_fault(smooth_faults *f, int which, double v, double *d_dr) {
    if (f->which != which || f->bad_after == 0 || --f->bad_after != 0)
        return v;
    f->bad_after = 1; /* and every call after it */
    if (f->part != FAULT_DERIVATIVE)
        v = f->bad_value;
    if (f->part != FAULT_VALUE)
        *d_dr = f->bad_value;
    return v;
}

/* Counts what a smooth callback answered. */
static double count_faults(smooth_faults *f, double v, const double *d_dr) {
    int bad = value_is_bad(v) + value_is_bad(*d_dr);
    f->bad_calls += bad > 0;
    f->bad_numbers += (uint32_t)bad;
    return v;
}

static double faulty_smooth_benefit(void *user, const tclod_query *q, double r, double *d_dr) {
    smooth_faults *f = (smooth_faults *)user;
    double v = table_smooth_benefit(f->model, q, r, d_dr);
    return count_faults(f, apply_fault(f, 0, v, d_dr), d_dr);
}

static double faulty_smooth_cost(void *user, const tclod_query *q, double r, double *d_dr) {
    smooth_faults *f = (smooth_faults *)user;
    double v = table_smooth_cost(f->model, q, r, d_dr);
    return count_faults(f, apply_fault(f, 1, v, d_dr), d_dr);
}

static void faulty_desc(tclod_selector_desc *d, smooth_faults *f, int precondition, int split) {
    mixed_desc(d, f->model, precondition, split);
    d->callbacks.benefit = faulty_benefit;
    d->callbacks.cost = faulty_cost;
    d->callbacks.smooth_benefit = faulty_smooth_benefit;
    d->callbacks.smooth_cost = faulty_smooth_cost;
    d->callbacks.user = f;
}

/* Arms a fault: from the k-th call of the smooth benefit (which == 0) or
 * cost (which == 1) on, `part` of every answer is `bad`; k = 0 disarms. */
static void arm_fault(smooth_faults *f, int which, int part, uint32_t k, double bad) {
    int table = which == 0 && part == FAULT_BOTH;
    f->model->smooth.bad_after = table ? k : 0;
    f->model->smooth.bad_value = bad;
    f->which = which;
    f->part = part;
    f->bad_after = table ? 0 : k;
    f->bad_value = bad;
    f->bad_calls = f->bad_numbers = 0;
}

/* 10 discrete nodes and 16 smooth objects in a 40 x 40 square. */
static void faulty_scene(table_model *m, tclod_scene *s, uint64_t seed) {
    table_rng rng;
    float place[4] = {0.0f, 0.0f, 0.0f, 1.0f};
    uint32_t i;
    table_rng_seed(&rng, seed);
    assert_int_equal(table_random_hierarchy(m, s, &rng, 10, 2, TABLE_DIMINISHING), TCLOD_OK);
    for (i = 0; i < 16; ++i)
        random_smooth(m, s, &rng, 20.0f, place);
}

static const uint32_t fault_calls[] = {1, 2, 3, 5, 8, 13, 21, 34, 55, 89, 144, 377, 100000};

static void bad_smooth_values_are_counted_and_the_budget_still_holds(void **state) {
    /* Each bad value (NaN, inf, -inf, -1) as the k-th and every later smooth
     * benefit, or cost, of a select: in the value, the derivative or both.
     * Every bad number is counted in invalid_values: exactly when only one
     * part is bad; when both are, the call is counted at least once and at
     * most twice (the header leaves open whether a bad value's derivative
     * counts apart). The budget holds, recomputed from the table. With k = 1
     * every value is bad, so no group can be drawn: a bad benefit makes the
     * group invisible, a bad cost its resolution unaffordable, even under an
     * unlimited budget. k beyond the calls made leaves a clean frame. */
    helper_fixture *f = (helper_fixture *)*state;
    smooth_faults faults;
    double budgets[2];
    size_t v, k, b;
    int which, part, mode;
    uint32_t clean = 0;
    faulty_scene(&f->model, f->scene, 41);
    budgets[0] = 0.4 * full_cost(&f->model);
    budgets[1] = INFINITY;
    memset(&faults, 0, sizeof faults);
    faults.model = &f->model;
    for (mode = 0; mode < 4; ++mode) {
        tclod_selector_desc d;
        tclod_selector *sel = NULL;
        faulty_desc(&d, &faults, mode & 1, mode >> 1);
        assert_int_equal(tclod_selector_create(f->scene, &d, NULL, &sel), TCLOD_OK);
        for (v = 0; v < sizeof bad_values / sizeof bad_values[0]; ++v)
            for (which = 0; which < 2; ++which)
                for (part = 0; part < 3; ++part)
                    for (k = 0; k < sizeof fault_calls / sizeof fault_calls[0]; ++k)
                        for (b = 0; b < 2; ++b) {
                            tclod_frame frame = helper_frame(NULL, budgets[b]);
                            tclod_stats st;
                            const tclod_smooth_group *groups;
                            size_t ng;
                            uint32_t calls, numbers;
                            unsigned long long tag =
                                (unsigned long long)(mode * 1000000 + v * 100000 + which * 10000 +
                                                     part * 1000 + k * 10 + b);
                            arm_fault(&faults, which, part, fault_calls[k], bad_values[v]);
                            if (tclod_select(sel, &frame, &st) != TCLOD_OK)
                                fail_msg("case %llu: select failed", tag);
                            calls = faults.bad_calls;
                            numbers = faults.bad_numbers;
                            arm_fault(&faults, 0, FAULT_BOTH, 0, 0.0);
                            if (part == FAULT_BOTH
                                    ? st.invalid_values < calls || st.invalid_values > numbers
                                    : st.invalid_values != numbers)
                                fail_msg("case %llu: %u bad numbers in %u calls handed out, "
                                         "%u counted",
                                         tag, (unsigned)numbers, (unsigned)calls,
                                         (unsigned)st.invalid_values);
                            check_mixed_result(sel, f->scene, &f->model, &st, budgets[b],
                                               calls == 0 || part == FAULT_DERIVATIVE, tag);
                            assert_int_equal(tclod_selector_smooth_groups(sel, &groups, &ng),
                                             TCLOD_OK);
                            if (fault_calls[k] == 1) {
                                assert_true(calls > 0);
                                if (part != FAULT_DERIVATIVE && ng != 0)
                                    fail_msg("case %llu: %u groups drawn with every %s bad", tag,
                                             (unsigned)ng, which ? "cost" : "benefit");
                            }
                            clean += calls == 0;
                        }
        tclod_selector_destroy(sel);
    }
    assert_true(clean > 0); /* the largest k leaves some frames clean */
}

static void strict_mode_turns_bad_smooth_values_into_errors_and_keeps_the_result(void **state) {
    /* A good selection first, with groups drawn; then each bad value as the
     * k-th and later smooth benefit or cost, in the value, the derivative or
     * both: the call fails with TCLOD_ERR_CALLBACK whenever a bad number was
     * handed out (and succeeds otherwise), its stats are not written, and
     * cut, groups and resolutions stay bit for bit what they were. */
    helper_fixture *f = (helper_fixture *)*state;
    smooth_faults faults;
    double budget;
    int mode;
    faulty_scene(&f->model, f->scene, 43);
    budget = 0.4 * full_cost(&f->model);
    memset(&faults, 0, sizeof faults);
    faults.model = &f->model;
    for (mode = 0; mode < 4; ++mode) {
        tclod_selector_desc d;
        tclod_selector *sel = NULL;
        tclod_frame frame = helper_frame(NULL, budget);
        tclod_stats st;
        mixed_snapshot *before = (mixed_snapshot *)malloc(sizeof *before);
        size_t v, k;
        int which, part;
        assert_non_null(before);
        faulty_desc(&d, &faults, mode & 1, mode >> 1);
        d.strict = 1;
        assert_int_equal(tclod_selector_create(f->scene, &d, NULL, &sel), TCLOD_OK);
        assert_int_equal(tclod_select(sel, &frame, &st), TCLOD_OK);
        check_mixed_result(sel, f->scene, &f->model, &st, budget, 1, (unsigned long long)mode);
        take_mixed_snapshot(sel, f->scene, before);
        assert_true(before->group_count > 0);
        for (v = 0; v < sizeof bad_values / sizeof bad_values[0]; ++v)
            for (which = 0; which < 2; ++which)
                for (part = 0; part < 3; ++part)
                    for (k = 0; k < sizeof fault_calls / sizeof fault_calls[0]; ++k) {
                        tclod_status status;
                        uint32_t calls;
                        arm_fault(&faults, which, part, fault_calls[k], bad_values[v]);
                        poison_stats(&st);
                        status = tclod_select(sel, &frame, &st);
                        calls = faults.bad_calls;
                        arm_fault(&faults, 0, FAULT_BOTH, 0, 0.0);
                        if (fault_calls[k] == 1)
                            assert_true(calls > 0);
                        if (calls > 0) {
                            if (status != TCLOD_ERR_CALLBACK)
                                fail_msg("mode %d: smooth %s part %d = %g (call %u on) gave "
                                         "status %d",
                                         mode, which ? "cost" : "benefit", part, bad_values[v],
                                         (unsigned)fault_calls[k], (int)status);
                            assert_stats_untouched(&st);
                        } else {
                            assert_int_equal(status, TCLOD_OK);
                        }
                        assert_mixed_snapshot(sel, before);
                    }
        /* Good values again: the selector carries on, to the same result. */
        assert_int_equal(tclod_select(sel, &frame, &st), TCLOD_OK);
        assert_int_equal(st.invalid_values, 0);
        assert_mixed_snapshot(sel, before);
        tclod_selector_destroy(sel);
        free(before);
    }
}

static void scenes_without_nodes_or_smooth_objects_select_within_the_budget(void **state) {
    /* Degenerate scenes: empty, smooth objects only, nodes only; greedy and
     * mixed selectors. Every select succeeds within the budget (checked as
     * everywhere else), and in strict mode a bad smooth value in a scene
     * without nodes fails the call with the previous result kept. Run under
     * -DTCLOD_SANITIZE=address,undefined this also checks that no buffer
     * that was never allocated is handed to memcpy. */
    static const float places[2][4] = {{0.0f, 0.0f, -5.0f, 1.0f}, {3.0f, 0.0f, -6.0f, 1.0f}};
    int kind, solver;
    (void)state;
    for (kind = 0; kind < 3; ++kind)
        for (solver = 0; solver < 2; ++solver) {
            tclod_scene *s = NULL;
            tclod_selector *sel = NULL;
            tclod_selector_desc d;
            table_model m;
            tclod_stats st;
            int i;
            table_init(&m);
            assert_int_equal(tclod_scene_create(NULL, &s), TCLOD_OK);
            if (kind == 1) /* smooth objects only: sqrt benefits 2 and 1, cost r */
                for (i = 0; i < 2; ++i)
                    assert_int_equal(table_add_smooth(&m, s, places[i], TABLE_POWER, 2.0 - i, 0.5,
                                                      1.0, 1.0, 0.0, NULL),
                                     TCLOD_OK);
            if (kind == 2) { /* nodes only: root (1, 1) -> child (2, 2) */
                assert_int_equal(table_add_node(&m, s, TCLOD_NONE, NULL, 1.0, 1.0, NULL), TCLOD_OK);
                assert_int_equal(table_add_node(&m, s, 0, NULL, 2.0, 2.0, NULL), TCLOD_OK);
            }
            mixed_desc(&d, &m, 1, 0);
            if (solver == 0)
                d.solver = TCLOD_SOLVER_GREEDY;
            d.strict = 1;
            assert_int_equal(tclod_selector_create(s, &d, NULL, &sel), TCLOD_OK);
            select_ok(sel, 1.5, &st);
            check_mixed_result(sel, s, &m, &st, 1.5, 1, (unsigned long long)(kind * 10 + solver));
            if (kind == 1 && solver == 1) {
                mixed_snapshot *before = (mixed_snapshot *)malloc(sizeof *before);
                tclod_frame frame = helper_frame(NULL, 1.5);
                assert_non_null(before);
                assert_true(tclod_selector_resolution(sel, 0) > 0.0);
                take_mixed_snapshot(sel, s, before);
                m.smooth.bad_after = 1;
                m.smooth.bad_value = NAN;
                assert_int_equal(tclod_select(sel, &frame, &st), TCLOD_ERR_CALLBACK);
                m.smooth.bad_after = 0;
                assert_mixed_snapshot(sel, before);
                free(before);
            }
            select_ok(sel, 0.0, &st);
            check_mixed_result(sel, s, &m, &st, 0.0, 1, (unsigned long long)(kind * 10 + solver));
            tclod_selector_destroy(sel);
            tclod_scene_destroy(s);
            table_free(&m);
        }
}

static void mixed_selectors_reject_bad_descriptions_and_arguments(void **state) {
    helper_fixture *f = (helper_fixture *)*state;
    static const double bad_fractions[] = {-1e-300, -0.1, -2.0, 1.0, 1.5, NAN, INFINITY, -INFINITY};
    /* -1 is TCLOD_OFF, 0 the default */
    static const double bad_areas[] = {-1e-300, -2.0, -0.5, NAN, INFINITY, -INFINITY};
    tclod_selector *const sentinel = (tclod_selector *)(void *)f;
    tclod_selector *out = sentinel, *sel = NULL;
    tclod_selector_desc good, d;
    const tclod_smooth_group *groups = NULL;
    const tclod_id *order = NULL;
    const float place[4] = {1.0f, 0.0f, -5.0f, 1.0f};
    uint32_t count = 0;
    size_t i, n = 99;
    int solver;
    helper_add(f, TCLOD_NONE, 1.0, 1.0);
    assert_int_equal(
        table_add_smooth(&f->model, f->scene, place, TABLE_POWER, 1.0, 0.5, 1.0, 1.0, 0.0, NULL),
        TCLOD_OK);
    mixed_desc(&good, &f->model, 1, 0);
    /* The mixed solver needs both smooth callbacks. */
    d = good;
    d.callbacks.smooth_benefit = NULL;
    assert_int_equal(tclod_selector_create(f->scene, &d, NULL, &out), TCLOD_ERR_ARG);
    d = good;
    d.callbacks.smooth_cost = NULL;
    assert_int_equal(tclod_selector_create(f->scene, &d, NULL, &out), TCLOD_ERR_ARG);
    d.callbacks.smooth_benefit = NULL;
    assert_int_equal(tclod_selector_create(f->scene, &d, NULL, &out), TCLOD_ERR_ARG);
    /* Option ranges are checked whatever the solver (the header lists them
     * without condition). */
    for (solver = 0; solver < 2; ++solver) {
        good.solver = solver ? TCLOD_SOLVER_MIXED : TCLOD_SOLVER_GREEDY;
        for (i = 0; i < sizeof bad_fractions / sizeof bad_fractions[0]; ++i) {
            d = good;
            d.mixed.smooth_epsilon = bad_fractions[i];
            if (tclod_selector_create(f->scene, &d, NULL, &out) != TCLOD_ERR_ARG)
                fail_msg("solver %d: smooth_epsilon %g accepted", solver, bad_fractions[i]);
            d = good;
            d.mixed.smooth_tolerance = bad_fractions[i];
            if (tclod_selector_create(f->scene, &d, NULL, &out) != TCLOD_ERR_ARG)
                fail_msg("solver %d: smooth_tolerance %g accepted", solver, bad_fractions[i]);
        }
        for (i = 0; i < sizeof bad_areas / sizeof bad_areas[0]; ++i) {
            d = good;
            d.smooth_cull_area = bad_areas[i];
            if (tclod_selector_create(f->scene, &d, NULL, &out) != TCLOD_ERR_ARG)
                fail_msg("solver %d: smooth_cull_area %g accepted", solver, bad_areas[i]);
        }
        assert_ptr_equal(out, sentinel);
        /* The ends of the ranges are accepted. */
        d = good;
        d.mixed.smooth_epsilon = TCLOD_OFF;
        d.mixed.smooth_tolerance = nextafter(1.0, 0.0);
        d.smooth_cull_area = TCLOD_OFF;
        assert_int_equal(tclod_selector_create(f->scene, &d, NULL, &out), TCLOD_OK);
        tclod_selector_destroy(out);
        out = sentinel;
        d = good;
        d.mixed.smooth_epsilon = nextafter(1.0, 0.0);
        d.mixed.smooth_tolerance = TCLOD_OFF;
        d.smooth_cull_area = DBL_MAX;
        assert_int_equal(tclod_selector_create(f->scene, &d, NULL, &out), TCLOD_OK);
        tclod_selector_destroy(out);
        out = sentinel;
    }
    good.solver = TCLOD_SOLVER_MIXED;
    assert_int_equal(tclod_selector_create(f->scene, &good, NULL, &sel), TCLOD_OK);
    /* Before the first selection: no groups, every resolution 0. */
    assert_int_equal(tclod_selector_smooth_groups(sel, &groups, &n), TCLOD_OK);
    assert_int_equal(n, 0);
    assert_true(tclod_selector_resolution(sel, 0) == 0.0);
    select_ok(sel, 10.0, NULL);
    assert_true(tclod_selector_resolution(sel, 0) > 0.0); /* fits: cost 1 at r = 1 */
    n = 99;
    groups = NULL;
    assert_int_equal(tclod_selector_smooth_groups(NULL, &groups, &n), TCLOD_ERR_ARG);
    assert_int_equal(tclod_selector_smooth_groups(sel, NULL, &n), TCLOD_ERR_ARG);
    assert_int_equal(tclod_selector_smooth_groups(sel, &groups, NULL), TCLOD_ERR_ARG);
    assert_null(groups);
    assert_int_equal(n, 99);
    count = 77;
    assert_int_equal(tclod_scene_smooth_order(NULL, &order, &count), TCLOD_ERR_ARG);
    assert_int_equal(tclod_scene_smooth_order(f->scene, NULL, &count), TCLOD_ERR_ARG);
    assert_int_equal(tclod_scene_smooth_order(f->scene, &order, NULL), TCLOD_ERR_ARG);
    assert_null(order);
    assert_int_equal(count, 77);
    /* Unknown ids and no selector: 0. */
    assert_true(tclod_selector_resolution(NULL, 0) == 0.0);
    assert_true(tclod_selector_resolution(sel, 1) == 0.0);
    assert_true(tclod_selector_resolution(sel, 12345) == 0.0);
    assert_true(tclod_selector_resolution(sel, TCLOD_NONE) == 0.0);
    tclod_selector_destroy(sel);
    /* The greedy solver ignores smooth objects: no groups, resolution 0. */
    d = good;
    d.solver = TCLOD_SOLVER_GREEDY;
    assert_int_equal(tclod_selector_create(f->scene, &d, NULL, &sel), TCLOD_OK);
    select_ok(sel, 10.0, NULL);
    assert_int_equal(tclod_selector_smooth_groups(sel, &groups, &n), TCLOD_OK);
    assert_int_equal(n, 0);
    assert_true(tclod_selector_resolution(sel, 0) == 0.0);
    tclod_selector_destroy(sel);
}

/* A view-dependent smooth benefit: larger on screen. */
static double view_smooth_benefit(void *user, const tclod_query *q, double r, double *d_dr) {
    double scale = q->screen_area > 0.0f ? 1.0 + sqrt((double)q->screen_area) / 1000.0 : 1.0;
    double b = table_smooth_benefit(user, q, r, d_dr);
    *d_dr *= scale;
    return b * scale;
}

/* A mixed selector with view-dependent benefits (view_benefit and
 * view_smooth_benefit) over m. */
static tclod_selector *mixed_view_selector(const tclod_scene *s, table_model *m, int precondition,
                                           int split, const tclod_allocator *a) {
    tclod_selector_desc d;
    tclod_selector *sel = NULL;
    mixed_desc(&d, m, precondition, split);
    d.callbacks.benefit = view_benefit;
    d.callbacks.smooth_benefit = view_smooth_benefit;
    assert_int_equal(tclod_selector_create(s, &d, a, &sel), TCLOD_OK);
    return sel;
}

/* 100 chains of 4 levels and `smooth` random smooth objects, all on
 * [-50, 50]². */
static void mixed_scene(table_model *m, tclod_scene *s, uint64_t seed, uint32_t smooth) {
    table_rng rng;
    float place[4] = {0.0f, 0.0f, 0.0f, 1.0f};
    uint32_t i;
    table_rng_seed(&rng, seed);
    assert_int_equal(table_chains(m, s, &rng, 100, 4, 50.0f), TCLOD_OK);
    for (i = 0; i < smooth; ++i)
        random_smooth(m, s, &rng, 50.0f, place);
}

static void two_mixed_selectors_give_bit_identical_results(void **state) {
    /* Pairs of mixed selectors, in both precondition modes, with splitting
     * off and on, over the same scene and the same 30 frames (moving view,
     * varied budgets, some without a view, some with iteration limits): cut,
     * groups, every resolution and the stats are bit-identical. */
    helper_fixture *f = (helper_fixture *)*state;
    tclod_selector *sel[8];
    double full;
    uint32_t drawn = 0;
    int i, p;
    mixed_scene(&f->model, f->scene, 47, 400);
    full = full_cost(&f->model);
    for (p = 0; p < 8; ++p)
        sel[p] = mixed_view_selector(f->scene, &f->model, (p >> 1) & 1, p >> 2, NULL);
    for (i = 0; i < 30; ++i) {
        tclod_view v;
        tclod_frame frame;
        frame_view(&v, i);
        frame = sequence_frame(i, &v, 0.1 * full);
        for (p = 0; p < 8; p += 2) {
            tclod_stats a, b;
            const tclod_id *ids_a, *ids_b;
            const tclod_smooth_group *g_a, *g_b;
            size_t n_a, n_b;
            uint32_t k;
            assert_int_equal(tclod_select(sel[p], &frame, &a), TCLOD_OK);
            assert_int_equal(tclod_select(sel[p + 1], &frame, &b), TCLOD_OK);
            assert_int_equal(tclod_selector_cut(sel[p], &ids_a, &n_a), TCLOD_OK);
            assert_int_equal(tclod_selector_cut(sel[p + 1], &ids_b, &n_b), TCLOD_OK);
            assert_int_equal(n_a, n_b);
            if (n_a > 0)
                assert_memory_equal(ids_a, ids_b, n_a * sizeof *ids_a);
            assert_int_equal(tclod_selector_smooth_groups(sel[p], &g_a, &n_a), TCLOD_OK);
            assert_int_equal(tclod_selector_smooth_groups(sel[p + 1], &g_b, &n_b), TCLOD_OK);
            assert_int_equal(n_a, n_b);
            if (!groups_identical(g_a, g_b, n_a))
                fail_msg("frame %d, pair %d: groups differ", i, p / 2);
            drawn += n_a > 0;
            for (k = 0; k < f->model.smooth.count; ++k) {
                double r_a = tclod_selector_resolution(sel[p], k);
                double r_b = tclod_selector_resolution(sel[p + 1], k);
                assert_memory_equal(&r_a, &r_b, sizeof r_a);
            }
            assert_memory_equal(&a.benefit, &b.benefit, sizeof a.benefit);
            assert_memory_equal(&a.cost, &b.cost, sizeof a.cost);
            assert_int_equal(a.iterations, b.iterations);
            assert_int_equal(a.increments, b.increments);
            assert_int_equal(a.line_searches, b.line_searches);
            assert_int_equal(a.variables, b.variables);
            assert_int_equal(a.evaluations, b.evaluations);
            assert_int_equal(a.stop_reason, b.stop_reason);
            assert_true(a.cost <= frame.budget);
        }
    }
    assert_true(drawn > 60); /* most frames draw groups in every pair */
    for (p = 0; p < 8; ++p)
        tclod_selector_destroy(sel[p]);
}

static void mixed_selects_after_the_first_allocate_nothing(void **state) {
    /* Scene and four mixed selectors (both precondition modes, splitting off
     * and on) on one counting allocator; after each selector's first select,
     * 40 more with a moving view, varied budgets and limits, sometimes
     * without a view (every object a variable), allocate nothing. */
    test_alloc counter;
    tclod_allocator hooks;
    tclod_scene *s = NULL;
    tclod_selector *sel[4];
    table_model m;
    double full;
    size_t after_first;
    int i, p;
    (void)state;
    test_alloc_init(&counter);
    hooks = test_alloc_hooks(&counter);
    table_init(&m);
    assert_int_equal(tclod_scene_create(&hooks, &s), TCLOD_OK);
    mixed_scene(&m, s, 53, 300);
    full = full_cost(&m);
    for (p = 0; p < 4; ++p) {
        tclod_view v;
        tclod_frame frame;
        sel[p] = mixed_view_selector(s, &m, p & 1, p >> 1, &hooks);
        frame_view(&v, 0);
        frame = helper_frame(&v, 0.1 * full);
        assert_int_equal(tclod_select(sel[p], &frame, NULL), TCLOD_OK);
    }
    after_first = counter.allocations;
    for (i = 1; i <= 40; ++i) {
        tclod_view v;
        tclod_frame frame;
        tclod_stats st;
        frame_view(&v, i);
        frame = sequence_frame(i, &v, 0.1 * full);
        if (i % 6 == 3)
            frame.solve_seconds = 1e-6;
        assert_int_equal(tclod_select(sel[i % 4], &frame, &st), TCLOD_OK);
        assert_true(st.cost <= frame.budget);
        if (counter.allocations != after_first)
            fail_msg("select %d allocated %u times", i,
                     (unsigned)(counter.allocations - after_first));
    }
    for (p = 0; p < 4; ++p)
        tclod_selector_destroy(sel[p]);
    tclod_scene_destroy(s);
    assert_int_equal(counter.outstanding_bytes, 0);
    assert_int_equal(counter.outstanding_blocks, 0);
    assert_int_equal(counter.bad_frees, 0);
    table_free(&m);
}

/* Asserts that order[0 .. n) is a permutation of 0 .. n - 1. */
static void assert_permutation(const tclod_id *order, uint32_t n) {
    unsigned char *seen = (unsigned char *)calloc(n ? n : 1u, 1);
    uint32_t i;
    assert_non_null(seen);
    for (i = 0; i < n; ++i) {
        if (order[i] >= n || seen[order[i]])
            fail_msg("smooth order[%u] = %u repeats or is out of range", (unsigned)i,
                     (unsigned)order[i]);
        seen[order[i]] = 1;
    }
    free(seen);
}

/* ---- re-entry from smooth callbacks -------------------------------------- */

typedef struct smooth_reentry {
    table_model *model;
    tclod_selector *sel;
    const tclod_frame *frame;
    int from_cost; /* re-enter from smooth_cost (1) or smooth_benefit (0) */
    int calls;     /* re-entry is tried on call 0 only */
    tclod_status select_status, cut_status, groups_status;
    double resolution; /* of smooth object 0, asked during the solve */
} smooth_reentry;

static void try_reentry(smooth_reentry *r) {
    if (r->calls++ == 0) {
        const tclod_id *ids = NULL;
        const tclod_smooth_group *groups = NULL;
        size_t n = 0;
        tclod_stats st;
        r->select_status = tclod_select(r->sel, r->frame, &st);
        r->cut_status = tclod_selector_cut(r->sel, &ids, &n);
        r->groups_status = tclod_selector_smooth_groups(r->sel, &groups, &n);
        r->resolution = tclod_selector_resolution(r->sel, 0);
        tclod_selector_destroy(r->sel); /* ignored while solving */
    }
}

static double reentrant_smooth_benefit(void *user, const tclod_query *q, double r, double *d_dr) {
    smooth_reentry *e = (smooth_reentry *)user;
    if (!e->from_cost)
        try_reentry(e);
    return table_smooth_benefit(e->model, q, r, d_dr);
}

static double reentrant_smooth_cost(void *user, const tclod_query *q, double r, double *d_dr) {
    smooth_reentry *e = (smooth_reentry *)user;
    if (e->from_cost)
        try_reentry(e);
    return table_smooth_cost(e->model, q, r, d_dr);
}

static double reentry_benefit(void *user, const tclod_query *q) {
    return table_benefit(((smooth_reentry *)user)->model, q);
}

static double reentry_cost(void *user, const tclod_query *q) {
    return table_cost(((smooth_reentry *)user)->model, q);
}

static void smooth_callbacks_cannot_reenter_their_selector(void **state) {
    /* Root 0 (1, 1) -> 1 (2, 1.5); three smooth objects, sqrt benefits of
     * weight 4, 2, 1 and linear costs 1: budget 4 draws some of them (object
     * 0, the best, for sure). A first select without re-entry gives object 0
     * a resolution > 0; in the next, the first smooth call (benefit, then
     * cost) tries select, cut, groups, resolution and destroy: refused with
     * TCLOD_ERR_STATE, resolution 0 during the solve, destroy ignored; the
     * outer select succeeds with a valid result. */
    helper_fixture *f = (helper_fixture *)*state;
    static const float places[3][4] = {
        {0.0f, 0.0f, -5.0f, 1.0f}, {10.0f, 0.0f, -5.0f, 1.0f}, {-10.0f, 0.0f, 8.0f, 1.0f}};
    static const double weights[3] = {4.0, 2.0, 1.0};
    tclod_frame frame = helper_frame(NULL, 4.0);
    tclod_selector_desc d;
    tclod_stats st;
    smooth_reentry r;
    int i, from_cost;
    helper_add(f, TCLOD_NONE, 1.0, 1.0);
    helper_add(f, 0, 2.0, 1.5);
    for (i = 0; i < 3; ++i)
        assert_int_equal(table_add_smooth(&f->model, f->scene, places[i], TABLE_POWER, weights[i],
                                          0.5, 1.0, 1.0, 0.0, NULL),
                         TCLOD_OK);
    for (from_cost = 0; from_cost < 2; ++from_cost) {
        memset(&r, 0, sizeof r);
        r.model = &f->model;
        r.frame = &frame;
        r.from_cost = from_cost;
        r.calls = 1; /* no re-entry in the first select */
        mixed_desc(&d, &f->model, 1, 0);
        d.callbacks.benefit = reentry_benefit;
        d.callbacks.cost = reentry_cost;
        d.callbacks.smooth_benefit = reentrant_smooth_benefit;
        d.callbacks.smooth_cost = reentrant_smooth_cost;
        d.callbacks.user = &r;
        assert_int_equal(tclod_selector_create(f->scene, &d, NULL, &r.sel), TCLOD_OK);
        assert_int_equal(tclod_select(r.sel, &frame, &st), TCLOD_OK);
        check_mixed_result(r.sel, f->scene, &f->model, &st, 4.0, 1, (unsigned long long)from_cost);
        assert_true(tclod_selector_resolution(r.sel, 0) > 0.0);
        r.calls = 0;
        r.select_status = r.cut_status = r.groups_status = TCLOD_OK;
        r.resolution = -1.0;
        assert_int_equal(tclod_select(r.sel, &frame, &st), TCLOD_OK);
        assert_true(r.calls > 0);
        assert_int_equal(r.select_status, TCLOD_ERR_STATE);
        assert_int_equal(r.cut_status, TCLOD_ERR_STATE);
        assert_int_equal(r.groups_status, TCLOD_ERR_STATE);
        assert_true(r.resolution == 0.0);
        check_mixed_result(r.sel, f->scene, &f->model, &st, 4.0, 1, (unsigned long long)from_cost);
        assert_true(tclod_selector_resolution(r.sel, 0) > 0.0);
        tclod_selector_destroy(r.sel);
    }
}

/* ---- the smooth order ----------------------------------------------------- */

/* Callbacks that check every query against the scene's smooth order (the
 * inverse permutation `pos`), counting what does not match instead of failing
 * inside the library. */
typedef struct query_log {
    table_model *model;
    const tclod_id *order;
    const uint32_t *pos;
    uint32_t count;
    uint32_t smooth_queries, largest_group;
    uint32_t bad_members;             /* members NULL, count 0, members[0] != id, or not a range */
    uint32_t node_queries, bad_nodes; /* node queries with members or count != 1 */
} query_log;

static void log_smooth_query(query_log *l, const tclod_query *q) {
    uint32_t p;
    if (l->order == NULL)
        return;
    l->smooth_queries++;
    if (q->count > l->largest_group)
        l->largest_group = q->count;
    if (q->members == NULL || q->count == 0 || q->id >= l->count || q->members[0] != q->id) {
        l->bad_members++;
        return;
    }
    p = l->pos[q->id];
    if (q->count > l->count - p ||
        memcmp(q->members, l->order + p, q->count * sizeof *q->members) != 0)
        l->bad_members++;
}

static void log_node_query(query_log *l, const tclod_query *q) {
    l->node_queries++;
    l->bad_nodes += q->members != NULL || q->count != 1;
}

static double log_benefit(void *user, const tclod_query *q) {
    query_log *l = (query_log *)user;
    log_node_query(l, q);
    return table_benefit(l->model, q);
}

static double log_cost(void *user, const tclod_query *q) {
    query_log *l = (query_log *)user;
    log_node_query(l, q);
    return table_cost(l->model, q);
}

static double log_smooth_benefit(void *user, const tclod_query *q, double r, double *d_dr) {
    query_log *l = (query_log *)user;
    log_smooth_query(l, q);
    if (l->bad_members > 0) { /* do not read members that may be wrong */
        *d_dr = 0.0;
        return 0.0;
    }
    return table_smooth_benefit(l->model, q, r, d_dr);
}

static double log_smooth_cost(void *user, const tclod_query *q, double r, double *d_dr) {
    query_log *l = (query_log *)user;
    log_smooth_query(l, q);
    if (l->bad_members > 0) {
        *d_dr = 0.0;
        return 0.0;
    }
    return table_smooth_cost(l->model, q, r, d_dr);
}

static void smooth_queries_name_contiguous_ranges_of_the_smooth_order(void **state) {
    /* 300 smooth objects (a quarter sharing a place with the one before) and
     * 400 chain nodes. tclod_scene_smooth_order is a permutation of 0 .. 299;
     * every smooth query of every solve (both precondition modes, splitting
     * off and on, with and without a view) has members[0] == id and members
     * equal to order[pos(id) .. pos(id) + count). Splitting must ask about
     * groups of several; the selectors do not change the order. */
    helper_fixture *f = (helper_fixture *)*state;
    const tclod_id *order = NULL, *again = NULL;
    tclod_id *copy;
    uint32_t *pos;
    uint32_t count = 0, i;
    query_log log;
    double full;
    int mode, frame;
    mixed_scene(&f->model, f->scene, 71, 300);
    full = full_cost(&f->model);
    assert_int_equal(tclod_scene_smooth_order(f->scene, &order, &count), TCLOD_OK);
    assert_int_equal(count, 300);
    assert_permutation(order, count);
    copy = (tclod_id *)malloc(count * sizeof *copy);
    pos = (uint32_t *)malloc(count * sizeof *pos);
    assert_non_null(copy);
    assert_non_null(pos);
    memcpy(copy, order, count * sizeof *copy);
    for (i = 0; i < count; ++i)
        pos[order[i]] = i;
    memset(&log, 0, sizeof log);
    log.model = &f->model;
    log.order = order;
    log.pos = pos;
    log.count = count;
    for (mode = 0; mode < 4; ++mode) {
        tclod_selector_desc d;
        tclod_selector *sel = NULL;
        mixed_desc(&d, &f->model, mode & 1, mode >> 1);
        d.callbacks.benefit = log_benefit;
        d.callbacks.cost = log_cost;
        d.callbacks.smooth_benefit = log_smooth_benefit;
        d.callbacks.smooth_cost = log_smooth_cost;
        d.callbacks.user = &log;
        assert_int_equal(tclod_selector_create(f->scene, &d, NULL, &sel), TCLOD_OK);
        log.largest_group = 0;
        for (frame = 0; frame < 6; ++frame) {
            tclod_view v;
            tclod_frame fr;
            tclod_stats st;
            frame_view(&v, frame);
            fr = helper_frame(frame % 2 ? &v : NULL, (0.05 + 0.1 * frame) * full);
            assert_int_equal(tclod_select(sel, &fr, &st), TCLOD_OK);
            if (log.bad_members > 0)
                fail_msg("mode %d frame %d: %u smooth queries off the order", mode, frame,
                         (unsigned)log.bad_members);
            check_mixed_result(sel, f->scene, &f->model, &st, fr.budget, 1,
                               (unsigned long long)(mode * 10 + frame));
        }
        if (mode >> 1)
            assert_true(log.largest_group > 1);
        else
            assert_int_equal(log.largest_group, 1);
        tclod_selector_destroy(sel);
    }
    assert_true(log.smooth_queries > 0);
    assert_int_equal(tclod_scene_smooth_order(f->scene, &again, &count), TCLOD_OK);
    assert_int_equal(count, 300);
    assert_memory_equal(again, copy, count * sizeof *copy);
    free(pos);
    free(copy);
}

/* Fills a stretch of stack with a byte pattern, so that whatever a later call
 * leaves uninitialised on the stack is not 0 by chance. */
static void paint_stack(void) {
    volatile unsigned char area[16384];
    size_t i;
    for (i = 0; i < sizeof area; ++i)
        area[i] = 0xa5;
}

static void node_queries_have_no_members_and_count_one(void **state) {
    /* tclod_query.members is "NULL for nodes" and count "1 for nodes": every
     * node query of the greedy and the mixed solver (with and without a view,
     * smooth objects in the scene) says so, whatever was on the stack. */
    helper_fixture *f = (helper_fixture *)*state;
    query_log log;
    double full;
    int mode, frame;
    mixed_scene(&f->model, f->scene, 73, 50);
    full = full_cost(&f->model);
    memset(&log, 0, sizeof log);
    log.model = &f->model;
    for (mode = 0; mode < 3; ++mode) {
        tclod_selector_desc d;
        tclod_selector *sel = NULL;
        mixed_desc(&d, &f->model, mode & 1, 0);
        if (mode == 2)
            d.solver = TCLOD_SOLVER_GREEDY;
        d.callbacks.benefit = log_benefit;
        d.callbacks.cost = log_cost;
        d.callbacks.smooth_benefit = log_smooth_benefit;
        d.callbacks.smooth_cost = log_smooth_cost;
        d.callbacks.user = &log; /* log.order NULL: smooth queries not checked */
        assert_int_equal(tclod_selector_create(f->scene, &d, NULL, &sel), TCLOD_OK);
        for (frame = 0; frame < 4; ++frame) {
            tclod_view v;
            tclod_frame fr;
            frame_view(&v, frame);
            fr = helper_frame(frame % 2 ? &v : NULL, 0.2 * full);
            paint_stack();
            assert_int_equal(tclod_select(sel, &fr, NULL), TCLOD_OK);
        }
        tclod_selector_destroy(sel);
    }
    assert_true(log.node_queries > 0);
    if (log.bad_nodes > 0)
        fail_msg("%u of %u node queries have members != NULL or count != 1",
                 (unsigned)log.bad_nodes, (unsigned)log.node_queries);
}

int main(void) {
    const struct CMUnitTest tests[] = {
        FIXTURE_TEST(budget_holds_when_tiny_costs_are_absorbed),
        FIXTURE_TEST(budget_holds_when_tiny_costs_are_absorbed_inside_an_increment),
        FIXTURE_TEST(absorbing_roots_leave_no_room),
        FIXTURE_TEST(absorbed_costs_are_not_spent_twice),
        cmocka_unit_test(budget_holds_on_random_scenes_with_mixed_magnitudes),
        FIXTURE_TEST(roots_are_dropped_one_at_a_time_when_their_costs_overflow),
        FIXTURE_TEST(bad_benefit_makes_the_node_invisible_and_is_counted),
        FIXTURE_TEST(edge_values_are_told_apart_from_bad_ones),
        FIXTURE_TEST(bad_cost_on_a_root_makes_it_unaffordable_and_is_counted),
        FIXTURE_TEST(bad_cost_on_a_child_keeps_its_parent_and_is_counted),
        FIXTURE_TEST(strict_mode_fails_the_call_and_keeps_the_previous_result),
        FIXTURE_TEST(select_rejects_bad_arguments_and_keeps_the_previous_result),
        FIXTURE_TEST(selector_create_rejects_bad_descriptions),
        FIXTURE_TEST(only_the_three_solvers_can_be_created),
        FIXTURE_TEST(allocators_need_both_hooks_or_none),
        FIXTURE_TEST(cut_rejects_null_arguments_and_is_empty_before_the_first_select),
        cmocka_unit_test(desc_default_fills_the_documented_values),
        FIXTURE_TEST(two_selectors_give_bit_identical_results),
        FIXTURE_TEST(equal_increments_are_taken_in_id_order),
        cmocka_unit_test(selects_after_the_first_allocate_nothing),
        FIXTURE_TEST(callbacks_cannot_reenter_their_selector),
        FIXTURE_TEST(an_edit_from_a_greedy_callback_is_refused_and_the_solve_goes_on),
        FIXTURE_TEST(an_edit_from_a_robin_hood_callback_is_refused_and_the_solve_goes_on),
        cmocka_unit_test(mixed_budget_holds_on_ten_thousand_random_mixed_instances),
        FIXTURE_TEST(bad_smooth_values_are_counted_and_the_budget_still_holds),
        FIXTURE_TEST(strict_mode_turns_bad_smooth_values_into_errors_and_keeps_the_result),
        cmocka_unit_test(scenes_without_nodes_or_smooth_objects_select_within_the_budget),
        FIXTURE_TEST(mixed_selectors_reject_bad_descriptions_and_arguments),
        FIXTURE_TEST(two_mixed_selectors_give_bit_identical_results),
        cmocka_unit_test(mixed_selects_after_the_first_allocate_nothing),
        FIXTURE_TEST(smooth_callbacks_cannot_reenter_their_selector),
        FIXTURE_TEST(smooth_queries_name_contiguous_ranges_of_the_smooth_order),
        FIXTURE_TEST(node_queries_have_no_members_and_count_one),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
