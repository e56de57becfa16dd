/*
 * test_kinds — additive refinement, empty nodes and the overflow policy
 * (docs/scenes.md): hand-worked selections, and every solver against the
 * brute-force optimum (tests/support/exact.c) on random hierarchies that mix
 * replace, additive and empty nodes.
 *
 * An additive node refined stays drawn: its increment adds its children's
 * benefit and cost. An empty node draws nothing, is never asked about, and
 * its children are selected as if they hung from its parent (or were roots).
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

#include "exact.h"
#include "helpers.h"
#include "table_scene.h"

#define FIXTURE_TEST(f) \
    cmocka_unit_test_setup_teardown(f, helper_fixture_setup, helper_fixture_teardown)

static const tclod_solver solvers[3] = {TCLOD_SOLVER_GREEDY, TCLOD_SOLVER_MIXED,
                                        TCLOD_SOLVER_ROBIN_HOOD};

/* Adds a node of kind `kind` (TABLE_REPLACE, TABLE_ADD or TABLE_EMPTY). */
static tclod_id add_kind(helper_fixture *f, tclod_id parent, table_kind kind, double benefit,
                         double cost) {
    tclod_node_desc d;
    tclod_id id = TCLOD_NONE;
    tclod_node_desc_default(&d);
    d.parent = parent;
    d.refine = kind == TABLE_ADD ? TCLOD_REFINE_ADD : TCLOD_REFINE_REPLACE;
    d.empty = kind == TABLE_EMPTY;
    assert_int_equal(table_add_node_desc(&f->model, f->scene, &d, benefit, cost, &id), TCLOD_OK);
    return id;
}

static tclod_selector *solver_selector(const tclod_scene *s, table_model *m, tclod_solver solver,
                                       tclod_overflow overflow) {
    tclod_selector_desc d;
    tclod_selector *sel = NULL;
    tclod_selector_desc_default(&d);
    d.solver = solver;
    d.overflow = overflow;
    table_callbacks(m, &d.callbacks);
    assert_int_equal(tclod_selector_create(s, &d, NULL, &sel), TCLOD_OK);
    return sel;
}

/* Selects at `budget` without a view and checks what every selection
 * promises: a valid selection (additive nodes with their descendants), its
 * costs in result order within the budget, the stats its sums. */
static tclod_stats select_checked(tclod_selector *sel, const table_model *m, double budget,
                                  int roots_may_drop) {
    tclod_frame f = helper_frame(NULL, budget);
    const tclod_id *ids = NULL;
    tclod_stats st;
    size_t n = 0;
    assert_int_equal(tclod_select(sel, &f, &st), TCLOD_OK);
    assert_int_equal(tclod_selector_cut(sel, &ids, &n), TCLOD_OK);
    assert_true(exact_check_selection(m, ids, n, roots_may_drop));
    if (!st.over_budget && !(table_sum_cost(m, ids, n) <= budget))
        fail_msg("cost %.17g over budget %.17g", table_sum_cost(m, ids, n), budget);
    assert_true(st.cost == table_sum_cost(m, ids, n));
    assert_true(st.benefit == table_sum_benefit(m, ids, n));
    return st;
}

/* ---- additive refinement ---------------------------------------------------- */

/* P (b 10, c 2) additive with children A and B (6, 1 each). Its increment
 * adds A and B, +12 for +2, and P stays: budget 2 draws {P} (10), budget 3.5
 * still {P} (the increment needs 4 in all), budget 4 draws {P, A, B} (22 for
 * 4). Were P a replace node, A and B (12 for 2) would replace it at budget 2
 * already (+2 for +0). The budgets have 0.01 to spare: the Robin Hood solver
 * keeps 1e-9 of the budget back (docs/robin_hood.md). */
