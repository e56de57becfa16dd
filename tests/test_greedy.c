/*
 * test_greedy — the greedy solver (src/solve/greedy/greedy.c): increment order worked out
 * by hand, fill past increments that do not fit, culling of invisible
 * subtrees, dropping of roots that do not fit, the ½-of-optimum bound (on an
 * adversarial instance and against a brute-force optimum on random trees),
 * the lookahead (jumps worked out by hand on chains and trees, refits of
 * jumps that do not fit, its key against a brute-force best ratio, the ½
 * bound without diminishing returns, nothing changed with them), the search,
 * warm starts with decrements, the anytime limits and stop reasons, and the
 * one-call-per-node rule for callbacks.
 *
 * Increment of node n = replace n by its children:
 *   Δb = Σ benefit(children) - benefit(n), Δc = Σ cost(children) - cost(n),
 * an invisible child (benefit 0) costing 0. One iteration = one increment
 * tried, taken or skipped because it does not fit.
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
#include "family_scene.h"
#include "helpers.h"
#include "table_scene.h"

/* Selects one frame without a view; asserts success. */
static void select_frame(tclod_selector *sel, double budget, uint32_t max_iterations,
                         tclod_stats *st) {
    tclod_frame f = helper_frame(NULL, budget);
    f.max_iterations = max_iterations;
    assert_int_equal(tclod_select(sel, &f, st), TCLOD_OK);
}

/* A greedy selector over the table model with the given lookahead and
 * restarts. */
static tclod_selector *tuned_selector(const tclod_scene *s, table_model *m, int warm_start,
                                      uint32_t lookahead, uint32_t restarts) {
    tclod_selector_desc d;
    tclod_selector *sel = NULL;
    tclod_selector_desc_default(&d);
    table_callbacks(m, &d.callbacks);
    d.cold_start = !(warm_start);
    d.greedy.lookahead = lookahead;
    d.greedy.restarts = restarts > 0 ? (int32_t)restarts : TCLOD_OFF;
    /* warm selectors stay warm: what a fallback to cold solves does is
     * tested on its own */
    d.greedy.fallback = TCLOD_OFF;
    assert_int_equal(tclod_selector_create(s, &d, NULL, &sel), TCLOD_OK);
    return sel;
}

static tclod_selector *lookahead_selector(const tclod_scene *s, table_model *m, int warm_start,
                                          uint32_t lookahead) {
    return tuned_selector(s, m, warm_start, lookahead, 1);
}

/* Asserts exact benefit and cost of a result whose values are exact binary
 * fractions (so any summation order gives the same double). */
static void assert_totals(const tclod_stats *st, double benefit, double cost) {
    if (st->benefit != benefit || st->cost != cost)
        fail_msg("benefit %.17g cost %.17g, expected %.17g and %.17g", st->benefit, st->cost,
                 benefit, cost);
}

/* The tree of the hand-worked order (ids in creation order, b = benefit,
 * c = cost):
 *   R 0 (b 10, c 2)  children A 1 (8, 2), B 2 (6, 2)
 *   A 1              children A1 3 (5, 2), A2 4 (5, 2)
 *   B 2              children B1 5 (4.5, 2), B2 6 (4.5, 2)
 *   S 7 (3, 1)       child S1 8 (6, 3), whose child is S2 9 (7, 7)
 * Increments:
 *   R : Δb = 8 + 6 - 10 = 4       Δc = 2 + 2 - 2 = 2   ratio 2
 *   A : Δb = 5 + 5 - 8 = 2        Δc = 2 + 2 - 2 = 2   ratio 1
 *   B : Δb = 4.5 + 4.5 - 6 = 3    Δc = 2 + 2 - 2 = 2   ratio 1.5
 *   S : Δb = 6 - 3 = 3            Δc = 3 - 1 = 2       ratio 1.5
 *   S1: Δb = 7 - 6 = 1            Δc = 7 - 3 = 4       ratio 0.25
 * Order: R (2), then B and S tie at 1.5 and B has the lower id (2 < 7),
 * then S, A (1), S1 (0.25). Roots alone: benefit 13, cost 3. */
static void build_order_tree(helper_fixture *f) {
    helper_add(f, TCLOD_NONE, 10.0, 2.0); /* 0 R */
    helper_add(f, 0, 8.0, 2.0);           /* 1 A */
    helper_add(f, 0, 6.0, 2.0);           /* 2 B */
    helper_add(f, 1, 5.0, 2.0);           /* 3 A1 */
    helper_add(f, 1, 5.0, 2.0);           /* 4 A2 */
    helper_add(f, 2, 4.5, 2.0);           /* 5 B1 */
    helper_add(f, 2, 4.5, 2.0);           /* 6 B2 */
    helper_add(f, TCLOD_NONE, 3.0, 1.0);  /* 7 S */
    helper_add(f, 7, 6.0, 3.0);           /* 8 S1 */
    helper_add(f, 8, 7.0, 7.0);           /* 9 S2 */
}

static void increments_follow_the_hand_worked_order(void **state) {
    helper_fixture *f = (helper_fixture *)*state;
    /* Cut after k increments with an unlimited budget:
     *   k 1 (R):  {A, B, S}            b 8+6+3 = 17        c 2+2+1 = 5
     *   k 2 (B):  {A, B1, B2, S}       b 8+9+3 = 20        c 2+4+1 = 7
     *   k 3 (S):  {A, B1, B2, S1}      b 8+9+6 = 23        c 2+4+3 = 9
     *   k 4 (A):  {A1, A2, B1, B2, S1} b 10+9+6 = 25       c 4+4+3 = 11 */
    static const tclod_id k1[] = {1, 2, 7};
    static const tclod_id k2[] = {1, 5, 6, 7};
    static const tclod_id k3[] = {1, 5, 6, 8};
    static const tclod_id k4[] = {3, 4, 5, 6, 8};
    static const tclod_id finest[] = {3, 4, 5, 6, 9};
    const struct {
        const tclod_id *cut;
        size_t n;
        double benefit, cost;
    } after[] = {{k1, 3, 17.0, 5.0}, {k2, 4, 20.0, 7.0}, {k3, 4, 23.0, 9.0}, {k4, 5, 25.0, 11.0}};
    tclod_selector *sel;
    tclod_stats st;
    uint32_t k;
    build_order_tree(f);
    sel = helper_selector(f->scene, &f->model, 0);
    for (k = 1; k <= 4; ++k) {
        table_reset_counts(&f->model);
        select_frame(sel, INFINITY, k, &st);
        helper_assert_cut(sel, after[k - 1].cut, after[k - 1].n);
        assert_totals(&st, after[k - 1].benefit, after[k - 1].cost);
        assert_int_equal(st.iterations, k);
        assert_int_equal(st.increments, k);
        assert_int_equal(st.decrements, 0);
        assert_int_equal(st.stop_reason, TCLOD_STOP_ITERATIONS);
        assert_int_equal(st.evaluations, table_asked_nodes(&f->model));
    }
    /* No limit: all five increments, then everything is at its finest level
     * ({A1, A2, B1, B2, S2}: b 10+9+7 = 26, c 4+4+7 = 15). */
    table_reset_counts(&f->model);
    select_frame(sel, INFINITY, 0, &st);
    helper_assert_cut(sel, finest, 5);
    assert_totals(&st, 26.0, 15.0);
    assert_int_equal(st.iterations, 5);
    assert_int_equal(st.increments, 5);
    assert_int_equal(st.stop_reason, TCLOD_STOP_FINEST);
    assert_int_equal(st.evaluations, 10);
    assert_int_equal(st.dropped_roots, 0);
    assert_int_equal(st.invalid_values, 0);
    tclod_selector_destroy(sel);
}

static void increments_stop_when_nothing_more_fits(void **state) {
    helper_fixture *f = (helper_fixture *)*state;
    /* Budget 10: R (c 5), B (c 7), S (c 9) are taken; A would cost 9 + 2 = 11
     * and S1 9 + 4 = 13: neither fits. Whether they count as tried depends on
     * whether the solver looks at them or sees that none can fit, so the
     * iterations lie between 3 and 5 (one pass: restarts = 1, so that the
     * counts are the pass's own). The cut
     * {A, B1, B2, S1} (b 23, c 9) is also the optimum: the other cuts of cost
     * <= 10 are {A1, A2, B1, B2, S} (b 22), {A1, A2, B, S1} (b 22) and less. */
    static const tclod_id budget_10[] = {1, 5, 6, 8};
    /* Budget 3: the roots cost 3 exactly; R and S (+2 each) do not fit. */
    static const tclod_id budget_3[] = {0, 7};
    tclod_selector *sel;
    tclod_stats st;
    build_order_tree(f);
    sel = tuned_selector(f->scene, &f->model, 0, 0, 1);
    select_frame(sel, 10.0, 0, &st);
    helper_assert_cut(sel, budget_10, 4);
    assert_totals(&st, 23.0, 9.0);
    assert_in_range(st.iterations, 3, 5);
    assert_int_equal(st.increments, 3);
    assert_int_equal(st.stop_reason, TCLOD_STOP_BUDGET);
    select_frame(sel, 3.0, 0, &st);
    helper_assert_cut(sel, budget_3, 2);
    assert_totals(&st, 13.0, 3.0);
    assert_in_range(st.iterations, 0, 2);
    assert_int_equal(st.increments, 0);
    assert_int_equal(st.dropped_roots, 0);
    assert_int_equal(st.stop_reason, TCLOD_STOP_BUDGET);
    tclod_selector_destroy(sel);
}

static void an_increment_that_does_not_fit_is_skipped_for_a_later_one(void **state) {
    helper_fixture *f = (helper_fixture *)*state;
    /* P 0 (1, 1) -> P1 1 (11, 11): Δb 10, Δc 10, ratio 1.
     * Q 2 (1, 1) -> Q1 3 (1.5, 2): Δb 0.5, Δc 1, ratio 0.5.
     * Budget 5, roots cost 2: P first needs 12 > 5, skipped; Q needs 3, taken.
     * {P, Q1}: b 2.5, c 3 — the optimum ({P1, ...} costs >= 12). One pass
     * (restarts = 1): the counts are the pass's own. */
    static const tclod_id filled[] = {0, 3};
    static const tclod_id one_try[] = {0, 2};
    tclod_selector *sel;
    tclod_stats st;
    helper_add(f, TCLOD_NONE, 1.0, 1.0);
    helper_add(f, 0, 11.0, 11.0);
    helper_add(f, TCLOD_NONE, 1.0, 1.0);
    helper_add(f, 2, 1.5, 2.0);
    sel = tuned_selector(f->scene, &f->model, 0, 0, 1);
    select_frame(sel, 5.0, 0, &st);
    helper_assert_cut(sel, filled, 2);
    assert_totals(&st, 2.5, 3.0);
    assert_int_equal(st.iterations, 2);
    assert_int_equal(st.increments, 1);
    assert_int_equal(st.stop_reason, TCLOD_STOP_BUDGET);
    /* The skipped increment is the first iteration. */
    select_frame(sel, 5.0, 1, &st);
    helper_assert_cut(sel, one_try, 2);
    assert_totals(&st, 2.0, 2.0);
    assert_int_equal(st.iterations, 1);
    assert_int_equal(st.increments, 0);
    assert_int_equal(st.stop_reason, TCLOD_STOP_ITERATIONS);
    tclod_selector_destroy(sel);
}

static void invisible_nodes_are_culled_with_their_subtree(void **state) {
    helper_fixture *f = (helper_fixture *)*state;
    /* P 0 (1, 1) with children H 1 (benefit 0, cost 5) and V 2 (2, 3);
     * H's subtree 3 (5, 1) -> 4 (6, 2) must never be looked at.
     * Q 5 (benefit 0) is an invisible root with child 6 (3, 1).
     * W 7 (1, 1) is a visible leaf root.
     * P's increment: Δb = 0 + 2 - 1 = 1, Δc = 0 + 3 - 1 = 2 (H costs 0): taken.
     * Result: cut {H, V, Q, W}, listed {V, W}, b 2 + 1 = 3, c 3 + 1 = 4. */
    static const tclod_id listed[] = {2, 7};
    tclod_selector *sel;
    tclod_stats st;
    helper_add(f, TCLOD_NONE, 1.0, 1.0); /* 0 P */
    helper_add(f, 0, 0.0, 5.0);          /* 1 H */
    helper_add(f, 0, 2.0, 3.0);          /* 2 V */
    helper_add(f, 1, 5.0, 1.0);          /* 3 */
    helper_add(f, 3, 6.0, 2.0);          /* 4 */
    helper_add(f, TCLOD_NONE, 0.0, 1.0); /* 5 Q */
    helper_add(f, 5, 3.0, 1.0);          /* 6 */
    helper_add(f, TCLOD_NONE, 1.0, 1.0); /* 7 W */
    sel = helper_selector(f->scene, &f->model, 0);
    table_reset_counts(&f->model);
    select_frame(sel, INFINITY, 0, &st);
    helper_assert_cut(sel, listed, 2);
    helper_check_result(sel, &f->model, &st, INFINITY, 0);
    assert_totals(&st, 3.0, 4.0);
    assert_int_equal(st.increments, 1);
    assert_int_equal(st.dropped_roots, 0);
    assert_int_equal(st.stop_reason, TCLOD_STOP_FINEST);
    /* Benefit asked once for 0, 1, 2, 5, 7; cost only for the visible ones. */
    assert_int_equal(f->model.benefit_calls[0], 1);
    assert_int_equal(f->model.benefit_calls[1], 1);
    assert_int_equal(f->model.benefit_calls[2], 1);
    assert_int_equal(f->model.benefit_calls[5], 1);
    assert_int_equal(f->model.benefit_calls[7], 1);
    assert_int_equal(f->model.cost_calls[0], 1);
    assert_int_equal(f->model.cost_calls[2], 1);
    assert_int_equal(f->model.cost_calls[7], 1);
    assert_int_equal(f->model.cost_calls[1], 0);
    assert_int_equal(f->model.cost_calls[5], 0);
    /* The culled subtrees are never evaluated. */
    assert_int_equal(f->model.benefit_calls[3] + f->model.cost_calls[3], 0);
    assert_int_equal(f->model.benefit_calls[4] + f->model.cost_calls[4], 0);
    assert_int_equal(f->model.benefit_calls[6] + f->model.cost_calls[6], 0);
    assert_int_equal(st.evaluations, 5);
    tclod_selector_destroy(sel);
}