static void an_additive_node_stays_drawn_under_its_children(void **state) {
    helper_fixture *f = (helper_fixture *)*state;
    static const tclod_id p_only[] = {0}, all[] = {0, 2, 3};
    tclod_id p = add_kind(f, TCLOD_NONE, TABLE_ADD, 10.0, 2.0);
    int k;
    add_kind(f, p, TABLE_REPLACE, 6.0, 1.0);
    add_kind(f, p, TABLE_REPLACE, 6.0, 1.0);
    /* P took ids 0 and 1 (the second its own among its children) */
    assert_int_equal(tclod_scene_node_count(f->scene), 4);
    assert_false(tclod_scene_node_live(f->scene, 1));
    for (k = 0; k < 3; ++k) {
        tclod_selector *sel = solver_selector(f->scene, &f->model, solvers[k], 0);
        tclod_stats st = select_checked(sel, &f->model, 2.01, 0);
        helper_assert_cut(sel, p_only, 1);
        assert_true(st.benefit == 10.0 && st.cost == 2.0);
        st = select_checked(sel, &f->model, 3.5, 0);
        helper_assert_cut(sel, p_only, 1);
        st = select_checked(sel, &f->model, 4.01, 0);
        helper_assert_cut(sel, all, 3);
        assert_true(st.benefit == 22.0 && st.cost == 4.0);
        tclod_selector_destroy(sel);
    }
}

/* R (b 4, c 2), replace, with children P (5, 1), additive, and Q (5, 1); P
 * with children P1 and P2 (3, 1 each). R's increment: {P, Q} for +6 at +0.
 * P's: P1 and P2 added, +6 for +2, P staying. Budget 2: {P, Q} (10); budget
 * 3: the same (P's increment needs 4); budget 4: {P, Q, P1, P2} (16). */
static void one_hierarchy_mixes_replace_and_additive_nodes(void **state) {
    helper_fixture *f = (helper_fixture *)*state;
    tclod_id r = add_kind(f, TCLOD_NONE, TABLE_REPLACE, 4.0, 2.0);
    tclod_id p = add_kind(f, r, TABLE_ADD, 5.0, 1.0);
    tclod_id q = add_kind(f, r, TABLE_REPLACE, 5.0, 1.0);
    tclod_id p1 = add_kind(f, p, TABLE_REPLACE, 3.0, 1.0);
    tclod_id p2 = add_kind(f, p, TABLE_REPLACE, 3.0, 1.0);
    const tclod_id pq[] = {p, q}, all[] = {p, q, p1, p2};
    tclod_selector *sel = solver_selector(f->scene, &f->model, TCLOD_SOLVER_GREEDY, 0);
    tclod_stats st = select_checked(sel, &f->model, 2.0, 0);
    helper_assert_cut(sel, pq, 2);
    assert_true(st.benefit == 10.0 && st.cost == 2.0);
    st = select_checked(sel, &f->model, 3.0, 0);
    helper_assert_cut(sel, pq, 2);
    st = select_checked(sel, &f->model, 4.0, 0);
    helper_assert_cut(sel, all, 4);
    assert_true(st.benefit == 16.0 && st.cost == 4.0);
    /* warm, back down: a decrement takes P1 and P2 away, P stays */
    st = select_checked(sel, &f->model, 3.0, 0);
    helper_assert_cut(sel, pq, 2);
    assert_true(st.benefit == 10.0 && st.cost == 2.0);
    tclod_selector_destroy(sel);
}

/* ---- empty nodes --------------------------------------------------------------- */

/* E, empty, the only root, with children X (2, 1) and Y (3, 1); X with a child
 * X1 (5, 2). E draws nothing and is never asked about; X and Y are the roots
 * the solvers see. Budget 0.5: neither fits, both left out (stop reason
 * TCLOD_STOP_ROOTS_DROPPED). Budget 1: Y, the higher value (the greedy's
 * order; the Robin Hood solver shares and drops X, its last). Budget 2: {X,
 * Y}, 5. Budget 3: X1 replaces X (+3 for +1): {X1, Y}, 8. The Robin Hood
 * solver shares 3.01 as 1.806 for Y (least complex: its finest level costs
 * 1, X's 2), which leaves 2.01 for X: X1 fits. */
static void an_empty_root_passes_its_children_on_as_roots(void **state) {
    helper_fixture *f = (helper_fixture *)*state;
    tclod_id e = add_kind(f, TCLOD_NONE, TABLE_EMPTY, 0.0, 0.0);
    tclod_id x = add_kind(f, e, TABLE_REPLACE, 2.0, 1.0);
    tclod_id y = add_kind(f, e, TABLE_REPLACE, 3.0, 1.0);
    tclod_id x1 = add_kind(f, x, TABLE_REPLACE, 5.0, 2.0);
    const tclod_id only_y[] = {y}, xy[] = {x, y}, refined[] = {x1, y};
    int k;
    for (k = 0; k < 3; ++k) {
        tclod_selector *sel = solver_selector(f->scene, &f->model, solvers[k], 0);
        tclod_stats st = select_checked(sel, &f->model, 0.5, 1);
        helper_assert_cut(sel, NULL, 0);
        assert_int_equal(st.dropped_roots, 2);
        assert_int_equal(st.stop_reason, TCLOD_STOP_ROOTS_DROPPED);
        if (solvers[k] != TCLOD_SOLVER_ROBIN_HOOD) { /* shares: not value order */
            st = select_checked(sel, &f->model, 1.0, 1);
            helper_assert_cut(sel, only_y, 1);
            assert_int_equal(st.dropped_roots, 1);
        }
        st = select_checked(sel, &f->model, 2.01, 0);
        helper_assert_cut(sel, xy, 2);
        assert_true(st.benefit == 5.0 && st.cost == 2.0);
        st = select_checked(sel, &f->model, 3.01, 0);
        helper_assert_cut(sel, refined, 2);
        assert_true(st.benefit == 8.0 && st.cost == 3.0);
        assert_int_equal(f->model.benefit_calls[e] + f->model.cost_calls[e], 0);
        tclod_selector_destroy(sel);
    }
}

/* R (2, 1) with children E, empty, and S (2, 1); E with children E1 and E2
 * (2, 1 each). R's increment goes past E: {E1, E2, S}, +4 for +2. Budget 2.5:
 * {R}; budget 3 (and 0.01 to spare): {E1, E2, S}, 6. An empty leaf Z below S
 * changes nothing: S has no child that draws, so it does not refine. */
static void an_empty_node_inside_a_hierarchy_is_passed_over(void **state) {
    helper_fixture *f = (helper_fixture *)*state;
    tclod_id r = add_kind(f, TCLOD_NONE, TABLE_REPLACE, 2.0, 1.0);
    tclod_id e = add_kind(f, r, TABLE_EMPTY, 0.0, 0.0);
    tclod_id s = add_kind(f, r, TABLE_REPLACE, 2.0, 1.0);
    tclod_id e1 = add_kind(f, e, TABLE_REPLACE, 2.0, 1.0);
    tclod_id e2 = add_kind(f, e, TABLE_REPLACE, 2.0, 1.0);
    tclod_id z = add_kind(f, s, TABLE_EMPTY, 0.0, 0.0);
    const tclod_id root[] = {r}, below[] = {e1, e2, s};
    int k;
    for (k = 0; k < 3; ++k) {
        tclod_selector *sel = solver_selector(f->scene, &f->model, solvers[k], 0);
        tclod_stats st = select_checked(sel, &f->model, 2.5, 0);
        helper_assert_cut(sel, root, 1);
        st = select_checked(sel, &f->model, 3.01, 0);
        helper_assert_cut(sel, below, 3);
        assert_true(st.benefit == 6.0 && st.cost == 3.0);
        st = select_checked(sel, &f->model, INFINITY, 0);
        helper_assert_cut(sel, below, 3);
        assert_int_equal(f->model.benefit_calls[e] + f->model.benefit_calls[z], 0);
        tclod_selector_destroy(sel);
    }
}

/* ---- when even the roots do not fit ----------------------------------------------- */

/* Root R (b 4, c 3) with a child C (5, 4), budget 2: by default nothing is
 * drawn and the status is TCLOD_OK with stop reason ROOTS_DROPPED; with
 * TCLOD_OVERFLOW_DRAW_ROOTS, R is drawn over the budget, flagged. Budget 0
 * never reports TCLOD_STOP_FINEST. Below an empty root the coarsest level is
 * its children's. */