static void roots_that_do_not_fit_are_dropped_lowest_value_first(void **state) {
    helper_fixture *f = (helper_fixture *)*state;
    /* Roots a 0 (10, 6), b 1 (3, 1), c 2 (4, 4): together cost 11. Values
     * (benefit / cost) 1.67, 3 and 1. Budget 7: dropping c (lowest) leaves
     * cost 7 <= 7, so a and b stay: b 13, one root dropped.
     * An invisible root d 3 (benefit 0) is never counted as dropped. */
    static const tclod_id kept[] = {0, 1};
    static const tclod_id all[] = {0, 1, 2};
    tclod_selector *sel;
    tclod_stats st;
    helper_add(f, TCLOD_NONE, 10.0, 6.0);
    helper_add(f, TCLOD_NONE, 3.0, 1.0);
    helper_add(f, TCLOD_NONE, 4.0, 4.0);
    helper_add(f, TCLOD_NONE, 0.0, 9.0);
    sel = helper_selector(f->scene, &f->model, 0);
    select_frame(sel, 7.0, 0, &st);
    helper_assert_cut(sel, kept, 2);
    helper_check_result(sel, &f->model, &st, 7.0, 1);
    assert_totals(&st, 13.0, 7.0);
    assert_int_equal(st.dropped_roots, 1);
    /* Budget 11: everything fits, nothing dropped. */
    select_frame(sel, 11.0, 0, &st);
    helper_assert_cut(sel, all, 3);
    assert_totals(&st, 17.0, 11.0);
    assert_int_equal(st.dropped_roots, 0);
    tclod_selector_destroy(sel);
}

static void zero_budget_drops_every_visible_root_that_costs(void **state) {
    helper_fixture *f = (helper_fixture *)*state;
    /* The three visible roots of the previous test and an invisible one:
     * with budget 0 the three are dropped, the invisible one is not counted. */
    tclod_selector *sel;
    tclod_stats st;
    helper_add(f, TCLOD_NONE, 10.0, 6.0);
    helper_add(f, TCLOD_NONE, 3.0, 1.0);
    helper_add(f, TCLOD_NONE, 4.0, 4.0);
    helper_add(f, TCLOD_NONE, 0.0, 9.0);
    helper_add(f, 0, 20.0, 7.0);
    sel = helper_selector(f->scene, &f->model, 0);
    select_frame(sel, 0.0, 0, &st);
    helper_assert_cut(sel, NULL, 0);
    assert_totals(&st, 0.0, 0.0);
    assert_int_equal(st.dropped_roots, 3);
    tclod_selector_destroy(sel);
}

static void zero_budget_keeps_roots_that_cost_nothing(void **state) {
    helper_fixture *f = (helper_fixture *)*state;
    /* Budget 0: a 0 (10, 6) must go; z 1 (2, 0) costs nothing (value
     * 2 / 0 = inf) and stays: b 2, c 0, one root dropped. */
    tclod_selector *sel;
    tclod_stats st;
    const tclod_id *ids;
    size_t n;
    helper_add(f, TCLOD_NONE, 10.0, 6.0);
    helper_add(f, TCLOD_NONE, 2.0, 0.0);
    sel = helper_selector(f->scene, &f->model, 0);
    select_frame(sel, 0.0, 0, &st);
    assert_int_equal(tclod_selector_cut(sel, &ids, &n), TCLOD_OK);
    assert_int_equal(n, 1);
    assert_int_equal(ids[0], 1);
    assert_totals(&st, 2.0, 0.0);
    assert_int_equal(st.dropped_roots, 1);
    tclod_selector_destroy(sel);
}

/* Roots that do not fit give way to children that cost less, before any root
 * is left out (children outside the frustum cost nothing):
 *   R1 0 (b 4, c 3)  children A 1 (2, 1), B 2 (invisible)
 *   R2 3 (b 3, c 2)  children C 4 (2.7, 1.5), D 5 (invisible)
 * Budget 4; the roots cost 5. Refining R1 saves 2 for a loss of 2 (ratio 1),
 * R2 saves 0.5 for 0.3 (0.6): R2's comes first and leaves 4.5, R1's then
 * 2.5, which fits. Undone newest first where it still fits: R1 back would
 * cost 4.5, no; R2 back costs 3, yes. Cut {A, R2}: b 5, c 3, nothing left
 * out, the optimum (exact_optimum). Leaving roots out instead kept {R1}, b 4.
 * A warm selector whose last cut was the roots (budget 10, where neither
 * refinement gains) comes to the same, and so does the mixed solver. */
static void roots_that_do_not_fit_give_way_to_cheaper_children(void **state) {
    helper_fixture *f = (helper_fixture *)*state;
    static const tclod_id want[] = {1, 3}, roots[] = {0, 3};
    tclod_id r1, r2;
    tclod_stats st;
    int k;
    r1 = helper_add(f, TCLOD_NONE, 4.0, 3.0);
    helper_add(f, r1, 2.0, 1.0);
    helper_add(f, r1, 0.0, 5.0);
    r2 = helper_add(f, TCLOD_NONE, 3.0, 2.0);
    helper_add(f, r2, 2.7, 1.5);
    helper_add(f, r2, 0.0, 5.0);
    assert_true(exact_optimum(&f->model, 4.0, NULL) == 5.0);
    for (k = 0; k < 3; ++k) {
        tclod_selector *sel;
        if (k < 2) {
            sel = helper_selector(f->scene, &f->model, k);
        } else {
            tclod_selector_desc d;
            tclod_selector_desc_default(&d);
            d.solver = TCLOD_SOLVER_MIXED;
            table_callbacks(&f->model, &d.callbacks);
            assert_int_equal(tclod_selector_create(f->scene, &d, NULL, &sel), TCLOD_OK);
        }
        if (k == 1) { /* warm, from the roots */
            select_frame(sel, 10.0, 0, &st);
            helper_assert_cut(sel, roots, 2);
        }
        select_frame(sel, 4.0, 0, &st);
        helper_assert_cut(sel, want, 2);
        helper_check_result(sel, &f->model, &st, 4.0, 0);
        assert_totals(&st, 5.0, 3.0);
        assert_int_equal(st.dropped_roots, 0);
        tclod_selector_destroy(sel);
    }
}

/* A warm start takes back a parent whose children left the view:
 *   P 0 (b 10, c 2)  children A 1 (6, 1), B 2 (6, 1)
 * Budget 10: P -> {A, B} gains 2 at no cost: cut {A, B}, b 12. Then A and B
 * turn invisible while P does not. The cut {A, B} would draw nothing (b 0);
 * collapsing it into P gains 10 for 2 more cost, and a cold solve never
 * refines P (its increment would lose 10): {P}, b 10, c 2. Over budget 1,
 * P does not fit and the invisible children, which cost nothing, stay: b 0,
 * c 0, no root left out. */
static void a_warm_start_takes_back_a_parent_whose_children_left_the_view(void **state) {
    helper_fixture *f = (helper_fixture *)*state;
    static const tclod_id both[] = {1, 2}, parent[] = {0};
    tclod_selector *sel;
    tclod_stats st;
    helper_add(f, TCLOD_NONE, 10.0, 2.0);
    helper_add(f, 0, 6.0, 1.0);
    helper_add(f, 0, 6.0, 1.0);
    sel = helper_selector(f->scene, &f->model, 1);
    select_frame(sel, 10.0, 0, &st);
    helper_assert_cut(sel, both, 2);
    assert_totals(&st, 12.0, 2.0);
    f->model.benefit[1] = f->model.benefit[2] = 0.0;
    select_frame(sel, 10.0, 0, &st);
    helper_assert_cut(sel, parent, 1);
    helper_check_result(sel, &f->model, &st, 10.0, 0);
    assert_totals(&st, 10.0, 2.0);
    select_frame(sel, 1.0, 0, &st);
    helper_assert_cut(sel, NULL, 0);
    assert_totals(&st, 0.0, 0.0);
    assert_int_equal(st.dropped_roots, 0);
    tclod_selector_destroy(sel);
}

/* A node whose parent is invisible is culled with it, whatever its own
 * volume says (children that reach out of their parent's volume):
 *   P 0 (b 10, c 2) -> Q 1 (12, 2) -> R 2 (14, 2)
 * Budget 10: {R}, b 14. Then Q turns invisible while R (reaching out of it)
 * is still seen, worth 1. A cold solve culls R with Q and keeps P (its
 * increment would lose 10); the warm start collapses R into Q before
 * anything else and then Q into P: {P}, b 10, c 2. */
static void a_warm_start_culls_the_children_of_an_invisible_parent(void **state) {
    helper_fixture *f = (helper_fixture *)*state;
    static const tclod_id leaf[] = {2}, top[] = {0};
    tclod_selector *sel;
    tclod_stats st;
    helper_add(f, TCLOD_NONE, 10.0, 2.0);
    helper_add(f, 0, 12.0, 2.0);
    helper_add(f, 1, 14.0, 2.0);
    sel = helper_selector(f->scene, &f->model, 1);
    select_frame(sel, 10.0, 0, &st);
    helper_assert_cut(sel, leaf, 1);
    f->model.benefit[1] = 0.0;
    f->model.benefit[2] = 1.0;
    select_frame(sel, 10.0, 0, &st);
    helper_assert_cut(sel, top, 1);
    assert_totals(&st, 10.0, 2.0);
    tclod_selector_destroy(sel);
}

static void greedy_reaches_half_the_optimum_on_an_adversarial_instance(void **state) {
    helper_fixture *f = (helper_fixture *)*state;
    /* Two chains with tiny roots A 0 and B 2 (b 0.125, c 0.125 each):
     *   A -> A1 1 (b 1.375, c 1.125):    Δb 1.25, Δc 1     ratio 1.25
     *   B -> B1 3 (b 100.125, c 100.125): Δb 100, Δc 100   ratio 1
     * Budget 100.75 = roots 0.25 + 100 + 0.5. Ratio order alone takes A1
     * (cost 1.25), then B1 would cost 101.25 > 100.75: benefit 1.5.
     * Cuts: {A, B} 0.25, {A1, B} 1.5, {A, B1} 100.25 (cost 100.25 fits),
     * {A1, B1} (cost 101.25, does not fit): optimum 100.25, half 50.125.
     * The only cut reaching half is {A, B1}. */
    static const tclod_id best[] = {0, 3};
    tclod_selector *sel;
    tclod_stats st;
    helper_add(f, TCLOD_NONE, 0.125, 0.125);
    helper_add(f, 0, 1.375, 1.125);
    helper_add(f, TCLOD_NONE, 0.125, 0.125);
    helper_add(f, 2, 100.125, 100.125);
    sel = helper_selector(f->scene, &f->model, 0);
    select_frame(sel, 100.75, 0, &st);
    helper_check_result(sel, &f->model, &st, 100.75, 0);
    assert_true(st.benefit >= 0.5 * 100.25);
    assert_true(st.benefit <= 100.25);
    helper_assert_cut(sel, best, 2);
    tclod_selector_destroy(sel);
}

static void exact_solver_agrees_with_hand_worked_optima(void **state) {
    helper_fixture *f = (helper_fixture *)*state;
    /* The brute-force optimum that the random tests trust, on the order tree:
     * budget 3 -> roots only, 13; 10 -> {A, B1, B2, S1}, 23; 11 ->
     * {A1, A2, B1, B2, S1}, 25; 15 and unlimited -> the leaves, 26;
     * 2.5 -> no cut fits (-1). And the cut checker on hand-made lists. */
    static const tclod_id valid[] = {3, 4, 2, 8};
    static const tclod_id overlapping[] = {1, 3, 4, 2, 8};
    static const tclod_id uncovered[] = {3, 2, 8};
    static const tclod_id repeated[] = {3, 4, 2, 8, 8};
    static const tclod_id one_hierarchy[] = {0};
    double cost;
    build_order_tree(f);
    assert_true(exact_optimum(&f->model, 3.0, &cost) == 13.0);
    assert_true(cost == 3.0);
    assert_true(exact_optimum(&f->model, 10.0, &cost) == 23.0);
    assert_true(cost == 9.0);
    assert_true(exact_optimum(&f->model, 11.0, NULL) == 25.0);
    assert_true(exact_optimum(&f->model, 15.0, NULL) == 26.0);
    assert_true(exact_optimum(&f->model, INFINITY, NULL) == 26.0);
    assert_true(exact_optimum(&f->model, 2.5, NULL) == -1.0);
    assert_true(exact_check_cut(&f->model, valid, 4, 0));
    assert_false(exact_check_cut(&f->model, overlapping, 5, 0));
    assert_false(exact_check_cut(&f->model, uncovered, 3, 0));
    assert_false(exact_check_cut(&f->model, uncovered, 3, 1));
    assert_false(exact_check_cut(&f->model, repeated, 5, 0));
    assert_false(exact_check_cut(&f->model, one_hierarchy, 1, 0));
    assert_true(exact_check_cut(&f->model, one_hierarchy, 1, 1));
    /* With B invisible its subtree needs no listed node. */
    f->model.benefit[2] = 0.0;
    assert_true(exact_check_cut(&f->model, uncovered + 0, 1, 1) == 0);
    {
        static const tclod_id culled_b[] = {3, 4, 8};
        assert_true(exact_check_cut(&f->model, culled_b, 3, 0));
    }
}