static void roots_over_the_budget_are_dropped_or_drawn_as_asked(void **state) {
    helper_fixture *f = (helper_fixture *)*state;
    tclod_id r = add_kind(f, TCLOD_NONE, TABLE_REPLACE, 4.0, 3.0);
    tclod_id e = add_kind(f, TCLOD_NONE, TABLE_EMPTY, 0.0, 0.0);
    tclod_id a = add_kind(f, e, TABLE_REPLACE, 1.0, 1.0);
    const tclod_id drawn[] = {r, a};
    int k;
    add_kind(f, r, TABLE_REPLACE, 5.0, 4.0);
    for (k = 0; k < 3; ++k) {
        tclod_selector *drop = solver_selector(f->scene, &f->model, solvers[k], 0);
        tclod_selector *draw =
            solver_selector(f->scene, &f->model, solvers[k], TCLOD_OVERFLOW_DRAW_ROOTS);
        tclod_stats st = select_checked(drop, &f->model, 0.5, 1);
        helper_assert_cut(drop, NULL, 0);
        assert_int_equal(st.stop_reason, TCLOD_STOP_ROOTS_DROPPED);
        assert_int_equal(st.dropped_roots, 2);
        assert_int_equal(st.over_budget, 0);
        st = select_checked(drop, &f->model, 0.0, 1);
        assert_int_equal(st.stop_reason, TCLOD_STOP_ROOTS_DROPPED);
        st = select_checked(draw, &f->model, 0.5, 1);
        helper_assert_cut(draw, drawn, 2);
        assert_int_equal(st.stop_reason, TCLOD_STOP_OVER_BUDGET);
        assert_int_equal(st.over_budget, 1);
        assert_int_equal(st.dropped_roots, 0);
        assert_true(st.cost == 4.0 && st.benefit == 5.0);
        /* within the budget the policy changes nothing */
        st = select_checked(draw, &f->model, 4.0, 0);
        assert_int_equal(st.over_budget, 0);
        assert_true(st.cost <= 4.0);
        tclod_selector_destroy(drop);
        tclod_selector_destroy(draw);
    }
}

/* Even drawing the roots over the budget, a root whose cost is not a number
 * (an unaffordable one) is left out and counted. */
static double nan_cost_of_root_zero(void *user, const tclod_query *q) {
    return q->id == 0 ? NAN : table_cost(user, q);
}

static void an_unaffordable_root_is_left_out_even_over_the_budget(void **state) {
    helper_fixture *f = (helper_fixture *)*state;
    const tclod_id drawn[] = {1};
    tclod_selector_desc d;
    tclod_selector *sel;
    tclod_frame fr = helper_frame(NULL, 0.5);
    tclod_stats st;
    add_kind(f, TCLOD_NONE, TABLE_REPLACE, 4.0, 3.0);
    add_kind(f, TCLOD_NONE, TABLE_REPLACE, 2.0, 1.0);
    tclod_selector_desc_default(&d);
    d.overflow = TCLOD_OVERFLOW_DRAW_ROOTS;
    table_callbacks(&f->model, &d.callbacks);
    d.callbacks.cost = nan_cost_of_root_zero;
    assert_int_equal(tclod_selector_create(f->scene, &d, NULL, &sel), TCLOD_OK);
    assert_int_equal(tclod_select(sel, &fr, &st), TCLOD_OK);
    helper_assert_cut(sel, drawn, 1);
    assert_int_equal(st.dropped_roots, 1);
    assert_int_equal(st.over_budget, 1);
    assert_int_equal(st.invalid_values, 1);
    tclod_selector_destroy(sel);
}

/* Drawn over the budget, the roots are all that is drawn: R (b 0.75, c 1)
 * with a child C (1, 1.5), budget 0. Refining R into C would gain, but the
 * policy draws the coarsest level and stops, so the result is {R}, cost
 * 1 > 0, flagged; and over_budget is 1 exactly when the cost exceeds the
 * budget. (A child that cost less than R would be drawn instead, within the
 * budget: test_greedy.c, roots_that_do_not_fit_give_way_to_cheaper_children.) */
static void drawn_over_the_budget_the_roots_are_all_that_is_drawn(void **state) {
    helper_fixture *f = (helper_fixture *)*state;
    tclod_id r = add_kind(f, TCLOD_NONE, TABLE_REPLACE, 0.75, 1.0);
    const tclod_id drawn[] = {r};
    int k;
    add_kind(f, r, TABLE_REPLACE, 1.0, 1.5);
    for (k = 0; k < 3; ++k) {
        tclod_selector *sel =
            solver_selector(f->scene, &f->model, solvers[k], TCLOD_OVERFLOW_DRAW_ROOTS);
        tclod_stats st = select_checked(sel, &f->model, 0.0, 0);
        helper_assert_cut(sel, drawn, 1);
        assert_int_equal(st.over_budget, 1);
        assert_int_equal(st.stop_reason, TCLOD_STOP_OVER_BUDGET);
        assert_true(st.cost == 1.0 && st.benefit == 0.75);
        /* a warm start over the same budget does no more */
        st = select_checked(sel, &f->model, 0.0, 0);
        helper_assert_cut(sel, drawn, 1);
        assert_int_equal(st.over_budget, 1);
        tclod_selector_destroy(sel);
    }
}

/* An additive root R (b 1, c 1) with a child C (2, 1), budget 10: {R, C}.
 * Then R's benefit falls to 0: R is culled with its whole subtree, so the
 * next select, warm or cold, draws nothing, cost 0. */
static void an_invisible_additive_node_takes_its_subtree_with_it(void **state) {
    helper_fixture *f = (helper_fixture *)*state;
    tclod_id r = add_kind(f, TCLOD_NONE, TABLE_ADD, 1.0, 1.0);
    tclod_id c = add_kind(f, r, TABLE_REPLACE, 2.0, 1.0);
    const tclod_id both[] = {r, c};
    int k;
    for (k = 0; k < 3; ++k) {
        tclod_selector *sel = solver_selector(f->scene, &f->model, solvers[k], 0);
        tclod_stats st;
        f->model.benefit[r] = 1.0;
        st = select_checked(sel, &f->model, 10.0, 0);
        helper_assert_cut(sel, both, 2);
        assert_true(st.cost == 2.0 && st.benefit == 3.0);
        f->model.benefit[r] = 0.0;
        st = select_checked(sel, &f->model, 10.0, 0);
        helper_assert_cut(sel, NULL, 0);
        assert_true(st.cost == 0.0 && st.benefit == 0.0);
        tclod_selector_destroy(sel);
    }
}

/* The same below a visible node: P (b 1, c 1) with one child A, additive, of
 * benefit 0, which has children X and Y (2, 1 each); budget 10. Refining P
 * into A would draw nothing (A is culled with X and Y), so every solver draws
 * {P}, benefit 1 (the Robin Hood solver, for which P and A are one object's
 * two levels, steps back from A to P). */
static void an_invisible_additive_node_culls_its_subtree_below_a_visible_one(void **state) {
    helper_fixture *f = (helper_fixture *)*state;
    tclod_id p = add_kind(f, TCLOD_NONE, TABLE_REPLACE, 1.0, 1.0);
    tclod_id a = add_kind(f, p, TABLE_ADD, 0.0, 1.0);
    int k;
    add_kind(f, a, TABLE_REPLACE, 2.0, 1.0);
    add_kind(f, a, TABLE_REPLACE, 2.0, 1.0);
    for (k = 0; k < 3; ++k) {
        tclod_selector *sel = solver_selector(f->scene, &f->model, solvers[k], 0);
        tclod_stats st = select_checked(sel, &f->model, 10.0, 0);
        helper_assert_cut(sel, &p, 1);
        assert_true(st.benefit == 1.0 && st.cost == 1.0);
        tclod_selector_destroy(sel);
    }
}

static void an_overflow_policy_out_of_range_is_refused(void **state) {
    helper_fixture *f = (helper_fixture *)*state;
    tclod_selector_desc d;
    tclod_selector *sel = NULL;
    tclod_selector_desc_default(&d);
    table_callbacks(&f->model, &d.callbacks);
    d.overflow = (tclod_overflow)2;
    assert_int_equal(tclod_selector_create(f->scene, &d, NULL, &sel), TCLOD_ERR_ARG);
    assert_null(sel);
}

/* ---- random hierarchies -------------------------------------------------------- */

/* A random hierarchy of up to 9 nodes that draw, kinds replace or additive,
 * with diminishing returns: every increment gains and costs, and its
 * Δbenefit / Δcost is at most 0.95 times that of the increment above it. */
typedef struct shape {
    uint32_t count;
    int parent[16];
    table_kind kind[16];
    double benefit[16], cost[16];
    int wrap[16]; /* this node hangs below an empty node made for it */
} shape;