static int compare_doubles(const void *a, const void *b) {
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* Random scenes of 3..12 nodes and 1..3 roots, each solved cold at four
 * budgets between the roots' cost and 1.1 x the leaves' cost, compared with
 * the brute-force optimum over all cuts. */
static void random_trees_against_exact_optimum(table_values values, int check_half,
                                               uint32_t lookahead) {
    enum { seeds = 300, budgets = 4 };
    static double ratios[seeds * budgets];
    size_t count = 0;
    uint64_t seed;
    for (seed = 1; seed <= seeds; ++seed) {
        tclod_scene *s = NULL;
        tclod_selector *sel;
        table_model m;
        table_rng rng;
        uint32_t nodes, roots;
        double lo, hi;
        int b;
        table_rng_seed(&rng, seed * 7919u + (uint64_t)values);
        nodes = 3 + table_rng_below(&rng, 10);
        roots = 1 + table_rng_below(&rng, 3);
        table_init(&m);
        assert_int_equal(tclod_scene_create(NULL, &s), TCLOD_OK);
        assert_int_equal(table_random_hierarchy(&m, s, &rng, nodes, roots, values), TCLOD_OK);
        sel = lookahead_selector(s, &m, 0, lookahead);
        /* A margin of 1e-12 above the roots' cost keeps a different summation
         * order from legitimately dropping a root. */
        lo = table_roots_cost(&m) * (1.0 + 1e-12);
        if (values == TABLE_DIMINISHING) {
            hi = table_leaves_cost(&m) * 1.1;
        } else {
            uint32_t i;
            hi = lo;
            for (i = 0; i < m.count; ++i)
                hi += m.cost[i];
        }
        for (b = 0; b < budgets; ++b) {
            double budget = b == 0 ? lo : table_rng_uniform(&rng, lo, hi);
            double optimum;
            tclod_stats st;
            table_reset_counts(&m);
            select_frame(sel, budget, 0, &st);
            helper_check_result(sel, &m, &st, budget, 0);
            assert_true(table_max_calls(&m) <= 1);
            optimum = exact_optimum(&m, budget, NULL);
            assert_true(optimum >= 0.0);
            if (st.benefit > optimum + 1e-9)
                fail_msg("seed %u budget %.17g: benefit %.17g above the optimum %.17g",
                         (unsigned)seed, budget, st.benefit, optimum);
            if (check_half && st.benefit < 0.5 * optimum)
                fail_msg("seed %u budget %.17g: benefit %.17g below half the optimum %.17g",
                         (unsigned)seed, budget, st.benefit, optimum);
            ratios[count++] = optimum > 0.0 ? st.benefit / optimum : 1.0;
        }
        tclod_selector_destroy(sel);
        tclod_scene_destroy(s);
        table_free(&m);
    }
    qsort(ratios, count, sizeof ratios[0], compare_doubles);
    print_message("%s values, lookahead %u: greedy / optimum over %u solves: median %.4f, "
                  "min %.4f\n",
                  values == TABLE_DIMINISHING ? "diminishing" : "arbitrary", (unsigned)lookahead,
                  (unsigned)count, ratios[count / 2], ratios[0]);
}

static void greedy_is_within_half_of_exact_optimum_on_random_trees(void **state) {
    (void)state;
    random_trees_against_exact_optimum(TABLE_DIMINISHING, 1, 0);
}

static void greedy_never_beats_the_optimum_nor_the_budget_on_arbitrary_values(void **state) {
    (void)state;
    random_trees_against_exact_optimum(TABLE_ARBITRARY, 0, 0);
}

/* With diminishing returns no level beyond the next has a better ratio, so
 * the lookahead changes nothing and the ½ bound still holds. */
static void greedy_with_lookahead_is_within_half_of_exact_optimum_on_random_trees(void **state) {
    (void)state;
    random_trees_against_exact_optimum(TABLE_DIMINISHING, 1, 2);
}

static void greedy_with_lookahead_never_beats_the_optimum_nor_the_budget(void **state) {
    (void)state;
    random_trees_against_exact_optimum(TABLE_ARBITRARY, 0, 3);
}

/* A random diminishing-returns scene of `nodes` nodes and `roots` roots. */
static void random_scene(helper_fixture *f, uint64_t seed, uint32_t nodes, uint32_t roots) {
    table_rng rng;
    table_rng_seed(&rng, seed);
    assert_int_equal(
        table_random_hierarchy(&f->model, f->scene, &rng, nodes, roots, TABLE_DIMINISHING),
        TCLOD_OK);
}

static void warm_start_on_an_unchanged_frame_is_at_least_as_good(void **state) {
    helper_fixture *f = (helper_fixture *)*state;
    tclod_selector *cold, *warm;
    double lo, hi;
    int i;
    random_scene(f, 42, 400, 12);
    /* Just above the roots' and the leaves' costs: at exactly these budgets
     * whether the first or the last increment fits is decided by rounding,
     * which the order of the running sums decides. */
    lo = table_roots_cost(&f->model) * (1.0 + 1e-12);
    hi = table_leaves_cost(&f->model) * (1.0 + 1e-12);
    cold = helper_selector(f->scene, &f->model, 0);
    warm = helper_selector(f->scene, &f->model, 1);
    for (i = 0; i <= 10; ++i) {
        double budget = lo + (hi - lo) * (double)i / 10.0;
        tclod_stats first, second, reference;
        select_frame(cold, budget, 0, &reference);
        select_frame(warm, budget, 0, &first);
        helper_check_result(warm, &f->model, &first, budget, 0);
        table_reset_counts(&f->model);
        select_frame(warm, budget, 0, &second);
        helper_check_result(warm, &f->model, &second, budget, 0);
        assert_true(table_max_calls(&f->model) <= 1);
        /* 1e-12 relative: the same cut listed in another order may sum
         * differently in the last bit. */
        if (second.benefit < first.benefit * (1.0 - 1e-12) ||
            second.benefit < reference.benefit * (1.0 - 1e-12))
            fail_msg("budget %.17g: warm %.17g, previous %.17g, cold %.17g", budget, second.benefit,
                     first.benefit, reference.benefit);
        /* Start over from the roots for the next budget. */
        tclod_selector_destroy(warm);
        warm = helper_selector(f->scene, &f->model, 1);
    }
    tclod_selector_destroy(warm);
    tclod_selector_destroy(cold);
}

/* A cold solve after an earlier one takes the increments keyed above the
 * earlier solve's first misfit without ordering them, and starts over with
 * the heap alone when they do not fit (docs/greedy.md); either way it must
 * reach the cut a new selector's solve reaches. Budgets that jump up and down
 * make both happen: after a large budget the earlier misfit's key is low and
 * the unordered increments overrun a small one. */
static void cold_solves_after_other_budgets_reach_a_new_selectors_cut(void **state) {
    enum { CAP = 4096 };
    static tclod_id a[CAP], b[CAP];
    helper_fixture *f = (helper_fixture *)*state;
    tclod_selector *reused;
    table_rng rng;
    double lo, hi;
    int k, restarted = 0;
    random_scene(f, 7, 900, 30);
    lo = table_roots_cost(&f->model);
    hi = table_leaves_cost(&f->model);
    reused = helper_selector(f->scene, &f->model, 0);
    table_rng_seed(&rng, 11);
    for (k = 0; k < 40; ++k) {
        double budget = table_rng_uniform(&rng, lo, hi);
        tclod_selector *fresh = helper_selector(f->scene, &f->model, 0);
        tclod_stats st, ref;
        size_t na, nb;
        select_frame(reused, budget, 0, &st);
        select_frame(fresh, budget, 0, &ref);
        helper_check_result(reused, &f->model, &st, budget, 0);
        na = helper_sorted_cut(reused, a, CAP);
        nb = helper_sorted_cut(fresh, b, CAP);
        assert_int_equal(na, nb);
        assert_memory_equal(a, b, na * sizeof *a);
        assert_true(fabs(st.benefit - ref.benefit) <= 1e-12 * ref.benefit);
        restarted += st.iterations > ref.iterations;
        tclod_selector_destroy(fresh);
    }
    assert_true(restarted > 0);
    tclod_selector_destroy(reused);
}

/* On a scene of 16384 nodes or more a warm start first sorts the cut by id
 * (docs/greedy.md). Budgets that jump up and down make warm solves take
 * increments and decrements, so the cut they sort comes in a scrambled order;
 * every result must still be a cut within its budget, and a second solve of
 * the same frame must lose nothing. */
static void warm_starts_on_a_large_scene_keep_every_guarantee(void **state) {
    helper_fixture *f = (helper_fixture *)*state;
    tclod_selector *sel;
    table_rng rng;
    double lo, hi;
    int k;
    random_scene(f, 5, 20000, 40);
    assert_true(tclod_scene_node_count(f->scene) >= 16384u);
    lo = table_roots_cost(&f->model);
    hi = table_leaves_cost(&f->model);
    sel = helper_selector(f->scene, &f->model, 1);
    table_rng_seed(&rng, 3);
    for (k = 0; k < 12; ++k) {
        double budget = table_rng_uniform(&rng, lo, hi);
        tclod_stats first, second;
        select_frame(sel, budget, 0, &first);
        helper_check_result(sel, &f->model, &first, budget, 0);
        select_frame(sel, budget, 0, &second);
        helper_check_result(sel, &f->model, &second, budget, 0);
        assert_true(second.benefit >= first.benefit * (1.0 - 1e-12));
    }
    tclod_selector_destroy(sel);
}

static void warm_start_after_a_budget_drop_uses_decrements(void **state) {
    helper_fixture *f = (helper_fixture *)*state;
    tclod_selector *sel;
    tclod_stats st;
    table_rng rng;
    double previous;
    int frame;
    table_rng_seed(&rng, 7);
    assert_int_equal(table_chains(&f->model, f->scene, &rng, 50, 6, 0.0f), TCLOD_OK);
    sel = helper_selector(f->scene, &f->model, 1);
    select_frame(sel, table_leaves_cost(&f->model) * 0.5, 0, &st);
    helper_check_result(sel, &f->model, &st, table_leaves_cost(&f->model) * 0.5, 0);
    previous = st.cost;
    /* Each frame the budget falls to 80% of the previous cost (never below
     * the roots' cost): the previous cut no longer fits and must shrink. */
    for (frame = 0; frame < 8; ++frame) {
        double budget = previous * 0.8;
        if (budget < table_roots_cost(&f->model) * 1.001)
            break;
        table_reset_counts(&f->model);
        select_frame(sel, budget, 0, &st);
        helper_check_result(sel, &f->model, &st, budget, 0);
        assert_true(table_max_calls(&f->model) <= 1);
        assert_true(st.decrements > 0);
        previous = st.cost;
    }
    assert_true(frame >= 3);
    tclod_selector_destroy(sel);
}

static void warm_start_swaps_a_refinement_for_a_better_one_of_the_same_cost(void **state) {
    helper_fixture *f = (helper_fixture *)*state;
    /* Chains A: 0 (b 1, c 1) -> 1 (b 5, c 3) and B: 2 (b 1, c 1) -> 3 (b 4,
     * c 3); budget 4 = the roots plus one increment of cost 2. Frame 1: A's
     * increment (Δb 4, ratio 2) beats B's (Δb 3, ratio 1.5): {1, 2}, benefit
     * 6. Frame 2: B's finer level is worth 7 (Δb 6, ratio 3). The warm start
     * finds its cut feasible and B's increment too costly (4 + 2 > 4); since
     * B's ratio 3 is above the loss ratio 4 / 2 = 2 of collapsing A, it swaps:
     * decrement A (loses 4, frees 2), increment B (gains 6): {0, 3}, benefit
     * 8, cost 4 -- the optimum, which a cold solve reaches directly. */
    static const tclod_id first[] = {1, 2}, swapped[] = {0, 3};
    tclod_selector *sel;
    tclod_stats st;
    helper_add(f, TCLOD_NONE, 1.0, 1.0);
    helper_add(f, 0, 5.0, 3.0);
    helper_add(f, TCLOD_NONE, 1.0, 1.0);
    helper_add(f, 2, 4.0, 3.0);
    sel = helper_selector(f->scene, &f->model, 1);
    select_frame(sel, 4.0, 0, &st);
    helper_assert_cut(sel, first, 2);
    assert_true(st.benefit == 6.0 && st.cost == 4.0);
    f->model.benefit[3] = 7.0;
    select_frame(sel, 4.0, 0, &st);
    helper_assert_cut(sel, swapped, 2);
    assert_true(st.benefit == 8.0 && st.cost == 4.0);
    assert_int_equal(st.decrements, 1);
    assert_int_equal(st.increments, 1);
    tclod_selector_destroy(sel);
}

static void warm_start_swaps_in_the_misfit_its_fill_skipped(void **state) {
    helper_fixture *f = (helper_fixture *)*state;
    /* Chains X: 0 (b 1, c 1) -> 1 (c 6), Y: 2 (b 1, c 1) -> 3 (c 2) and Z:
     * 4 (b 1, c 1) -> 5 (b 5.75, c 5); budget 8. Frame 1: 1 and 3 are worth 1
     * (no gain): the roots (3) and Z's increment (Δc 4): {0, 2, 5}, benefit
     * 7.75, cost 7. Frame 2: 1 is worth 11 (Δb 10, Δc 5, ratio 2) and 3 is
     * worth 2.5 (Δb 1.5, Δc 1, ratio 1.5). The warm fill finds X's increment
     * too costly (7 + 5 > 8) and takes Y's, which fits: {0, 3, 5}, 9.25, cost
     * 8. X's ratio 2 beats the cheapest decrement's loss ratio (Z: 4.75 / 4),
     * so the swaps take X's increment back up, though the fill skipped it:
     * they need 5, and collapsing Z (frees 4, loses 4.75) then Y (frees 1,
     * loses 1.5) frees it for a loss of 6.25 < 10: {1, 2, 4}, benefit 13,
     * cost 8. Y's increment (ratio 1.5) is then below X's loss ratio 2, and
     * nothing fits the room left (0). A cold solve takes X first: the same. */
    static const tclod_id first[] = {0, 2, 5}, best[] = {1, 2, 4};
    tclod_selector *warm, *cold;
    tclod_stats st;
    helper_add(f, TCLOD_NONE, 1.0, 1.0);
    helper_add(f, 0, 1.0, 6.0);
    helper_add(f, TCLOD_NONE, 1.0, 1.0);
    helper_add(f, 2, 1.0, 2.0);
    helper_add(f, TCLOD_NONE, 1.0, 1.0);
    helper_add(f, 4, 5.75, 5.0);
    warm = helper_selector(f->scene, &f->model, 1);
    cold = helper_selector(f->scene, &f->model, 0);
    select_frame(warm, 8.0, 0, &st);
    helper_assert_cut(warm, first, 3);
    assert_true(st.benefit == 7.75 && st.cost == 7.0);
    f->model.benefit[1] = 11.0;
    f->model.benefit[3] = 2.5;
    select_frame(warm, 8.0, 0, &st);
    helper_assert_cut(warm, best, 3);
    assert_true(st.benefit == 13.0 && st.cost == 8.0);
    assert_int_equal(st.increments, 2); /* Y's in the fill, then X's */
    assert_int_equal(st.decrements, 2); /* Z's and Y's, for X's */
    select_frame(cold, 8.0, 0, &st);
    helper_assert_cut(cold, best, 3);
    assert_true(st.benefit == 13.0 && st.cost == 8.0);
    tclod_selector_destroy(warm);
    tclod_selector_destroy(cold);
}

static void warm_start_swaps_collapse_a_chain_level_by_level(void **state) {
    helper_fixture *f = (helper_fixture *)*state;
    /* Chains X: 0 (b 1, c 1) -> 1 (2, 2) -> 2 (2.25, 4) and I: 3 (1, 1) ->
     * 4 (1, 4); budget 5. Frame 1: X's increments (ratios 1 and 0.125) fit, I
     * gains nothing: {2, 3}, benefit 3.25, cost 5. Frame 2: 4 is worth 5 (Δb
     * 4, Δc 3), with no room. The only collapse queued, 2 into 1, frees 2 for
     * 0.25; once taken, 1 into 0 is one too (its only child is about to be in
     * the cut) and frees the last 1 for 1: {0, 4}, benefit 6, cost 5, the
     * optimum (exact_optimum). Seeing one level only kept 3.25. */
    static const tclod_id first[] = {2, 3}, best[] = {0, 4};
    tclod_selector *warm;
    tclod_stats st;
    helper_add(f, TCLOD_NONE, 1.0, 1.0);
    helper_add(f, 0, 2.0, 2.0);
    helper_add(f, 1, 2.25, 4.0);
    helper_add(f, TCLOD_NONE, 1.0, 1.0);
    helper_add(f, 3, 1.0, 4.0);
    warm = helper_selector(f->scene, &f->model, 1);
    select_frame(warm, 5.0, 0, &st);
    helper_assert_cut(warm, first, 2);
    assert_totals(&st, 3.25, 5.0);
    f->model.benefit[4] = 5.0;
    assert_true(exact_optimum(&f->model, 5.0, NULL) == 6.0);
    select_frame(warm, 5.0, 0, &st);
    helper_assert_cut(warm, best, 2);
    helper_check_result(warm, &f->model, &st, 5.0, 0);
    assert_totals(&st, 6.0, 5.0);
    assert_int_equal(st.decrements, 2);
    tclod_selector_destroy(warm);
}

/* Warm solves over models that change every frame; `audited`: with the
 * default fallback and enough frames for audits (a cold solve after every
 * 32nd warm one, the same nodes asked at most once in all), else warm only. */
static void warm_starts_over_changing_models(helper_fixture *f, uint32_t lookahead, int audited) {
    tclod_selector *sel;
    table_rng rng;
    int frame, cold_kept = 0;
    random_scene(f, 99, 300, 8);
    table_rng_seed(&rng, 5);
    if (audited) {
        tclod_selector_desc d;
        tclod_selector_desc_default(&d);
        table_callbacks(&f->model, &d.callbacks);
        d.greedy.lookahead = lookahead;
        assert_int_equal(tclod_selector_create(f->scene, &d, NULL, &sel), TCLOD_OK);
    } else {
        sel = lookahead_selector(f->scene, &f->model, 1, lookahead);
    }
    for (frame = 0; frame < (audited ? 200 : 30); ++frame) {
        double lo = table_roots_cost(&f->model) * (1.0 + 1e-12);
        double hi = table_leaves_cost(&f->model);
        double budget = table_rng_uniform(&rng, lo, hi);
        tclod_stats st;
        uint32_t i;
        table_reset_counts(&f->model);
        select_frame(sel, budget, 0, &st);
        helper_check_result(sel, &f->model, &st, budget, 0);
        assert_true(table_max_calls(&f->model) <= 1);
        assert_int_equal(st.evaluations, table_asked_nodes(&f->model));
        cold_kept += (st.notes & TCLOD_NOTE_COLD_FALLBACK) != 0;
        /* Between frames: every value scaled by its own factor in [0.5, 2)
         * (diminishing returns no longer hold), some nodes turn invisible. */
        for (i = 0; i < f->model.count; ++i) {
            f->model.benefit[i] *= table_rng_uniform(&rng, 0.5, 2.0);
            f->model.cost[i] *= table_rng_uniform(&rng, 0.5, 2.0);
            if (table_rng_below(&rng, 50) == 0)
                f->model.benefit[i] = 0.0;
            else if (f->model.benefit[i] == 0.0)
                f->model.benefit[i] = 1.0;
        }
    }
    if (audited && lookahead == 0)
        assert_true(cold_kept >= 1); /* here 1 of the 6 audits: both outcomes met */
    else
        assert_int_equal(cold_kept, 0); /* no audit with a lookahead */
    tclod_selector_destroy(sel);
}

static void warm_start_after_model_changes_stays_feasible(void **state) {
    warm_starts_over_changing_models((helper_fixture *)*state, 0, 0);
}

/* The same with audits: every frame stays a valid selection within its
 * budget whichever cut an audit keeps. */
static void audited_warm_starts_after_model_changes_stay_feasible(void **state) {
    warm_starts_over_changing_models((helper_fixture *)*state, 0, 1);
}

/* With a lookahead no solve is audited (docs/greedy.md). */
static void warm_starts_with_lookahead_and_fallback_stay_feasible(void **state) {
    warm_starts_over_changing_models((helper_fixture *)*state, 3, 1);
}

/* Decrements collapse a level reached by a lookahead increment into the level
 * above it, which the increment passed over. */
static void warm_start_with_lookahead_after_model_changes_stays_feasible(void **state) {
    warm_starts_over_changing_models((helper_fixture *)*state, 3, 0);
}

static void a_warm_start_swaps_past_the_balance_point_to_fill_the_room(void **state) {
    helper_fixture *f = (helper_fixture *)*state;
    /* A 0 (10, 2) -> A1 2 (14, 4): Δb 4, Δc 2, ratio 2. B 1 (10, 2) -> B1 3
     * (13, 3): Δb 3, Δc 1, ratio 3. Budget 6, roots cost 4. The plain pass
     * (restarts off) takes B's increment, and A's needs 2 where 1 is left:
     * {A, B1}, b 23, c 5. A warm solve of the same frame: A's ratio, 2, is
     * below the loss ratio of collapsing B1, 3, so [MB97]'s balance holds and
     * no exchange of equal cost gains. But A lacks only 1, less than its
     * cost: collapsing B1 frees that 1 for a loss of 3, and A gains 4.
     * {A1, B}: b 24, c 6, the optimum ({A1, B1} costs 7). The swap back, B
     * for A1's collapse, would lose 4 for 3. */
    static const tclod_id plain[] = {0, 3};
    static const tclod_id swapped[] = {1, 2};
    tclod_selector *sel;
    tclod_stats st;
    helper_add(f, TCLOD_NONE, 10.0, 2.0);
    helper_add(f, TCLOD_NONE, 10.0, 2.0);
    helper_add(f, 0, 14.0, 4.0);
    helper_add(f, 1, 13.0, 3.0);
    sel = tuned_selector(f->scene, &f->model, 1, 0, 0);
    select_frame(sel, 6.0, 0, &st); /* the first solve is cold */
    helper_assert_cut(sel, plain, 2);
    assert_totals(&st, 23.0, 5.0);
    select_frame(sel, 6.0, 0, &st);
    helper_assert_cut(sel, swapped, 2);
    assert_totals(&st, 24.0, 6.0);
    assert_int_equal(st.increments, 1);
    assert_int_equal(st.decrements, 1);
    select_frame(sel, 6.0, 0, &st); /* and stays */
    helper_assert_cut(sel, swapped, 2);
    assert_int_equal(st.decrements, 0);
    tclod_selector_destroy(sel);
}

static void warm_start_evaluates_the_frontier_not_the_path_from_the_roots(void **state) {
    helper_fixture *f = (helper_fixture *)*state;
    /* 100 chains of 20 levels (object o's level k is node 20 o + k); the
     * budget is what every object costs at level 8, so the cut lies deep in
     * the chains. A cold solve evaluates every level from the root down to
     * one below the cut's: k + 2 nodes for an object cut at level k < 19.
     * On the same frame a warm solve keeps the cut, but for the swaps that
     * fill the room its misfits leave (at most 16 tried past the balance
     * point), and evaluates only its frontier: the cut node, its child (to
     * key its increment) and its parent (collapsible: its only child is in
     * the cut), at most 3 per object. A tried swap's collapse also evaluates
     * the grandparent it makes collapsible; the margin of 16 bounds those
     * here, far below the path the cold solve walks. */
    tclod_selector *cold, *warm;
    tclod_stats st_cold, st_warm;
    table_rng rng;
    const tclod_id *ids;
    size_t n, i;
    uint32_t path = 0, frontier = 0, o;
    double budget = 0.0;
    table_rng_seed(&rng, 11);
    assert_int_equal(table_chains(&f->model, f->scene, &rng, 100, 20, 0.0f), TCLOD_OK);
    for (o = 0; o < 100u; ++o)
        budget += f->model.cost[20u * o + 8u];
    cold = helper_selector(f->scene, &f->model, 0);
    warm = helper_selector(f->scene, &f->model, 1);
    select_frame(cold, budget, 0, &st_cold);
    assert_int_equal(tclod_selector_cut(cold, &ids, &n), TCLOD_OK);
    assert_int_equal(n, 100);
    for (i = 0; i < n; ++i) {
        uint32_t k = ids[i] % 20u;
        assert_true(k > 0u && k < 19u); /* deep in every chain, never at an end */
        path += k + 2u;
        frontier += 3u;
    }
    assert_int_equal(st_cold.evaluations, path);
    select_frame(warm, budget, 0, &st_warm); /* the first solve is cold */
    assert_int_equal(st_warm.evaluations, path);
    table_reset_counts(&f->model);
    select_frame(warm, budget, 0, &st_warm);
    helper_check_result(warm, &f->model, &st_warm, budget, 0);
    assert_true(st_warm.benefit >= st_cold.benefit);
    assert_int_equal(st_warm.evaluations, table_asked_nodes(&f->model));
    assert_true(st_warm.evaluations <= frontier + 16u);
    assert_true(2u * st_warm.evaluations < path);
    tclod_selector_destroy(warm);
    tclod_selector_destroy(cold);
}

static void warm_start_after_the_scene_grew_includes_new_nodes(void **state) {
    helper_fixture *f = (helper_fixture *)*state;
    /* Frame 1: roots 0 (1, 1) and 1 (2, 1). Then a new root 2 (5, 1) and a
     * child 3 (4, 2) of root 0 (Δb 3, Δc 1) are added. Frame 2 with an
     * unlimited budget must show both: {3, 1, 2}. */
    static const tclod_id before[] = {0, 1};
    static const tclod_id after[] = {1, 2, 3};
    tclod_selector *sel;
    tclod_stats st;
    helper_add(f, TCLOD_NONE, 1.0, 1.0);
    helper_add(f, TCLOD_NONE, 2.0, 1.0);
    sel = helper_selector(f->scene, &f->model, 1);
    select_frame(sel, INFINITY, 0, &st);
    helper_assert_cut(sel, before, 2);
    helper_add(f, TCLOD_NONE, 5.0, 1.0);
    helper_add(f, 0, 4.0, 2.0);
    select_frame(sel, INFINITY, 0, &st);
    helper_assert_cut(sel, after, 3);
    assert_totals(&st, 11.0, 4.0);
    tclod_selector_destroy(sel);
}

static void warm_start_recovers_dropped_roots_when_the_budget_returns(void **state) {
    helper_fixture *f = (helper_fixture *)*state;
    /* 20 chains of 4 levels. Unlimited budget: the 20 finest levels. Budget
     * 0: every root costs > 0, so all 20 are dropped and nothing is listed.
     * Unlimited again: back to the 20 finest levels (ids 4 o + 3). */
    tclod_id finest[20];
    tclod_selector *sel;
    tclod_stats st;
    table_rng rng;
    int o;
    table_rng_seed(&rng, 21);
    assert_int_equal(table_chains(&f->model, f->scene, &rng, 20, 4, 0.0f), TCLOD_OK);
    for (o = 0; o < 20; ++o)
        finest[o] = (tclod_id)(4 * o + 3);
    sel = helper_selector(f->scene, &f->model, 1);
    select_frame(sel, INFINITY, 0, &st);
    helper_assert_cut(sel, finest, 20);
    select_frame(sel, 0.0, 0, &st);
    helper_assert_cut(sel, NULL, 0);
    assert_int_equal(st.dropped_roots, 20);
    assert_true(st.benefit == 0.0 && st.cost == 0.0);
    select_frame(sel, INFINITY, 0, &st);
    helper_assert_cut(sel, finest, 20);
    assert_int_equal(st.dropped_roots, 0);
    assert_int_equal(st.stop_reason, TCLOD_STOP_FINEST);
    tclod_selector_destroy(sel);
}

static void limits_never_stop_a_warm_start_over_budget(void **state) {
    helper_fixture *f = (helper_fixture *)*state;
    /* 50 chains of 6 levels refined to the finest, then the budget falls to
     * 30% of the leaves' cost with a limit of one iteration, or of 1 ns: the
     * decrements back within budget must still run. */
    tclod_selector *sel;
    tclod_frame frame;
    tclod_stats st;
    table_rng rng;
    double budget;
    int limit;
    table_rng_seed(&rng, 22);
    assert_int_equal(table_chains(&f->model, f->scene, &rng, 50, 6, 0.0f), TCLOD_OK);
    budget = table_leaves_cost(&f->model) * 0.3;
    sel = helper_selector(f->scene, &f->model, 1);
    for (limit = 0; limit < 2; ++limit) {
        select_frame(sel, INFINITY, 0, &st);
        frame = helper_frame(NULL, budget);
        if (limit == 0)
            frame.max_iterations = 1;
        else
            frame.solve_seconds = 1e-9;
        assert_int_equal(tclod_select(sel, &frame, &st), TCLOD_OK);
        helper_check_result(sel, &f->model, &st, budget, 0);
        assert_true(st.decrements > 0);
    }
    tclod_selector_destroy(sel);
}

static void iteration_limit_stops_with_a_feasible_result(void **state) {
    helper_fixture *f = (helper_fixture *)*state;
    static const uint32_t limits[] = {1, 5, 50};
    tclod_selector *cold, *warm;
    double budget;
    size_t i;
    random_scene(f, 1234, 2000, 20);
    budget = table_roots_cost(&f->model) +
             0.3 * (table_leaves_cost(&f->model) - table_roots_cost(&f->model));
    cold = helper_selector(f->scene, &f->model, 0);
    warm = helper_selector(f->scene, &f->model, 1);
    for (i = 0; i < sizeof limits / sizeof limits[0]; ++i) {
        tclod_stats st;
        select_frame(cold, budget, limits[i], &st);
        helper_check_result(cold, &f->model, &st, budget, 0);
        assert_int_equal(st.stop_reason, TCLOD_STOP_ITERATIONS);
        assert_int_equal(st.iterations, limits[i]);
        assert_true(st.increments <= limits[i]);
        /* The warm budgets rise from frame to frame, so no decrement is forced
         * (those always run, whatever the limit) and the limit holds. */
        select_frame(warm, budget * (0.7 + 0.1 * (double)i), limits[i], &st);
        helper_check_result(warm, &f->model, &st, budget * (0.7 + 0.1 * (double)i), 0);
        assert_true(st.iterations <= limits[i]);
    }
    tclod_selector_destroy(warm);
    tclod_selector_destroy(cold);
}

static void time_limit_stops_with_a_feasible_result(void **state) {
    helper_fixture *f = (helper_fixture *)*state;
    /* 2000 chains of 10 levels: 18000 increments to take with this budget
     * minus the few that do not fit; 1 ns cannot be enough. */
    tclod_selector *sel;
    tclod_frame frame;
    tclod_stats st;
    table_rng rng;
    double budget;
    table_rng_seed(&rng, 3);
    assert_int_equal(table_chains(&f->model, f->scene, &rng, 2000, 10, 0.0f), TCLOD_OK);
    budget = table_leaves_cost(&f->model) * 0.9;
    sel = helper_selector(f->scene, &f->model, 0);
    frame = helper_frame(NULL, budget);
    frame.solve_seconds = 1e-9;
    assert_int_equal(tclod_select(sel, &frame, &st), TCLOD_OK);
    helper_check_result(sel, &f->model, &st, budget, 0);
    assert_int_equal(st.stop_reason, TCLOD_STOP_TIME);
    assert_true(st.iterations < 18000);
    assert_true(st.solve_seconds >= 0.0);
    tclod_selector_destroy(sel);
}

static void unlimited_budget_refines_everything_to_the_finest_level(void **state) {
    helper_fixture *f = (helper_fixture *)*state;
    tclod_selector *sel;
    tclod_stats st;
    random_scene(f, 77, 500, 10);
    sel = helper_selector(f->scene, &f->model, 0);
    select_frame(sel, INFINITY, 0, &st);
    assert_int_equal(st.stop_reason, TCLOD_STOP_FINEST);
    helper_check_result(sel, &f->model, &st, INFINITY, 0);
    /* The finest cut lists exactly the leaves. */
    {
        tclod_id *cut = (tclod_id *)malloc(500 * sizeof *cut);
        unsigned char has_child[500] = {0};
        size_t n, at = 0;
        uint32_t i;
        assert_non_null(cut);
        for (i = 0; i < 500; ++i)
            if (f->model.parent[i] != TCLOD_NONE)
                has_child[f->model.parent[i]] = 1;
        n = helper_sorted_cut(sel, cut, 500);
        for (i = 0; i < 500; ++i)
            if (!has_child[i]) {
                assert_true(at < n);
                assert_int_equal(cut[at], i);
                at++;
            }
        assert_int_equal(at, n);
        free(cut);
    }
    tclod_selector_destroy(sel);
}

static void budget_stop_is_reported_when_an_increment_does_not_fit(void **state) {
    helper_fixture *f = (helper_fixture *)*state;
    tclod_selector *sel;
    tclod_stats st;
    random_scene(f, 78, 500, 10);
    sel = helper_selector(f->scene, &f->model, 0);
    select_frame(sel, table_leaves_cost(&f->model) * 0.5, 0, &st);
    helper_check_result(sel, &f->model, &st, table_leaves_cost(&f->model) * 0.5, 0);
    assert_int_equal(st.stop_reason, TCLOD_STOP_BUDGET);
    assert_true(st.iterations > st.increments);
    tclod_selector_destroy(sel);
}

static void callbacks_are_called_at_most_once_per_node_per_solve(void **state) {
    helper_fixture *f = (helper_fixture *)*state;
    tclod_selector *sel[2];
    table_rng rng;
    int frame, w;
    random_scene(f, 2024, 600, 15);
    table_rng_seed(&rng, 8);
    sel[0] = helper_selector(f->scene, &f->model, 0);
    sel[1] = helper_selector(f->scene, &f->model, 1);
    for (frame = 0; frame < 20; ++frame) {
        double budget = table_rng_uniform(&rng, 0.0, table_leaves_cost(&f->model) * 1.2);
        uint32_t limit = frame % 3 == 0 ? 1 + table_rng_below(&rng, 100) : 0;
        for (w = 0; w < 2; ++w) {
            tclod_stats st;
            table_reset_counts(&f->model);
            select_frame(sel[w], budget, limit, &st);
            helper_check_result(sel[w], &f->model, &st, budget, 1);
            if (table_max_calls(&f->model) > 1)
                fail_msg("frame %d %s: a callback ran %u times for one node", frame,
                         w ? "warm" : "cold", table_max_calls(&f->model));
            assert_int_equal(f->model.unknown_ids, 0);
            assert_int_equal(st.evaluations, table_asked_nodes(&f->model));
        }
    }
    tclod_selector_destroy(sel[1]);
    tclod_selector_destroy(sel[0]);
}

static void greedy_ignores_smooth_objects(void **state) {
    helper_fixture *f = (helper_fixture *)*state;
    const float bounds[4] = {0.0f, 0.0f, -10.0f, 1.0f};
    tclod_selector *sel;
    tclod_stats st;
    tclod_id smooth;
    static const tclod_id root[] = {0};
    helper_add(f, TCLOD_NONE, 1.0, 1.0);
    assert_int_equal(tclod_scene_add_smooth(f->scene, bounds, &smooth), TCLOD_OK);
    sel = helper_selector(f->scene, &f->model, 0);
    select_frame(sel, 10.0, 0, &st);
    helper_assert_cut(sel, root, 1);
    assert_true(tclod_selector_resolution(sel, smooth) == 0.0);
    assert_int_equal(f->model.unknown_ids, 0);
    tclod_selector_destroy(sel);
}

static void deep_chain_is_refined_to_its_last_level(void **state) {
    helper_fixture *f = (helper_fixture *)*state;
    /* One object with 200000 levels: level k has benefit k + 1 and cost
     * (k + 1)², so increment k gains 1 for 2k + 1: ratios fall. With no
     * budget limit the last level is selected after 199999 increments. */
    enum { levels = 200000 };
    tclod_selector *sel;
    tclod_stats st;
    tclod_id parent = TCLOD_NONE;
    static tclod_id last[1] = {levels - 1};
    uint32_t k;
    for (k = 0; k < levels; ++k)
        parent = helper_add(f, parent, (double)k + 1.0, ((double)k + 1.0) * ((double)k + 1.0));
    sel = helper_selector(f->scene, &f->model, 0);
    select_frame(sel, INFINITY, 0, &st);
    helper_assert_cut(sel, last, 1);
    assert_int_equal(st.increments, levels - 1);
    assert_int_equal(st.stop_reason, TCLOD_STOP_FINEST);
    tclod_selector_destroy(sel);
}

/* Three objects, ids in creation order:
 *   P0 0 (b 1, c 1) -> P3 3 (1.5, 3) -> P4 4 (9, 5)
 *   Q0 1 (1, 1) -> Q5 5 (3, 3);   R0 2 (1, 1) -> R6 6 (3, 3)
 * Roots: b 3, c 3; budget 7 leaves 4. One-level increments: P0 gains 0.5 for
 * 2 (ratio 0.25), Q0 and R0 gain 2 for 2 (ratio 1). Without lookahead Q0 and
 * R0 go first and spend the 4: {P0, Q5, R6}, b 1 + 3 + 3 = 7, c 7; P0's
 * increment no longer fits, and taken alone it would give only 3.5. With
 * lookahead 1, P0's increment may reach P4: gain 9 - 1 = 8 for 5 - 1 = 4,
 * ratio 2, first in line: {P4, Q0, R0}, b 9 + 1 + 1 = 11, c 5 + 1 + 1 = 7,
 * after which neither 2-cost increment fits. 11 is the optimum: the other
 * ways to spend 4 are Q0 and R0 (gain 4) or P0 to P3 and one of them (2.5). */
static void lookahead_finds_a_refinement_whose_gain_comes_at_its_second_level(void **state) {
    helper_fixture *f = (helper_fixture *)*state;
    static const tclod_id one_level[] = {0, 5, 6};
    static const tclod_id reached[] = {1, 2, 4};
    tclod_selector *sel;
    tclod_stats st;
    helper_add(f, TCLOD_NONE, 1.0, 1.0); /* 0 P0 */
    helper_add(f, TCLOD_NONE, 1.0, 1.0); /* 1 Q0 */
    helper_add(f, TCLOD_NONE, 1.0, 1.0); /* 2 R0 */
    helper_add(f, 0, 1.5, 3.0);          /* 3 P3 */
    helper_add(f, 3, 9.0, 5.0);          /* 4 P4 */
    helper_add(f, 1, 3.0, 3.0);          /* 5 Q5 */
    helper_add(f, 2, 3.0, 3.0);          /* 6 R6 */
    assert_true(exact_optimum(&f->model, 7.0, NULL) == 11.0);

    sel = lookahead_selector(f->scene, &f->model, 0, 0);
    select_frame(sel, 7.0, 0, &st);
    helper_assert_cut(sel, one_level, 3);
    assert_totals(&st, 7.0, 7.0);
    assert_int_equal(st.increments, 2);
    tclod_selector_destroy(sel);

    sel = lookahead_selector(f->scene, &f->model, 0, 1);
    table_reset_counts(&f->model);
    select_frame(sel, 7.0, 0, &st);
    helper_assert_cut(sel, reached, 3);
    assert_totals(&st, 11.0, 7.0);
    assert_int_equal(st.increments, 1);
    assert_int_equal(st.stop_reason, TCLOD_STOP_BUDGET);
    assert_true(table_max_calls(&f->model) <= 1);
    assert_int_equal(st.evaluations, 7); /* every node: P3 and P4 from P0's increment */
    tclod_selector_destroy(sel);
}

/* One chain X0 (b 1, c 1), X1 (2, 2), X2 (3, 3), X3 (40, 4). From X0, X1 and
 * X2 both gain 1 per unit of cost and X3 gains 39 for 3 (ratio 13). The first
 * increment (max_iterations 1) goes to X1 without lookahead; with lookahead 1
 * it sees X1 and X2, equal, and takes the shallower, X1; lookahead 2 reaches
 * X3: b 40, c 4. */
static void lookahead_takes_the_best_level_within_reach_and_the_shallower_of_equals(void **state) {
    helper_fixture *f = (helper_fixture *)*state;
    static const tclod_id x1[] = {1};
    static const tclod_id x3[] = {3};
    tclod_selector *sel;
    tclod_stats st;
    uint32_t lookahead;
    helper_add(f, TCLOD_NONE, 1.0, 1.0); /* 0 X0 */
    helper_add(f, 0, 2.0, 2.0);          /* 1 X1 */
    helper_add(f, 1, 3.0, 3.0);          /* 2 X2 */
    helper_add(f, 2, 40.0, 4.0);         /* 3 X3 */
    for (lookahead = 0; lookahead <= 2; ++lookahead) {
        sel = lookahead_selector(f->scene, &f->model, 0, lookahead);
        select_frame(sel, INFINITY, 1, &st);
        assert_int_equal(st.increments, 1);
        if (lookahead < 2) {
            helper_assert_cut(sel, x1, 1);
            assert_totals(&st, 2.0, 2.0);
        } else {
            helper_assert_cut(sel, x3, 1);
            assert_totals(&st, 40.0, 4.0);
        }
        tclod_selector_destroy(sel);
    }
}

/* With diminishing returns the next level always has the best ratio: the
 * hand-worked order is the same with lookahead (S's increment could reach
 * S2, gaining 7 - 3 = 4 for 7 - 1 = 6, ratio 2/3 < 1.5). */
static void lookahead_keeps_the_order_under_diminishing_returns(void **state) {
    helper_fixture *f = (helper_fixture *)*state;
    static const tclod_id k1[] = {1, 2, 7};
    static const tclod_id k2[] = {1, 5, 6, 7};
    static const tclod_id k3[] = {1, 5, 6, 8};
    static const tclod_id k4[] = {3, 4, 5, 6, 8};
    const tclod_id *after[] = {k1, k2, k3, k4};
    const size_t sizes[] = {3, 4, 4, 5};
    tclod_selector *sel;
    tclod_stats st;
    uint32_t k;
    build_order_tree(f);
    sel = lookahead_selector(f->scene, &f->model, 0, 3);
    for (k = 1; k <= 4; ++k) {
        select_frame(sel, INFINITY, k, &st);
        helper_assert_cut(sel, after[k - 1], sizes[k - 1]);
        assert_int_equal(st.increments, k);
    }
    tclod_selector_destroy(sel);
}

/* Three hierarchies, ids in creation order (b, c):
 *   A 0 (10, 10) -> A1 3 (5, 8) -> A1a 7 (15, 6), A1b 8 (15, 6) -> A1b1 11 (21, 8)
 *                -> A2 4 (5, 8) -> A2a 9 (7, 5), A2b 10 (7, 5)
 *   B 1 (4, 4) -> B1 5 (8, 6);   C 2 (4, 4) -> C1 6 (8, 6)
 * Roots: b 18, c 18. One level down A's increment gains 5 + 5 - 10 = 0 for
 * 16 - 10 = 6: no candidate, so without lookahead only B and C refine (each
 * +4 for +2), whatever the search: b 26, c 22. A1's own step gains 25 for 4,
 * A2's 9 for 2, A1b's 6 for 2. With lookahead 1 A's increment may replace A
 * by any cut of its subtree down to the grandchildren, (Δc, Δb):
 *   {A1, A2} (6, 0), {A1a, A1b, A2} (10, 25), {A1, A2a, A2b} (8, 9),
 *   {A1a, A1b, A2a, A2b} (12, 34);
 * the best ratio is the last one's, 34 / 12 = 2.83 > 2. Budget 30 leaves 12,
 * which it takes whole: b 52, c 30; then nothing fits. Budget 32 leaves 2
 * more, for A1b's step (ratio 3, ahead of B and C): b 58, c 32. Budget 28
 * leaves 10: the jump does not fit, and A's increment becomes the cut that
 * gains most among the vertices of the hull of these points that fit. The
 * hull from (6, 0) runs to (10, 25) (slope 6.25), then to (12, 34) (4.5);
 * (8, 9) lies below it. So {A1a, A1b, A2}, ratio 2.5, still ahead of B and C:
 * b 18 + 25 = 43, c 28. All three are the optimum (the brute force agrees).
 * They need neither the safeguard nor the search: without restarts they come
 * too. */
static void tree_lookahead_finds_a_refinement_whose_gain_comes_below_its_children(void **state) {
    helper_fixture *f = (helper_fixture *)*state;
    static const tclod_id one_level[] = {0, 5, 6};
    static const tclod_id whole[] = {1, 2, 7, 8, 9, 10};
    static const tclod_id deeper[] = {1, 2, 7, 9, 10, 11};
    static const tclod_id refit[] = {1, 2, 4, 7, 8};
    static const double budgets[3] = {30.0, 32.0, 28.0}, benefits[3] = {52.0, 58.0, 43.0};
    static const tclod_id *const cuts[3] = {whole, deeper, refit};
    static const size_t sizes[3] = {6, 6, 5};
    static const uint32_t restarts[2] = {0, 32}; /* 32: the default */
    tclod_selector *plain, *look;
    tclod_stats st;
    int k, r;
    helper_add(f, TCLOD_NONE, 10.0, 10.0); /* 0 A */
    helper_add(f, TCLOD_NONE, 4.0, 4.0);   /* 1 B */
    helper_add(f, TCLOD_NONE, 4.0, 4.0);   /* 2 C */
    helper_add(f, 0, 5.0, 8.0);            /* 3 A1 */
    helper_add(f, 0, 5.0, 8.0);            /* 4 A2 */
    helper_add(f, 1, 8.0, 6.0);            /* 5 B1 */
    helper_add(f, 2, 8.0, 6.0);            /* 6 C1 */
    helper_add(f, 3, 15.0, 6.0);           /* 7 A1a */
    helper_add(f, 3, 15.0, 6.0);           /* 8 A1b */
    helper_add(f, 4, 7.0, 5.0);            /* 9 A2a */
    helper_add(f, 4, 7.0, 5.0);            /* 10 A2b */
    helper_add(f, 8, 21.0, 8.0);           /* 11 A1b1 */
    plain = tuned_selector(f->scene, &f->model, 0, 0, TCLOD_MAX_RESTARTS);
    for (k = 0; k < 3; ++k) {
        assert_true(exact_optimum(&f->model, budgets[k], NULL) == benefits[k]);
        select_frame(plain, budgets[k], 0, &st);
        helper_assert_cut(plain, one_level, 3);
        assert_totals(&st, 26.0, 22.0);
        for (r = 0; r < 2; ++r) {
            look = tuned_selector(f->scene, &f->model, 0, 1, restarts[r]);
            table_reset_counts(&f->model);
            select_frame(look, budgets[k], 0, &st);
            helper_assert_cut(look, cuts[k], sizes[k]);
            assert_totals(&st, benefits[k], budgets[k]);
            assert_true(table_max_calls(&f->model) <= 1);
            assert_int_equal(st.evaluations, 12); /* A's key evaluates its subtree */
            tclod_selector_destroy(look);
        }
    }
    tclod_selector_destroy(plain);
}

/* A's hierarchy of the test above alone: A 0 (10, 10) -> A1 1 (5, 8),
 * A2 2 (5, 8); A1 -> A1a 3, A1b 4 (15, 6 each); A2 -> A2a 5, A2b 6 (7, 5
 * each). With lookahead 1 A's increment is the jump to the four grandchildren
 * (+34 for +12). Budget 20 leaves 10: the jump does not fit, but its cheapest
 * cut, A's children (+6), does, so the fill goes on and the increment becomes
 * {A1a, A1b, A2} (+25 for +10): b 35, c 20. Budget 15 leaves 5, less than any
 * cut of A's costs: A alone, b 10. No restarts: the plain pass does it. */
static void a_lookahead_increment_too_dear_gives_way_to_the_best_cut_that_fits(void **state) {
    helper_fixture *f = (helper_fixture *)*state;
    static const tclod_id refit[] = {2, 3, 4};
    static const tclod_id alone[] = {0};
    tclod_selector *sel;
    tclod_stats st;
    helper_add(f, TCLOD_NONE, 10.0, 10.0); /* 0 A */
    helper_add(f, 0, 5.0, 8.0);            /* 1 A1 */
    helper_add(f, 0, 5.0, 8.0);            /* 2 A2 */
    helper_add(f, 1, 15.0, 6.0);           /* 3 A1a */
    helper_add(f, 1, 15.0, 6.0);           /* 4 A1b */
    helper_add(f, 2, 7.0, 5.0);            /* 5 A2a */
    helper_add(f, 2, 7.0, 5.0);            /* 6 A2b */
    sel = tuned_selector(f->scene, &f->model, 0, 1, 0);
    select_frame(sel, 20.0, 0, &st);
    helper_assert_cut(sel, refit, 3);
    assert_totals(&st, 35.0, 20.0);
    select_frame(sel, 15.0, 0, &st);
    helper_assert_cut(sel, alone, 1);
    assert_totals(&st, 10.0, 10.0);
    tclod_selector_destroy(sel);
}

/* P 0 (b 1, c 1) -> P1 2 (3, 2): +2 for +1. Q 1 (1, 1) -> Qa 3, Qb 4 (2.5,
 * 2.5 each): +4 for +4; Qa -> Qa1 5 and Qb -> Qb1 6 (10, 5.5 each): +7.5 for
 * +3 each. Q's cuts: {Qa, Qb} (+4 for +4, ratio 1), one of them refined
 * (+11.5 for +7), both (+19 for +10, ratio 1.9), so with lookahead 1 Q's
 * increment is the last, behind P's (2). Budget 6 leaves 4: P goes first,
 * then Q's increment misfits and no cut of Q fits the 3 left: b 4, c 3. The
 * optimum, 6, leaves P and refines Q one level (c 6). The search finds it: it
 * forces Q's increment, which does not fit as it is, so the pass takes the
 * cut of Q that fits the 4 left, {Qa, Qb}; then P's step no longer fits. */
static void the_search_forces_the_cut_that_fits_of_a_lookahead_increment(void **state) {
    helper_fixture *f = (helper_fixture *)*state;
    static const tclod_id blocked[] = {1, 2};
    static const tclod_id best[] = {0, 3, 4};
    helper_add(f, TCLOD_NONE, 1.0, 1.0); /* 0 P */
    helper_add(f, TCLOD_NONE, 1.0, 1.0); /* 1 Q */
    helper_add(f, 0, 3.0, 2.0);          /* 2 P1 */
    helper_add(f, 1, 2.5, 2.5);          /* 3 Qa */
    helper_add(f, 1, 2.5, 2.5);          /* 4 Qb */
    helper_add(f, 3, 10.0, 5.5);         /* 5 Qa1 */
    helper_add(f, 4, 10.0, 5.5);         /* 6 Qb1 */
    assert_true(exact_optimum(&f->model, 6.0, NULL) == 6.0);
    {
        tclod_selector *one = tuned_selector(f->scene, &f->model, 0, 1, 1);
        tclod_selector *search = tuned_selector(f->scene, &f->model, 0, 1, 32);
        tclod_stats st;
        select_frame(one, 6.0, 0, &st);
        helper_assert_cut(one, blocked, 2);
        assert_totals(&st, 4.0, 3.0);
        select_frame(search, 6.0, 0, &st);
        helper_assert_cut(search, best, 3);
        assert_totals(&st, 6.0, 6.0);
        tclod_selector_destroy(one);
        tclod_selector_destroy(search);
    }
}

/* The adversarial instance of the half-optimum bound with a refinement whose
 * first step gains little: A 0 (b 0.125, c 0.125) -> A1 1 (1.375, 1.125),
 * +1.25 for +1; B 2 (0.125, 0.125) -> B1 3 (0.625, 50.125), +0.5 for +50 ->
 * B2 4 (100.125, 100.125), +100 for +100 from B. Budget 100.75. With
 * lookahead 1 B's increment reaches B2 (ratio 1), behind A's (1.25): A1 is
 * taken, then B's jump misfits and gives way to B1, which fits: b 2, c 51.25.
 * T(B) alone, {A, B2}, costs 100.25 and gains 100.25, so the safeguard's pass
 * (one restart) reaches it, the optimum. Without restarts: 2. */
static void the_safeguard_keeps_a_lookahead_within_half_of_the_optimum(void **state) {
    helper_fixture *f = (helper_fixture *)*state;
    static const tclod_id refit[] = {1, 3};
    static const tclod_id best[] = {0, 4};
    tclod_selector *sel;
    tclod_stats st;
    helper_add(f, TCLOD_NONE, 0.125, 0.125); /* 0 A */
    helper_add(f, 0, 1.375, 1.125);          /* 1 A1 */
    helper_add(f, TCLOD_NONE, 0.125, 0.125); /* 2 B */
    helper_add(f, 2, 0.625, 50.125);         /* 3 B1 */
    helper_add(f, 3, 100.125, 100.125);      /* 4 B2 */
    assert_true(exact_optimum(&f->model, 100.75, NULL) == 100.25);
    sel = tuned_selector(f->scene, &f->model, 0, 1, 0);
    select_frame(sel, 100.75, 0, &st);
    helper_assert_cut(sel, refit, 2);
    assert_totals(&st, 2.0, 51.25);
    tclod_selector_destroy(sel);
    sel = tuned_selector(f->scene, &f->model, 0, 1, 1);
    select_frame(sel, 100.75, 0, &st);
    helper_assert_cut(sel, best, 2);
    assert_totals(&st, 100.25, 100.25);
    tclod_selector_destroy(sel);
}

/* One chain X0 (b 1, c 1), X1 (1.5, 2), X2 (5, 3), X3 (9, 5). From X0 the
 * levels gain 0.5 for 1, 4 for 2 and 8 for 4: X2 and X3 share the best ratio,
 * 2. Dinkelbach's method starts at X1's ratio, 0.5, where X3 is the best
 * (9 - 0.5 x 5 = 6.5 against 5 - 1.5 = 3.5), so the ratio it finds first
 * belongs to the deeper of the two; at 2 both give b - 2c = -1. The increment
 * takes the shallower, X2: the next vertex of the chain's hull. */
static void lookahead_takes_the_shallower_of_equal_best_ratios_found_from_below(void **state) {
    helper_fixture *f = (helper_fixture *)*state;
    static const tclod_id x2[] = {2};
    tclod_selector *sel;
    tclod_stats st;
    helper_add(f, TCLOD_NONE, 1.0, 1.0); /* 0 X0 */
    helper_add(f, 0, 1.5, 2.0);          /* 1 X1 */
    helper_add(f, 1, 5.0, 3.0);          /* 2 X2 */
    helper_add(f, 2, 9.0, 5.0);          /* 3 X3 */
    sel = lookahead_selector(f->scene, &f->model, 0, 2);
    select_frame(sel, INFINITY, 1, &st);
    assert_int_equal(st.increments, 1);
    helper_assert_cut(sel, x2, 1);
    assert_totals(&st, 5.0, 3.0);
    tclod_selector_destroy(sel);
}

/* Random hierarchies of `nodes` nodes and `roots` roots whose returns need
 * not diminish (TABLE_RISING): every increment gains and costs more, but a
 * step may gain up to 5 times more per cost than its parent's. */
static void rising_scene(table_model *m, tclod_scene **s, uint64_t seed, uint32_t nodes,
                         uint32_t roots) {
    table_rng rng;
    table_rng_seed(&rng, seed);
    table_init(m);
    assert_int_equal(tclod_scene_create(NULL, s), TCLOD_OK);
    assert_int_equal(table_random_hierarchy(m, *s, &rng, nodes, roots, TABLE_RISING), TCLOD_OK);
}

/* With the lookahead reaching every level, an increment is the cut of its
 * node's subtree with the best ratio (Dinkelbach's method, docs/greedy.md):
 * on random single hierarchies whose returns need not diminish, the first
 * increment of a solve (max_iterations 1, no budget limit) gains at the best
 * ratio a brute-force enumeration of every cut below the root finds. */
static void tree_lookahead_takes_the_best_ratio_of_every_cut_below(void **state) {
    uint64_t seed;
    (void)state;
    for (seed = 1; seed <= 300; ++seed) {
        tclod_scene *s = NULL;
        tclod_selector *sel;
        table_model m;
        tclod_stats st;
        double best, ratio;
        rising_scene(&m, &s, seed * 6151u, 2 + (uint32_t)(seed % (EXACT_MAX_NODES - 1u)), 1);
        best = exact_best_ratio(&m, 0);
        assert_true(best > 0.0); /* every increment gains */
        sel = tuned_selector(s, &m, 0, TCLOD_MAX_LOOKAHEAD, 32);
        select_frame(sel, INFINITY, 1, &st);
        assert_int_equal(st.increments, 1);
        ratio = (st.benefit - m.benefit[0]) / (st.cost - m.cost[0]);
        if (!(fabs(ratio - best) <= 1e-9 * best))
            fail_msg("seed %u, %u nodes: first increment's ratio %.17g, best %.17g", (unsigned)seed,
                     (unsigned)m.count, ratio, best);
        tclod_selector_destroy(sel);
        tclod_scene_destroy(s);
        table_free(&m);
    }
}

/* What refining root r's whole hierarchy to its leaves adds to the cost. */
static double refine_whole(const table_model *m, tclod_id r) {
    double sum = 0.0;
    tclod_id v, u;
    for (v = 0; v < m->count; ++v) {
        int leaf = 1;
        for (u = v + 1u; u < m->count && leaf; ++u)
            leaf = m->parent[u] != v;
        for (u = v; m->parent[u] != TCLOD_NONE;)
            u = m->parent[u];
        if (leaf && u == r)
            sum += m->cost[v];
    }
    return sum - m->cost[r];
}

/* The half-optimum bound without diminishing returns (docs/greedy.md): with
 * the lookahead reaching every level and refinements that always cost more,
 * the keys are the slopes of the hulls of the subtrees, a cold pass takes
 * them in falling order up to its first misfit s, the optimum is below the
 * benefit there plus Δb(s), and T(s) fits whenever any one hierarchy refined
 * to its leaves fits with the other roots. Random hierarchies of 6 to 16 nodes
 * (TABLE_RISING), budgets from there up to every leaf's cost, against the
 * brute-force optimum. */
static void tree_lookahead_is_within_half_of_the_optimum_without_diminishing_returns(void **state) {
    enum { seeds = 300, budgets = 4 };
    static double ratios[2][seeds * budgets];
    size_t count = 0;
    uint64_t seed;
    (void)state;
    for (seed = 1; seed <= seeds; ++seed) {
        tclod_scene *s = NULL;
        tclod_selector *look, *plain;
        table_model m;
        table_rng rng;
        uint32_t r, nodes;
        double lo = 0.0, hi;
        int b;
        table_rng_seed(&rng, seed);
        nodes = 6 + table_rng_below(&rng, EXACT_MAX_NODES - 5u);
        rising_scene(&m, &s, seed * 7907u, nodes, 3 + table_rng_below(&rng, 3));
        for (r = 0; r < m.count; ++r)
            if (m.parent[r] == TCLOD_NONE && refine_whole(&m, r) > lo)
                lo = refine_whole(&m, r);
        lo += table_roots_cost(&m);
        hi = table_leaves_cost(&m);
        look = tuned_selector(s, &m, 0, TCLOD_MAX_LOOKAHEAD, 32);
        plain = tuned_selector(s, &m, 0, 0, 32);
        for (b = 0; b < budgets; ++b) {
            /* 1e-12 above: at exactly a cut's cost, whether it fits is decided
             * by rounding, which the order of the sums decides */
            double budget = table_rng_uniform(&rng, lo, hi) * (1.0 + 1e-12);
            double optimum = exact_optimum(&m, budget, NULL);
            tclod_stats st, ref;
            select_frame(plain, budget, 0, &ref);
            table_reset_counts(&m);
            select_frame(look, budget, 0, &st);
            helper_check_result(look, &m, &st, budget, 0);
            assert_true(table_max_calls(&m) <= 1);
            assert_true(optimum > 0.0);
            if (st.benefit > optimum * (1.0 + 1e-12) || st.benefit < 0.5 * optimum)
                fail_msg("seed %u budget %.17g: benefit %.17g, optimum %.17g", (unsigned)seed,
                         budget, st.benefit, optimum);
            ratios[0][count] = ref.benefit / optimum;
            ratios[1][count++] = st.benefit / optimum;
        }
        tclod_selector_destroy(look);
        tclod_selector_destroy(plain);
        tclod_scene_destroy(s);
        table_free(&m);
    }
    qsort(ratios[0], count, sizeof ratios[0][0], compare_doubles);
    qsort(ratios[1], count, sizeof ratios[1][0], compare_doubles);
    print_message("rising returns, %u solves: greedy / optimum median %.4f, min %.4f; with "
                  "lookahead median %.4f, min %.4f\n",
                  (unsigned)count, ratios[0][count / 2], ratios[0][0], ratios[1][count / 2],
                  ratios[1][0]);
}

/* Selectors without and with the deepest lookahead, cold and warm, give the
 * same cuts and benefits at each of these budgets, in this order. */
static void assert_lookahead_changes_nothing(const tclod_scene *s, table_model *m,
                                             const double *budgets, int count, const char *what) {
    enum { CAP = 256 };
    tclod_id a[CAP], b[CAP];
    tclod_selector *sel[4];
    int i, k;
    for (i = 0; i < 4; ++i) /* cold, warm; without and with lookahead */
        sel[i] = tuned_selector(s, m, i % 2, i < 2 ? 0 : TCLOD_MAX_LOOKAHEAD, 32);
    for (k = 0; k < count; ++k) {
        tclod_stats st[4];
        for (i = 0; i < 4; ++i)
            select_frame(sel[i], budgets[k], 0, &st[i]);
        for (i = 0; i < 2; ++i) {
            size_t na = helper_sorted_cut(sel[i], a, CAP),
                   nb = helper_sorted_cut(sel[i + 2], b, CAP);
            if (na != nb || memcmp(a, b, na * sizeof *a) != 0 || st[i].benefit != st[i + 2].benefit)
                fail_msg("%s, budget %.17g (%s): %.17g without lookahead, %.17g with", what,
                         budgets[k], i ? "warm" : "cold", st[i].benefit, st[i + 2].benefit);
        }
    }
    for (i = 0; i < 4; ++i)
        tclod_selector_destroy(sel[i]);
}

/* With diminishing returns no cut below a node's children gains more per
 * cost than they do (its ratio is a weighted mean of theirs and smaller
 * ones), so the lookahead changes no key and no selection: random trees
 * (TABLE_DIMINISHING) and the benchmark's tree families with diminishing
 * returns, whose steps often gain exactly as much per cost as their parent's
 * (a tie that only rounding could break), cold and warm, at budgets that
 * rise and fall, with the default search. */
static void tree_lookahead_changes_nothing_under_diminishing_returns(void **state) {
    double budgets[10];
    uint64_t seed;
    int kind, k;
    (void)state;
    for (seed = 1; seed <= 100; ++seed) {
        tclod_scene *s = NULL;
        table_model m;
        table_rng rng;
        double lo, hi;
        uint32_t nodes, roots;
        table_rng_seed(&rng, seed * 31u);
        table_init(&m);
        assert_int_equal(tclod_scene_create(NULL, &s), TCLOD_OK);
        nodes = 3 + table_rng_below(&rng, 40);
        roots = 1 + table_rng_below(&rng, 3);
        assert_int_equal(table_random_hierarchy(&m, s, &rng, nodes, roots, TABLE_DIMINISHING),
                         TCLOD_OK);
        lo = table_roots_cost(&m) * (1.0 + 1e-12);
        hi = table_leaves_cost(&m) * 1.1;
        for (k = 0; k < 6; ++k)
            budgets[k] = table_rng_uniform(&rng, lo, hi);
        assert_lookahead_changes_nothing(s, &m, budgets, 6, "random tree");
        tclod_scene_destroy(s);
        table_free(&m);
    }
    for (kind = FAMILY_UNCORRELATED; kind <= FAMILY_STRONGLY_CORRELATED; ++kind)
        for (seed = 1; seed <= 60; ++seed) {
            tclod_scene *s = NULL;
            table_model m;
            table_rng rng;
            family_desc d;
            double roots_cost, leaves_cost;
            family_desc_default(&d, FAMILY_TREES, (family_kind)kind);
            table_rng_seed(&rng, seed * 977u + (uint64_t)kind);
            table_init(&m);
            assert_int_equal(tclod_scene_create(NULL, &s), TCLOD_OK);
            assert_int_equal(family_build(&d, &m, s, &rng), TCLOD_OK);
            roots_cost = table_roots_cost(&m);
            leaves_cost = table_leaves_cost(&m);
            for (k = 0; k < 10; ++k) /* as tclod_quality: f = 0.05, 0.1 ... 0.9 */
                budgets[k] =
                    floor(roots_cost + (k == 0 ? 0.05 : 0.1 * k) * (leaves_cost - roots_cost));
            assert_lookahead_changes_nothing(s, &m, budgets, 10,
                                             family_kind_name((family_kind)kind));
            tclod_scene_destroy(s);
            table_free(&m);
        }
}

/* n objects of two levels: roots (b 1, c 1) with ids 0 .. n - 1, then their
 * finer levels, fine[i] = {benefit, cost}, in the same order. */
static void add_two_level_objects(helper_fixture *f, const double (*fine)[2], uint32_t n) {
    uint32_t i;
    for (i = 0; i < n; ++i)
        helper_add(f, TCLOD_NONE, 1.0, 1.0);
    for (i = 0; i < n; ++i)
        helper_add(f, i, fine[i][0], fine[i][1]);
}

/* A cold solve with `restarts` at the budget (and iteration limit) gives the
 * cut (sorted) with these totals, each callback called once at most. */
static void assert_restarts_give(helper_fixture *f, uint32_t restarts, double budget,
                                 uint32_t max_iterations, const tclod_id *cut, size_t n,
                                 double benefit, double cost) {
    tclod_selector *sel = tuned_selector(f->scene, &f->model, 0, 0, restarts);
    tclod_stats st;
    table_reset_counts(&f->model);
    select_frame(sel, budget, max_iterations, &st);
    helper_assert_cut(sel, cut, n);
    assert_totals(&st, benefit, cost);
    assert_true(table_max_calls(&f->model) <= 1);
    tclod_selector_destroy(sel);
}

/* Four objects of two levels, roots (b 1, c 1) with ids 0 .. 3, refinements
 * A (+6 for +2, ratio 3), B (+8 for +4, ratio 2), C (+9.5 for +5, ratio 1.9),
 * D (+5.5 for +6). Roots: b 4, c 4; budget 11 leaves 7. The plain greedy takes
 * A and B (b 18, c 10); C, the first misfit, and D no longer fit. Their
 * selections alone, T(C) = 4 + 9.5 = 13.5 at cost 9 and T(D) = 9.5, are below
 * 18, so one restart (the default) makes no pass: b 18. The relaxation's
 * bound at C is 18 + 9.5 = 27.5, far above 18, so with two the search makes
 * them: C forced (cost 9), then A fits (11) and B no longer: b 19.5, best so
 * far, first misfit B (bound 19.5 + 8); C and B forced cost 13: no fit, and
 * the passes are spent. The best, C's, is made again: {A1, B0, C1, D0},
 * b 19.5, c 11, the optimum (A and C are the pair of refinements that fit
 * with the larger gain). With an iteration limit that is never reached there
 * is no search: b 18. */
static void restarts_try_skipped_increments_and_keep_the_best(void **state) {
    helper_fixture *f = (helper_fixture *)*state;
    static const double fine[4][2] = {{7.0, 3.0}, {9.0, 5.0}, {10.5, 6.0}, {6.5, 7.0}};
    static const tclod_id plain[] = {2, 3, 4, 5};
    static const tclod_id best[] = {1, 3, 4, 6};
    add_two_level_objects(f, fine, 4); /* A1 4, B1 5, C1 6, D1 7 */
    assert_true(exact_optimum(&f->model, 11.0, NULL) == 19.5);
    assert_restarts_give(f, 1, 11.0, 0, plain, 4, 18.0, 10.0);
    assert_restarts_give(f, 2, 11.0, 0, best, 4, 19.5, 11.0);
    assert_restarts_give(f, 2, 11.0, 1000, plain, 4, 18.0, 10.0);
}

/* Objects X, Y, Z of two levels, roots (b 1, c 1) with ids 0 .. 2; refining X
 * gains 12 for 7 (ratio 1.71), Y 68 for 60 (1.13), Z 56 for 51 (1.10). The
 * budget, 120, leaves 117. The plain greedy takes X and Y (67) and Z no
 * longer fits: b 3 + 80 = 83, c 1 + 8 + 61 = 70. The optimum leaves X out for
 * Y and Z (111, c 114): b 3 + 124 = 127. The search finds it by forcing Z (X then fits, Y does not:
 * b 71) and then Y as well (X no longer fits: b 127); its other passes
 * (X forced too: no fit; X left out; Y left out; Z left out) find nothing
 * better, and the best pass is made again. */
static void the_search_finds_the_pair_a_cheaper_increment_blocks(void **state) {
    helper_fixture *f = (helper_fixture *)*state;
    static const double fine[3][2] = {{13.0, 8.0}, {69.0, 61.0}, {57.0, 52.0}};
    static const tclod_id plain[] = {2, 3, 4};
    static const tclod_id best[] = {0, 4, 5};
    add_two_level_objects(f, fine, 3); /* X1 3, Y1 4, Z1 5 */
    assert_true(exact_optimum(&f->model, 120.0, NULL) == 127.0);
    assert_restarts_give(f, 1, 120.0, 0, plain, 3, 83.0, 70.0);
    assert_restarts_give(f, 8, 120.0, 0, best, 3, 127.0, 114.0);
}

/* Restarts only replace the result by a better one: on random trees with any
 * values, the most restarts never give less than one, nor exceed the budget
 * or the optimum. */
static void more_restarts_never_give_less(void **state) {
    enum { seeds = 200, budgets = 4 };
    uint64_t seed;
    (void)state;
    for (seed = 1; seed <= seeds; ++seed) {
        tclod_scene *s = NULL;
        tclod_selector *one, *most;
        table_model m;
        table_rng rng;
        int b;
        table_rng_seed(&rng, seed * 104729u);
        table_init(&m);
        assert_int_equal(tclod_scene_create(NULL, &s), TCLOD_OK);
        assert_int_equal(table_random_hierarchy(&m, s, &rng, 3 + table_rng_below(&rng, 10),
                                                1 + table_rng_below(&rng, 3),
                                                seed % 2 ? TABLE_ARBITRARY : TABLE_DIMINISHING),
                         TCLOD_OK);
        one = tuned_selector(s, &m, 0, 0, 1);
        most = tuned_selector(s, &m, 0, 0, TCLOD_MAX_RESTARTS);
        for (b = 0; b < budgets; ++b) {
            /* from the roots' cost to that of every node (always above the roots') */
            double lo = table_roots_cost(&m) * (1.0 + 1e-12), hi = lo, budget;
            tclod_stats a, z;
            uint32_t i;
            for (i = 0; i < m.count; ++i)
                hi += m.cost[i];
            budget = table_rng_uniform(&rng, lo, hi);
            select_frame(one, budget, 0, &a);
            table_reset_counts(&m);
            select_frame(most, budget, 0, &z);
            helper_check_result(most, &m, &z, budget, 0);
            assert_true(table_max_calls(&m) <= 1);
            if (z.benefit < a.benefit || z.benefit > exact_optimum(&m, budget, NULL) + 1e-9)
                fail_msg("seed %u budget %.17g: %.17g with restarts, %.17g with one, optimum "
                         "%.17g",
                         (unsigned)seed, budget, z.benefit, a.benefit,
                         exact_optimum(&m, budget, NULL));
        }
        tclod_selector_destroy(one);
        tclod_selector_destroy(most);
        tclod_scene_destroy(s);
        table_free(&m);
    }
}

#define FIXTURE_TEST(name) \
    cmocka_unit_test_setup_teardown(name, helper_fixture_setup, helper_fixture_teardown)

/* Falling back (docs/greedy.md): 200 chains of a root and three levels, each
 * level costing 1 more than the one before it, whose favoured half swaps
 * every frame: the budget refines 100 chains to their last level, and which
 * 100 changes, so a warm start must undo 300 increments and take 300 others
 * (about 2.5 times a cold solve's evaluations and iterations). Its mean work
 * then exceeds 1.25 times the cold solves': the next solves start from the
 * roots and say so, and select exactly what a cold selector selects. With
 * fallback TCLOD_OFF every solve starts warm; on frames that do not change,
 * warm starts pay and no solve falls back. */
#define SWAP_CHAINS 200u
static void swap_halves(table_model *m, const tclod_id *root, uint32_t frame) {
    uint32_t i, k;
    for (i = 0; i < SWAP_CHAINS; ++i) {
        tclod_id n = root[i];
        int favoured = (i < SWAP_CHAINS / 2u) == (frame % 2u == 0u);
        for (k = 0; k < 4u; ++k, ++n)
            m->benefit[n] = (double)(k + 1u) * (favoured ? 10.0 : 1.0) + 0.001 * (double)i;
    }
}

static void warm_starts_that_work_more_than_cold_fall_back(void **state) {
    tclod_scene *s = NULL;
    table_model m;
    tclod_id root[SWAP_CHAINS];
    tclod_selector *sel[3];
    uint32_t i, k, frame, fell = 0, still = 0;
    /* budget: every root (cost 1) and 100 chains at level 3 (cost 4) */
    double budget = SWAP_CHAINS + 100.0 * 3.0;
    (void)state;
    table_init(&m);
    assert_int_equal(tclod_scene_create(NULL, &s), TCLOD_OK);
    for (i = 0; i < SWAP_CHAINS; ++i) {
        tclod_id parent = TCLOD_NONE, id;
        for (k = 0; k < 4u; ++k) {
            assert_int_equal(table_add_node(&m, s, parent, NULL, 1.0, (double)(k + 1u), &id),
                             TCLOD_OK);
            if (k == 0)
                root[i] = id;
            parent = id;
        }
        assert_int_equal(root[i] + 3u, id); /* a chain's ids are consecutive */
    }
    for (k = 0; k < 3; ++k) { /* cold, warm with fallback, warm without */
        tclod_selector_desc d;
        tclod_selector_desc_default(&d);
        table_callbacks(&m, &d.callbacks);
        d.cold_start = k == 0;
        d.greedy.restarts = TCLOD_OFF;
        d.greedy.fallback = k == 2 ? TCLOD_OFF : 0;
        assert_int_equal(tclod_selector_create(s, &d, NULL, &sel[k]), TCLOD_OK);
    }
    for (frame = 0; frame < 40; ++frame) {
        tclod_stats st[3];
        tclod_id a[SWAP_CHAINS], b[SWAP_CHAINS];
        swap_halves(&m, root, frame);
        for (k = 0; k < 3; ++k)
            select_frame(sel[k], budget, 0, &st[k]);
        assert_int_equal(st[0].notes & TCLOD_NOTE_COLD_FALLBACK, 0);
        assert_int_equal(st[2].notes & TCLOD_NOTE_COLD_FALLBACK, 0);
        if (!(st[1].notes & TCLOD_NOTE_COLD_FALLBACK))
            continue;
        fell++;
        assert_int_equal(helper_sorted_cut(sel[0], a, SWAP_CHAINS),
                         helper_sorted_cut(sel[1], b, SWAP_CHAINS));
        assert_memory_equal(a, b, sizeof a);
        assert_true(st[1].benefit == st[0].benefit);
        assert_int_equal(st[1].evaluations, st[0].evaluations);
    }
    /* after the first warm solve (1400 against 900), spans of 1, 2, 4, 8, 16
     * ... cold solves with one warm probe between them: frames 2, 4-5, 7-10,
     * 12-19 and 21-36 fall back, 38 on */
    assert_true(fell >= 33);
    /* still frames: once the span is over, warm solves do less work than
     * cold ones and none falls back again */
    for (;;) {
        tclod_stats st;
        select_frame(sel[1], budget, 0, &st);
        if (!(st.notes & TCLOD_NOTE_COLD_FALLBACK))
            break;
        assert_true(++still <= 64u); /* TCLOD_FALLBACK_SPAN_MAX */
    }
    for (frame = 0; frame < 20; ++frame) {
        tclod_stats st;
        select_frame(sel[1], budget, 0, &st);
        assert_int_equal(st.notes & TCLOD_NOTE_COLD_FALLBACK, 0);
    }
    for (k = 0; k < 3; ++k)
        tclod_selector_destroy(sel[k]);
    tclod_scene_destroy(s);
    table_free(&m);
}

/* Selects `solves` frames of budget 10 with warm selector sel; asserts that
 * none carries TCLOD_NOTE_COLD_FALLBACK and each has benefit `benefit`. */
static void solves_stay(tclod_selector *sel, uint32_t solves, double benefit) {
    tclod_stats st;
    uint32_t i;
    for (i = 0; i < solves; ++i) {
        select_frame(sel, 10.0, 0, &st);
        assert_int_equal(st.notes & TCLOD_NOTE_COLD_FALLBACK, 0);
        assert_true(st.benefit == benefit);
    }
}

static void an_audit_replaces_a_warm_cut_that_a_cold_solve_beats(void **state) {
    helper_fixture *f = (helper_fixture *)*state;
    /* R 0 (b 1, c 1) -> A 1 (b 2, c 2), B 2 (b 2, c 2); A -> A1 3, A2 4 (b 3,
     * c 2 each); budget 10. The first solve (cold: no cut yet) refines R
     * (Δb 3, Δc 3) and A (Δb 4, Δc 2): {2, 3, 4}, benefit 8, cost 6. Then R is
     * worth 100 (an impostor the eye entered): a cold solve keeps R (its
     * increment loses 96): {0}, 100. A warm start sees no increment and only
     * A's decrement (loses 4); R is not collapsible while A is refined, so it
     * stays at 8. The 32nd warm solve after the first is audited: the cold
     * solve that follows it has more benefit, so it is kept and the solve says
     * it fell back; the warm starts after it go on from {0}. */
    static const tclod_id refined[] = {2, 3, 4}, top[] = {0};
    tclod_selector *sel;
    tclod_stats st;
    helper_add(f, TCLOD_NONE, 1.0, 1.0);
    helper_add(f, 0, 2.0, 2.0);
    helper_add(f, 0, 2.0, 2.0);
    helper_add(f, 1, 3.0, 2.0);
    helper_add(f, 1, 3.0, 2.0);
    sel = helper_selector(f->scene, &f->model, 1);
    solves_stay(sel, 1, 8.0);
    helper_assert_cut(sel, refined, 3);
    f->model.benefit[0] = 100.0;
    solves_stay(sel, 32, 8.0); /* TCLOD_AUDIT_PERIOD warm solves */
    helper_assert_cut(sel, refined, 3);
    select_frame(sel, 10.0, 0, &st);
    assert_true(st.notes & TCLOD_NOTE_COLD_FALLBACK);
    assert_true(st.benefit == 100.0 && st.cost == 1.0);
    helper_assert_cut(sel, top, 1);
    solves_stay(sel, 3, 100.0);
    helper_assert_cut(sel, top, 1);
    tclod_selector_destroy(sel);
}

static void an_audit_keeps_a_warm_cut_that_beats_the_cold_solve(void **state) {
    helper_fixture *f = (helper_fixture *)*state;
    /* A chain P 0 (b 1, c 1) -> Q 1 (b 5, c 2) -> S 2 (b 10, c 3); budget 10.
     * The first solve refines to S: {2}, benefit 10. Then Q is worth 0.5: a
     * cold solve stops at P (Q's increment loses 0.5), benefit 1, while a warm
     * start keeps S (collapsing S into Q would lose 9.5) and is worth 10. The
     * audit's cold solve has less benefit: the warm cut stays, and no solve
     * says it fell back. */
    static const tclod_id finest[] = {2};
    tclod_selector *sel;
    helper_add(f, TCLOD_NONE, 1.0, 1.0);
    helper_add(f, 0, 5.0, 2.0);
    helper_add(f, 1, 10.0, 3.0);
    sel = helper_selector(f->scene, &f->model, 1);
    solves_stay(sel, 1, 10.0);
    f->model.benefit[1] = 0.5;
    solves_stay(sel, 40, 10.0); /* an audit among them */
    helper_assert_cut(sel, finest, 1);
    tclod_selector_destroy(sel);
}

int main(void) {
    const struct CMUnitTest tests[] = {
        FIXTURE_TEST(increments_follow_the_hand_worked_order),
        FIXTURE_TEST(increments_stop_when_nothing_more_fits),
        FIXTURE_TEST(an_increment_that_does_not_fit_is_skipped_for_a_later_one),
        FIXTURE_TEST(invisible_nodes_are_culled_with_their_subtree),
        FIXTURE_TEST(roots_that_do_not_fit_are_dropped_lowest_value_first),
        FIXTURE_TEST(zero_budget_drops_every_visible_root_that_costs),
        FIXTURE_TEST(zero_budget_keeps_roots_that_cost_nothing),
        FIXTURE_TEST(roots_that_do_not_fit_give_way_to_cheaper_children),
        FIXTURE_TEST(a_warm_start_takes_back_a_parent_whose_children_left_the_view),
        FIXTURE_TEST(a_warm_start_culls_the_children_of_an_invisible_parent),
        FIXTURE_TEST(greedy_reaches_half_the_optimum_on_an_adversarial_instance),
        FIXTURE_TEST(exact_solver_agrees_with_hand_worked_optima),
        cmocka_unit_test(greedy_is_within_half_of_exact_optimum_on_random_trees),
        cmocka_unit_test(greedy_never_beats_the_optimum_nor_the_budget_on_arbitrary_values),
        FIXTURE_TEST(lookahead_finds_a_refinement_whose_gain_comes_at_its_second_level),
        FIXTURE_TEST(lookahead_takes_the_best_level_within_reach_and_the_shallower_of_equals),
        FIXTURE_TEST(lookahead_keeps_the_order_under_diminishing_returns),
        FIXTURE_TEST(lookahead_takes_the_shallower_of_equal_best_ratios_found_from_below),
        FIXTURE_TEST(tree_lookahead_finds_a_refinement_whose_gain_comes_below_its_children),
        FIXTURE_TEST(a_lookahead_increment_too_dear_gives_way_to_the_best_cut_that_fits),
        FIXTURE_TEST(the_search_forces_the_cut_that_fits_of_a_lookahead_increment),
        FIXTURE_TEST(the_safeguard_keeps_a_lookahead_within_half_of_the_optimum),
        cmocka_unit_test(tree_lookahead_takes_the_best_ratio_of_every_cut_below),
        cmocka_unit_test(tree_lookahead_is_within_half_of_the_optimum_without_diminishing_returns),
        cmocka_unit_test(tree_lookahead_changes_nothing_under_diminishing_returns),
        cmocka_unit_test(warm_starts_that_work_more_than_cold_fall_back),
        FIXTURE_TEST(restarts_try_skipped_increments_and_keep_the_best),
        FIXTURE_TEST(the_search_finds_the_pair_a_cheaper_increment_blocks),
        cmocka_unit_test(more_restarts_never_give_less),
        cmocka_unit_test(greedy_with_lookahead_is_within_half_of_exact_optimum_on_random_trees),
        cmocka_unit_test(greedy_with_lookahead_never_beats_the_optimum_nor_the_budget),
        FIXTURE_TEST(warm_start_on_an_unchanged_frame_is_at_least_as_good),
        FIXTURE_TEST(cold_solves_after_other_budgets_reach_a_new_selectors_cut),
        FIXTURE_TEST(warm_starts_on_a_large_scene_keep_every_guarantee),
        FIXTURE_TEST(warm_start_after_a_budget_drop_uses_decrements),
        FIXTURE_TEST(warm_start_swaps_a_refinement_for_a_better_one_of_the_same_cost),
        FIXTURE_TEST(warm_start_swaps_in_the_misfit_its_fill_skipped),
        FIXTURE_TEST(warm_start_swaps_collapse_a_chain_level_by_level),
        FIXTURE_TEST(an_audit_replaces_a_warm_cut_that_a_cold_solve_beats),
        FIXTURE_TEST(an_audit_keeps_a_warm_cut_that_beats_the_cold_solve),
        FIXTURE_TEST(audited_warm_starts_after_model_changes_stay_feasible),
        FIXTURE_TEST(warm_starts_with_lookahead_and_fallback_stay_feasible),
        FIXTURE_TEST(warm_start_after_model_changes_stays_feasible),
        FIXTURE_TEST(warm_start_with_lookahead_after_model_changes_stays_feasible),
        FIXTURE_TEST(a_warm_start_swaps_past_the_balance_point_to_fill_the_room),
        FIXTURE_TEST(warm_start_evaluates_the_frontier_not_the_path_from_the_roots),
        FIXTURE_TEST(warm_start_after_the_scene_grew_includes_new_nodes),
        FIXTURE_TEST(warm_start_recovers_dropped_roots_when_the_budget_returns),
        FIXTURE_TEST(limits_never_stop_a_warm_start_over_budget),
        FIXTURE_TEST(iteration_limit_stops_with_a_feasible_result),
        FIXTURE_TEST(time_limit_stops_with_a_feasible_result),
        FIXTURE_TEST(unlimited_budget_refines_everything_to_the_finest_level),
        FIXTURE_TEST(budget_stop_is_reported_when_an_increment_does_not_fit),
        FIXTURE_TEST(callbacks_are_called_at_most_once_per_node_per_solve),
        FIXTURE_TEST(greedy_ignores_smooth_objects),
        FIXTURE_TEST(deep_chain_is_refined_to_its_last_level),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