static void random_shape(table_rng *rng, shape *sh) {
    uint32_t roots = 1 + table_rng_below(rng, 2), i;
    double ratio[16];
    sh->count = 3 + table_rng_below(rng, 7);
    for (i = 0; i < sh->count; ++i) {
        sh->parent[i] = i < roots ? -1 : (int)table_rng_below(rng, i);
        sh->kind[i] = table_rng_below(rng, 3) == 0 ? TABLE_ADD : TABLE_REPLACE;
        sh->wrap[i] = 0;
    }
    for (i = 0; i < sh->count; ++i) {
        uint32_t c, children = 0;
        double weights = 0.0, db, dc, w[16];
        if (sh->parent[i] < 0) {
            sh->benefit[i] = table_rng_uniform(rng, 1.0, 10.0);
            sh->cost[i] = table_rng_uniform(rng, 0.5, 2.0);
            ratio[i] = table_rng_uniform(rng, 1.0, 4.0);
        }
        for (c = i + 1; c < sh->count; ++c)
            if (sh->parent[c] == (int)i) {
                w[c] = table_rng_uniform(rng, 0.2, 1.0);
                weights += w[c];
                children++;
            }
        if (children == 0)
            continue;
        dc = table_rng_uniform(rng, 0.5, 2.0) * (double)children;
        db = ratio[i] * dc;
        if (sh->kind[i] == TABLE_REPLACE) {
            db += sh->benefit[i];
            dc += sh->cost[i];
        }
        for (c = i + 1; c < sh->count; ++c)
            if (sh->parent[c] == (int)i) {
                sh->benefit[c] = db * w[c] / weights;
                sh->cost[c] = dc * w[c] / weights;
                ratio[c] = 0.95 * ratio[i] * table_rng_uniform(rng, 0.3, 1.0);
            }
    }
    /* empty nodes: some nodes hang below one made for them */
    for (i = 0; i < sh->count; ++i)
        sh->wrap[i] = table_rng_below(rng, 4) == 0;
}

/* Builds shape sh into f, with its empty nodes or without; ids of sh's nodes
 * into id[]. Parents come before children. */
static void build_shape(helper_fixture *f, const shape *sh, int with_empty, tclod_id *id) {
    uint32_t i;
    for (i = 0; i < sh->count; ++i) {
        tclod_id parent = sh->parent[i] < 0 ? TCLOD_NONE : id[sh->parent[i]];
        if (with_empty && sh->wrap[i]) {
            parent = add_kind(f, parent, TABLE_EMPTY, 0.0, 0.0);
            if (i % 3 == 0) /* and an empty leaf beside it */
                add_kind(f, parent, TABLE_EMPTY, 0.0, 0.0);
        }
        id[i] = add_kind(f, parent, sh->kind[i], sh->benefit[i], sh->cost[i]);
    }
}

static double roots_cost(const shape *sh) {
    double sum = 0.0;
    uint32_t i;
    for (i = 0; i < sh->count; ++i)
        if (sh->parent[i] < 0)
            sum += sh->cost[i];
    return sum;
}

static double total_cost(const shape *sh) {
    double sum = 0.0;
    uint32_t i;
    for (i = 0; i < sh->count; ++i)
        sum += sh->cost[i];
    return sum;
}

static int compare_doubles(const void *a, const void *b) {
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* 400 random hierarchies mixing the three kinds, each at four budgets from
 * the roots' cost to all of it: every solver draws a valid selection within
 * the budget and never above the brute-force optimum, asks each node at most
 * once and empty nodes never; the greedy stays within half of the optimum
 * (diminishing returns, docs/greedy.md). */
static void solvers_draw_valid_selections_on_random_mixed_hierarchies(void **state) {
    enum { seeds = 400, budgets = 4 };
    static double ratios[seeds * budgets];
    size_t count = 0;
    uint64_t seed;
    (void)state;
    for (seed = 1; seed <= seeds; ++seed) {
        helper_fixture *f;
        table_rng rng;
        shape sh;
        tclod_id id[16];
        int k, b;
        void *st_ptr;
        table_rng_seed(&rng, seed * 104729u);
        random_shape(&rng, &sh);
        assert_int_equal(helper_fixture_setup(&st_ptr), 0);
        f = (helper_fixture *)st_ptr;
        build_shape(f, &sh, 1, id);
        if (f->model.count > EXACT_MAX_NODES) {
            helper_fixture_teardown(&st_ptr);
            continue;
        }
        for (b = 0; b < budgets; ++b) {
            double lo = roots_cost(&sh) * (1.0 + 1e-12);
            double budget = b == 0 ? lo : table_rng_uniform(&rng, lo, total_cost(&sh) * 1.05);
            double optimum = exact_optimum(&f->model, budget, NULL);
            assert_true(optimum >= 0.0);
            for (k = 0; k < 3; ++k) {
                tclod_selector *sel = solver_selector(f->scene, &f->model, solvers[k], 0);
                tclod_stats st;
                uint32_t i;
                table_reset_counts(&f->model);
                st = select_checked(sel, &f->model, budget, solvers[k] == TCLOD_SOLVER_ROBIN_HOOD);
                /* once per node, the Robin Hood solver's complexities (the
                 * costs of the finest levels) included */
                for (i = 0; i < f->model.count; ++i)
                    assert_true(f->model.benefit_calls[i] <= 1 && f->model.cost_calls[i] <= 1);
                for (i = 0; i < f->model.count; ++i)
                    if (f->model.kind[i] == TABLE_EMPTY)
                        assert_int_equal(f->model.benefit_calls[i], 0);
                /* the optimum keeps every hierarchy: one that dropped some
                 * may spend their cost on others */
                if (st.dropped_roots == 0 && st.benefit > optimum * (1.0 + 1e-12))
                    fail_msg("seed %u solver %d: benefit %.17g above the optimum %.17g",
                             (unsigned)seed, k, st.benefit, optimum);
                if (solvers[k] == TCLOD_SOLVER_GREEDY) {
                    if (st.benefit < 0.5 * optimum)
                        fail_msg("seed %u budget %.17g: greedy %.17g below half of %.17g",
                                 (unsigned)seed, budget, st.benefit, optimum);
                    ratios[count++] = optimum > 0.0 ? st.benefit / optimum : 1.0;
                }
                tclod_selector_destroy(sel);
            }
        }
        helper_fixture_teardown(&st_ptr);
    }
    assert_true(count > seeds);
    qsort(ratios, count, sizeof ratios[0], compare_doubles);
    print_message("greedy / optimum over %u mixed solves: median %.4f, min %.4f\n", (unsigned)count,
                  ratios[count / 2], ratios[0]);
}

/* The same hierarchies with and without their empty nodes: the solvers see
 * the same tree, so they reach the same benefit (ids and the order of
 * children differ, so only up to the rounding of sums in another order). */
static void empty_nodes_change_no_selection(void **state) {
    uint64_t seed;
    (void)state;
    for (seed = 1; seed <= 200; ++seed) {
        table_rng rng;
        shape sh;
        int k;
        double budget;
        table_rng_seed(&rng, seed * 7877u);
        random_shape(&rng, &sh);
        budget = table_rng_uniform(&rng, roots_cost(&sh), total_cost(&sh));
        for (k = 0; k < 2; ++k) { /* the greedy and the mixed solver */
            void *pa, *pb;
            helper_fixture *a, *b;
            tclod_id ida[16], idb[16];
            tclod_selector *sa, *sb;
            tclod_stats ta, tb;
            assert_int_equal(helper_fixture_setup(&pa), 0);
            assert_int_equal(helper_fixture_setup(&pb), 0);
            a = (helper_fixture *)pa;
            b = (helper_fixture *)pb;
            build_shape(a, &sh, 0, ida);
            build_shape(b, &sh, 1, idb);
            sa = solver_selector(a->scene, &a->model, solvers[k], 0);
            sb = solver_selector(b->scene, &b->model, solvers[k], 0);
            ta = select_checked(sa, &a->model, budget, 1);
            tb = select_checked(sb, &b->model, budget, 1);
            if (fabs(ta.benefit - tb.benefit) > 1e-9 * ta.benefit)
                fail_msg("seed %u: %.17g without empty nodes, %.17g with", (unsigned)seed,
                         ta.benefit, tb.benefit);
            tclod_selector_destroy(sa);
            tclod_selector_destroy(sb);
            helper_fixture_teardown(&pa);
            helper_fixture_teardown(&pb);
        }
    }
}

int main(void) {
    const struct CMUnitTest tests[] = {
        FIXTURE_TEST(an_additive_node_stays_drawn_under_its_children),
        FIXTURE_TEST(one_hierarchy_mixes_replace_and_additive_nodes),
        FIXTURE_TEST(an_empty_root_passes_its_children_on_as_roots),
        FIXTURE_TEST(an_empty_node_inside_a_hierarchy_is_passed_over),
        FIXTURE_TEST(roots_over_the_budget_are_dropped_or_drawn_as_asked),
        FIXTURE_TEST(an_unaffordable_root_is_left_out_even_over_the_budget),
        FIXTURE_TEST(drawn_over_the_budget_the_roots_are_all_that_is_drawn),
        FIXTURE_TEST(an_invisible_additive_node_takes_its_subtree_with_it),
        FIXTURE_TEST(an_invisible_additive_node_culls_its_subtree_below_a_visible_one),
        FIXTURE_TEST(an_overflow_policy_out_of_range_is_refused),
        cmocka_unit_test(solvers_draw_valid_selections_on_random_mixed_hierarchies),
        cmocka_unit_test(empty_nodes_change_no_selection),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
