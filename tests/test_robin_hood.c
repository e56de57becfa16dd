/*
 * test_robin_hood — the Robin Hood solver (src/solve/robin_hood.c, [RH §5]):
 * shares proportional to value (eq. 2-4), leftover passed on, the
 * simple-to-complex order, the value functions (eq. 8-11), the misfit
 * policies, smooth objects' inverse cost, branches, and the budget.
 *
 * Instances are chains of nodes (table model: fixed costs per level) and
 * smooth objects (benefit w sqrt(r), cost k r). With TCLOD_VALUE_BENEFIT an
 * instance's value is its importance, the benefit of its first level, which
 * lets the tests set values directly; the frames have no view unless said.
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
#include "table_scene.h"
#include "world_scene.h"

/* A chain with the given level costs, every level of benefit `value`. Returns
 * the first level's id; level k is that id + k. */
static tclod_id add_chain(helper_fixture *f, double value, const double *costs, int levels) {
    tclod_id first = helper_add(f, TCLOD_NONE, value, costs[0]), prev = first;
    int k;
    for (k = 1; k < levels; ++k)
        prev = helper_add(f, prev, value, costs[k]);
    return first;
}

/* The defaults with the Robin Hood solver and the table's callbacks. */
static void rh_desc(helper_fixture *f, tclod_selector_desc *d) {
    tclod_selector_desc_default(d);
    d->solver = TCLOD_SOLVER_ROBIN_HOOD;
    table_mixed_callbacks(&f->model, &d->callbacks);
}

static tclod_selector *rh_create(helper_fixture *f, const tclod_selector_desc *d) {
    tclod_selector *sel = NULL;
    assert_int_equal(tclod_selector_create(f->scene, d, NULL, &sel), TCLOD_OK);
    return sel;
}

static tclod_selector *rh_selector(helper_fixture *f, tclod_value value, tclod_misfit misfit) {
    tclod_selector_desc d;
    rh_desc(f, &d);
    d.robin_hood.value = value;
    d.robin_hood.misfit = misfit;
    return rh_create(f, &d);
}

static void select_rh(tclod_selector *sel, const tclod_view *view, double budget, tclod_stats *st) {
    tclod_frame fr = helper_frame(view, budget);
    assert_int_equal(tclod_select(sel, &fr, st), TCLOD_OK);
}

/* 1 when node id is listed in the cut. */
static int listed(const tclod_selector *sel, tclod_id id) {
    const tclod_id *ids;
    size_t n, i;
    assert_int_equal(tclod_selector_cut(sel, &ids, &n), TCLOD_OK);
    for (i = 0; i < n; ++i)
        if (ids[i] == id)
            return 1;
    return 0;
}

/* ---- shares and leftover -------------------------------------------------------- */

/* Four equal chains (levels costing 1, 2, 4, 8), equal values, budget 8 (less
 * the pass's margin): shares 8/4 = 2 each, so every chain takes its level 1. */
static void equal_values_get_equal_shares(void **state) {
    helper_fixture *f = (helper_fixture *)*state;
    static const double costs[4] = {1.0, 2.0, 4.0, 8.0};
    tclod_id chains[4];
    tclod_selector *sel;
    tclod_stats st;
    int i;
    for (i = 0; i < 4; ++i)
        chains[i] = add_chain(f, 1.0, costs, 4);
    sel = rh_selector(f, TCLOD_VALUE_BENEFIT, TCLOD_MISFIT_DROP);
    select_rh(sel, NULL, 8.0 * (1.0 + 1e-6), &st);
    for (i = 0; i < 4; ++i)
        assert_true(listed(sel, chains[i] + 1u));
    assert_true(st.cost == 8.0);
    tclod_selector_destroy(sel);
}

/* Three instances of equal value, least complex first: A (finest level costs
 * 1), B (levels 1, 2, 3.5), C (levels 2, 4.5, 10). Budget 9:
 *   A: share 9/3 = 3, takes 1, leaves 2: pool 8;
 *   B: share 8/2 = 4, takes 3.5, leaves 0.5: pool 4.5;
 *   C: share 4.5, takes 4.5: pool 0, nothing for cycle 3.
 * Without the leftover passed on every share would be 9/3 = 3: A takes 1, B
 * 2, C 2, and cycle 3 would reach the same cut from the 4 left with two
 * increments (B's 1.5, then C's 2.5). The share pass reaches it alone: no
 * increment. */
static void leftover_of_a_simple_instance_reaches_a_complex_one(void **state) {
    helper_fixture *f = (helper_fixture *)*state;
    static const double ca[1] = {1.0}, cb[3] = {1.0, 2.0, 3.5}, cc[3] = {2.0, 4.5, 10.0};
    tclod_id a, b, c;
    tclod_selector *sel;
    tclod_stats st;
    c = add_chain(f, 1.0, cc, 3);
    b = add_chain(f, 1.0, cb, 3);
    a = add_chain(f, 1.0, ca, 1);
    sel = rh_selector(f, TCLOD_VALUE_BENEFIT, TCLOD_MISFIT_DROP);
    select_rh(sel, NULL, 9.0 * (1.0 + 1e-6), &st);
    assert_true(listed(sel, a));
    assert_true(listed(sel, b + 2u));
    assert_true(listed(sel, c + 1u));
    assert_true(st.cost == 1.0 + 3.5 + 4.5);
    assert_int_equal(st.increments, 0);
    tclod_selector_destroy(sel);
}

/* Equal values, budget 10: K (levels 2, 9), created first, and S (levels 1,
 * 8; finest 8 < 9, so the simpler). Simple first: S's share 5 affords only
 * its level 0 and leaves 4, so K's share 9 takes its level 1: total 10, no
 * leftover for cycle 3 (no increment). In creation order K's share 5 would
 * take its level 0 and S's 8 its level 1: also total 10. A complexity
 * callback that calls S the more complex turns the order round. Without the
 * leftover passed on both shares would be 5 (S 1, K 2) and cycle 3 would
 * give the 7 left to K (one increment): the simple-first cut, by another
 * way. */
static double reversed_complexity(void *user, const tclod_query *q) {
    (void)user;
    return q->id == 0 ? 1.0 : 100.0; /* K (id 0) least complex */
}

/* A Robin Hood selector (values: the benefits) whose order is set by
 * reversed_complexity. */
static tclod_selector *reversed_selector(helper_fixture *f) {
    tclod_selector_desc d;
    rh_desc(f, &d);
    d.callbacks.complexity = reversed_complexity;
    d.robin_hood.value = TCLOD_VALUE_BENEFIT;
    return rh_create(f, &d);
}

static void instances_are_visited_simple_to_complex(void **state) {
    helper_fixture *f = (helper_fixture *)*state;
    static const double ck[2] = {2.0, 9.0}, cs[2] = {1.0, 8.0};
    tclod_id k = add_chain(f, 1.0, ck, 2), s = add_chain(f, 1.0, cs, 2);
    tclod_selector *sel = rh_selector(f, TCLOD_VALUE_BENEFIT, TCLOD_MISFIT_DROP);
    tclod_stats st;
    select_rh(sel, NULL, 10.0 * (1.0 + 1e-6), &st);
    assert_true(listed(sel, s));
    assert_true(listed(sel, k + 1u));
    assert_int_equal(st.increments, 0);
    tclod_selector_destroy(sel);

    sel = reversed_selector(f);
    select_rh(sel, NULL, 10.0 * (1.0 + 1e-6), &st);
    assert_true(listed(sel, k));
    assert_true(listed(sel, s + 1u));
    assert_int_equal(st.increments, 0);
    tclod_selector_destroy(sel);
}

/* The order is found again when the scene changes. K (levels 2, 9) and S
 * (levels 1, 8), equal values, budget 10: S is the simpler (8 < 9) and goes
 * first, S's share 5 takes its level 0, K's 9 its level 1. A third level of S
 * costing 20 makes S the more complex (20 > 9): now K goes first, K's share 5
 * takes its level 0 (2) and S's 8 its level 1 (8), total 10 again. With the
 * order of the first frame kept, S would still take its level 0 and K its
 * level 1. */
static void a_scene_change_orders_the_instances_again(void **state) {
    helper_fixture *f = (helper_fixture *)*state;
    static const double ck[2] = {2.0, 9.0}, cs[2] = {1.0, 8.0};
    tclod_id k = add_chain(f, 1.0, ck, 2), s = add_chain(f, 1.0, cs, 2);
    tclod_selector *sel = rh_selector(f, TCLOD_VALUE_BENEFIT, TCLOD_MISFIT_DROP);
    tclod_stats st;
    select_rh(sel, NULL, 10.0 * (1.0 + 1e-6), &st);
    assert_true(listed(sel, s));
    assert_true(listed(sel, k + 1u));

    helper_add(f, s + 1u, 1.0, 20.0);
    select_rh(sel, NULL, 10.0 * (1.0 + 1e-6), &st);
    assert_true(listed(sel, k));
    assert_true(listed(sel, s + 1u));
    assert_true(st.cost == 10.0);
    assert_int_equal(st.increments, 0);
    tclod_selector_destroy(sel);
}

/* Without a complexity callback, an instance's complexity is the cost of its
 * finest level, and the callbacks are still asked at most once per node per
 * select (tclod_callbacks), also in a select after a scene change, which
 * orders the instances again. Scene, no bounds, no view, budget 100 (every
 * level fits), values the benefits:
 *   chain A: 0 (b 1, c 1) -> 1 (b 2, c 2) -> 2 (b 3, c 4), finest level 2;
 *   B: 3 (b 1, c 1), its own finest level;
 *   branch C: 4 (b 1, c 1) with children 5 and 6 (b 1, c 1), each an instance
 *   of one level, C its own finest level;
 *   D: 7 (b 0, c 5), not visible;
 *   chain E: 8 (b 1, c 1) -> 9 (b 0, c 3), its finest level not visible;
 *   branch G: 10 (b 0, c 1), not visible, with children 11 and 12 (b 1, c 1).
 * No node is asked its benefit or its cost twice in a select. The frame asks
 * nothing about 7, 9 and 10 beyond their benefit (0), and nothing at all
 * about 11 and 12, below G, which is culled with its subtree: a select that
 * orders the instances asks their costs once each, for the complexity, at
 * the reference area with no view (the only queries with screen_area 10 000;
 * the frame's carry -1), and the frame's own costs of the other finest levels
 * (2, 3, 4, 5, 6) serve as theirs. After a node is added (F, 13: b 1, c 1, a
 * root) the next select orders the instances again and asks the same, F's
 * cost once too; a select with no change asks no complexity. The order, from
 * the same costs, is as before, and the cut lists A's 2, B, C's children 5
 * and 6, and F after the change. */
static uint32_t reference_queries;

static double counting_cost(void *user, const tclod_query *q) {
    reference_queries += q->view == NULL && q->screen_area == 10000.0f;
    return table_cost(user, q);
}

static void costs_are_asked_once_per_select_across_scene_changes(void **state) {
    helper_fixture *f = (helper_fixture *)*state;
    static const double ca[3] = {1.0, 2.0, 4.0};
    tclod_selector_desc d;
    tclod_selector *sel;
    tclod_stats st;
    tclod_id c, e, g, id;
    int frame;
    add_chain(f, 1.0, ca, 3);
    f->model.benefit[1] = 2.0;
    f->model.benefit[2] = 3.0;
    helper_add(f, TCLOD_NONE, 1.0, 1.0);
    c = helper_add(f, TCLOD_NONE, 1.0, 1.0);
    helper_add(f, c, 1.0, 1.0);
    helper_add(f, c, 1.0, 1.0);
    helper_add(f, TCLOD_NONE, 0.0, 5.0);
    e = helper_add(f, TCLOD_NONE, 1.0, 1.0);
    helper_add(f, e, 0.0, 3.0);
    g = helper_add(f, TCLOD_NONE, 0.0, 1.0);
    helper_add(f, g, 1.0, 1.0);
    helper_add(f, g, 1.0, 1.0);
    rh_desc(f, &d);
    d.robin_hood.value = TCLOD_VALUE_BENEFIT;
    d.callbacks.cost = counting_cost;
    sel = rh_create(f, &d);
    for (frame = 0; frame < 3; ++frame) {
        static const tclod_id drawn[] = {2, 3, 5, 6, 13}, finest[] = {2, 3, 4, 5, 6, 13};
        static const tclod_id unseen[] = {7, 9, 10, 11, 12};
        size_t k;
        uint32_t nodes;
        if (frame == 1)
            assert_int_equal(helper_add(f, TCLOD_NONE, 1.0, 1.0), 13);
        nodes = tclod_scene_node_count(f->scene);
        table_reset_counts(&f->model);
        reference_queries = 0;
        select_rh(sel, NULL, 100.0, &st);
        for (id = 0; id < nodes; ++id)
            if (f->model.benefit_calls[id] > 1 || f->model.cost_calls[id] > 1)
                fail_msg("frame %d, node %u: %u benefit and %u cost calls", frame, (unsigned)id,
                         (unsigned)f->model.benefit_calls[id], (unsigned)f->model.cost_calls[id]);
        for (k = 0; k < (frame == 0 ? 5u : 6u); ++k) /* the visible finest levels */
            assert_int_equal(f->model.cost_calls[finest[k]], 1);
        for (k = 0; k < 5; ++k)
            assert_int_equal(f->model.cost_calls[unseen[k]], frame < 2);
        assert_int_equal(f->model.benefit_calls[11] + f->model.benefit_calls[12], 0);
        assert_int_equal(reference_queries, frame < 2 ? 5u : 0u);
        assert_int_equal(st.invalid_values, 0);
        for (k = 0; k < (frame == 0 ? 4u : 5u); ++k)
            assert_true(listed(sel, drawn[k]));
        helper_check_result(sel, &f->model, &st, 100.0, 1);
    }
    tclod_selector_destroy(sel);
}

/* A branch's children are found again when the scene changes: roots R1 and
 * R2 (cost 1), each with two children of cost 1, equal values, budget 10.
 * Each root's share 5 covers its children's 2, so the cut is R1's A, B and
 * R2's D, E, cost 4. A third child C of R1 (cost 1) moves R2's children one
 * place on in the scene's child list; R1's share 5 still covers its three
 * children's 3, so the cut is A, B, C, D, E, cost 5. A child range kept from
 * the first frame would leave C out, or read C and D as R2's children. */
static void a_scene_change_finds_the_branches_children_again(void **state) {
    helper_fixture *f = (helper_fixture *)*state;
    tclod_id r1 = helper_add(f, TCLOD_NONE, 1.0, 1.0), a = helper_add(f, r1, 1.0, 1.0),
             b = helper_add(f, r1, 1.0, 1.0), r2 = helper_add(f, TCLOD_NONE, 1.0, 1.0),
             d = helper_add(f, r2, 1.0, 1.0), e = helper_add(f, r2, 1.0, 1.0), c;
    tclod_selector *sel = rh_selector(f, TCLOD_VALUE_BENEFIT, TCLOD_MISFIT_DROP);
    tclod_stats st;
    const tclod_id *ids;
    size_t n;
    select_rh(sel, NULL, 10.0, &st);
    assert_true(listed(sel, a) && listed(sel, b) && listed(sel, d) && listed(sel, e));
    assert_true(st.cost == 4.0);

    c = helper_add(f, r1, 1.0, 1.0);
    select_rh(sel, NULL, 10.0, &st);
    assert_int_equal(tclod_selector_cut(sel, &ids, &n), TCLOD_OK);
    assert_int_equal(n, 5);
    assert_true(listed(sel, a) && listed(sel, b) && listed(sel, c) && listed(sel, d) &&
                listed(sel, e));
    assert_true(st.cost == 5.0);
    tclod_selector_destroy(sel);
}

/* The leftover cycle ([RH §7.2]): K (levels 2, 9) and S (one level costing
 * 1), equal values, budget 10, K visited first. K's share 5 takes its level
 * 0, S's share 8 takes 1 and leaves 7: K's next step (9 - 2 = 7) fits the
 * leftover, so K ends at its level 1 and the frame uses all of its 10. */
static void the_leftover_refines_the_instances_that_can_refine(void **state) {
    helper_fixture *f = (helper_fixture *)*state;
    static const double ck[2] = {2.0, 9.0}, cs[1] = {1.0};
    tclod_id k = add_chain(f, 1.0, ck, 2), s = add_chain(f, 1.0, cs, 1);
    tclod_selector *sel;
    tclod_stats st;
    sel = reversed_selector(f);
    select_rh(sel, NULL, 10.0 * (1.0 + 1e-6), &st);
    assert_true(listed(sel, k + 1u));
    assert_true(listed(sel, s));
    assert_false(listed(sel, k));
    assert_true(st.cost == 10.0);
    assert_int_equal(st.stop_reason, TCLOD_STOP_FINEST);
    tclod_selector_destroy(sel);
}

/* One chain of 300 levels, level k costing k + 1: the whole budget B (less
 * the pass's margin of 1e-9 B) is its share, so it takes level
 * ceil(B - 1e-9 B) - 2, the finest whose cost fits, and the leftover (below 1)
 * buys no step. The level a chain took last is kept up to 255 (beyond, 255),
 * and the next search starts there: from level 279 it must gallop up again,
 * for level 99 down, and at 300.5 reach the chain's end. */
static void a_chain_of_more_than_255_levels_takes_its_finest_affordable_level(void **state) {
    static const struct {
        double budget;
        tclod_id level;
    } frames[] = {{281.0, 279}, {281.0, 279}, {101.0, 99}, {300.5, 299}, {281.0, 279}};
    helper_fixture *f = (helper_fixture *)*state;
    double costs[300];
    tclod_selector *sel;
    tclod_stats st;
    tclod_id first;
    size_t i;
    int k;
    for (k = 0; k < 300; ++k)
        costs[k] = (double)(k + 1);
    first = add_chain(f, 1.0, costs, 300);
    sel = rh_selector(f, TCLOD_VALUE_BENEFIT, TCLOD_MISFIT_DROP);
    for (i = 0; i < sizeof frames / sizeof frames[0]; ++i) {
        const tclod_id *ids;
        size_t n;
        select_rh(sel, NULL, frames[i].budget, &st);
        assert_int_equal(tclod_selector_cut(sel, &ids, &n), TCLOD_OK);
        assert_int_equal(n, 1);
        assert_int_equal(ids[0], first + frames[i].level);
        assert_true(st.cost == (double)(frames[i].level + 1u));
    }
    tclod_selector_destroy(sel);
}

/* Budget B: chain K (levels 0.5 and 1, value 0.75 / B) goes first, its
 * share B (1 - 1e-9) 0.75 / (B + 0.75) (the pass keeps 1e-9 B back), about
 * 0.75, taking level 0; then S (one level, B - 1.3, value 1) takes all
 * but the last 0.8 - 1e-9 B. K's step 0.5 fits that leftover; it is shared
 * out again only when it is at least 5 10^-4 of the budget. Returns the
 * cut's cost. */
static double leftover_against_the_budget(helper_fixture *f, double budget, tclod_id *k) {
    static const double ck[2] = {0.5, 1.0};
    double cs[1];
    tclod_selector *sel;
    tclod_stats st;
    cs[0] = budget - 1.3;
    *k = add_chain(f, 0.75 / budget, ck, 2);
    (void)add_chain(f, 1.0, cs, 1);
    sel = rh_selector(f, TCLOD_VALUE_BENEFIT, TCLOD_MISFIT_DROP);
    select_rh(sel, NULL, budget, &st);
    assert_true(listed(sel, *k) || listed(sel, *k + 1u));
    tclod_selector_destroy(sel);
    return st.cost;
}

/* B = 2000: the leftover 0.8 is below 5 10^-4 B = 1 and stays unused. */
static void a_leftover_below_a_2000th_of_the_budget_is_not_shared_again(void **state) {
    helper_fixture *f = (helper_fixture *)*state;
    tclod_id k;
    assert_true(leftover_against_the_budget(f, 2000.0, &k) == 0.5 + (2000.0 - 1.3));
}

/* B = 1000: the leftover 0.8 is above 5 10^-4 B = 0.5, and K takes level 1. */
static void a_leftover_of_a_2000th_of_the_budget_is_shared_again(void **state) {
    helper_fixture *f = (helper_fixture *)*state;
    tclod_id k;
    assert_true(leftover_against_the_budget(f, 1000.0, &k) == 1.0 + (1000.0 - 1.3));
}

/* Values 3 : 1 share 8 as 6 : 2. Chains with levels 1, 2, 6 (value 3) and
 * 1, 2, 6 (value 1): the first takes 6, the second 2. */
static void shares_follow_the_values(void **state) {
    helper_fixture *f = (helper_fixture *)*state;
    static const double costs[3] = {1.0, 2.0, 6.0};
    tclod_id big = add_chain(f, 3.0, costs, 3), small = add_chain(f, 1.0, costs, 3);
    tclod_selector *sel = rh_selector(f, TCLOD_VALUE_BENEFIT, TCLOD_MISFIT_DROP);
    tclod_stats st;
    select_rh(sel, NULL, 8.0 * (1.0 + 1e-6), &st);
    assert_true(listed(sel, big + 2u));
    assert_true(listed(sel, small + 1u));
    tclod_selector_destroy(sel);
}

/* ---- misfits ---------------------------------------------------------------- */

/* Equal values, least complex first: B (one level costing 1), then A (one
 * level costing 3.5). Budget 4: B's share 2 takes 1, leaving 3 for A, whose
 * share 3 does not cover 3.5: A is left out and counted as a dropped root.
 * Budget 4.5: A's share 3.5 covers it. */
static void an_instance_whose_simplest_level_exceeds_its_share_is_dropped(void **state) {
    helper_fixture *f = (helper_fixture *)*state;
    static const double ca[1] = {3.5}, cb[1] = {1.0};
    tclod_id a = add_chain(f, 1.0, ca, 1), b = add_chain(f, 1.0, cb, 1);
    tclod_selector *sel = rh_selector(f, TCLOD_VALUE_BENEFIT, TCLOD_MISFIT_DROP);
    tclod_stats st;
    select_rh(sel, NULL, 4.0, &st);
    assert_true(listed(sel, b));
    assert_false(listed(sel, a));
    assert_int_equal(st.dropped_roots, 1);
    select_rh(sel, NULL, 4.5 * (1.0 + 1e-6), &st);
    assert_true(listed(sel, a));
    assert_int_equal(st.dropped_roots, 0);
    tclod_selector_destroy(sel);
}

/* X (value 1, one level costing 3) goes first (a complexity callback says
 * so), then Y (value 3, one level costing 2); budget 4. X's share 4 * 1/4 = 1
 * does not cover 3. DROP: X out, and Y's share is all 4: Y in. COARSEST: the 4
 * left covers X's 3, so X is drawn, leaving 1 for Y, which neither its share
 * nor what is left covers: Y out. */
static void the_coarsest_policy_draws_a_misfit_the_time_left_covers(void **state) {
    helper_fixture *f = (helper_fixture *)*state;
    static const double cx[1] = {3.0}, cy[1] = {2.0};
    tclod_id x = add_chain(f, 1.0, cx, 1), y = add_chain(f, 3.0, cy, 1);
    tclod_selector_desc d;
    tclod_selector *sel;
    tclod_stats st;
    rh_desc(f, &d);
    d.callbacks.complexity = reversed_complexity; /* id 0 (x) first */
    d.robin_hood.value = TCLOD_VALUE_BENEFIT;

    d.robin_hood.misfit = TCLOD_MISFIT_DROP;
    sel = rh_create(f, &d);
    select_rh(sel, NULL, 4.0, &st);
    assert_false(listed(sel, x));
    assert_true(listed(sel, y));
    tclod_selector_destroy(sel);

    d.robin_hood.misfit = TCLOD_MISFIT_COARSEST;
    sel = rh_create(f, &d);
    select_rh(sel, NULL, 4.0, &st);
    assert_true(listed(sel, x));
    assert_false(listed(sel, y));
    assert_true(st.cost == 3.0);
    tclod_selector_destroy(sel);
}

/* ---- smooth objects ------------------------------------------------------------ */

/* Two smooth objects of equal value, costs r and 2 r (the cheaper first).
 * Budget 1.5: the first's share 0.75 buys r = 0.75; the second's share 0.75
 * buys r = 0.375. Budget 3: the first's share 1.5 buys r = 1 for 1, leaving
 * 0.5; the second's share 2 buys r = 1. */
static void smooth_objects_take_the_resolution_their_share_buys(void **state) {
    helper_fixture *f = (helper_fixture *)*state;
    float b0[4] = {0.0f, 0.0f, 0.0f, 1.0f}, b1[4] = {5.0f, 0.0f, 0.0f, 1.0f};
    tclod_id s0, s1;
    tclod_selector *sel;
    tclod_stats st;
    /* value: importance = benefit at r = 1 = w; equal w */
    assert_int_equal(
        table_add_smooth(&f->model, f->scene, b0, TABLE_POWER, 1.0, 0.5, 1.0, 1.0, 0.0, &s0),
        TCLOD_OK);
    assert_int_equal(
        table_add_smooth(&f->model, f->scene, b1, TABLE_POWER, 1.0, 0.5, 2.0, 2.0, 0.0, &s1),
        TCLOD_OK);
    sel = rh_selector(f, TCLOD_VALUE_BENEFIT, TCLOD_MISFIT_DROP);
    select_rh(sel, NULL, 1.5, &st);
    assert_true(fabs(tclod_selector_resolution(sel, s0) - 0.75) < 1e-6);
    assert_true(fabs(tclod_selector_resolution(sel, s1) - 0.375) < 1e-6);
    assert_true(st.cost <= 1.5);
    select_rh(sel, NULL, 3.0 * (1.0 + 1e-6), &st);
    assert_true(tclod_selector_resolution(sel, s0) == 1.0);
    assert_true(tclod_selector_resolution(sel, s1) == 1.0);
    tclod_selector_destroy(sel);
}

/* ---- branches -------------------------------------------------------------------- */

/* A root R (cost 1) with four children of cost 1 and values 1, 1, 1, 3;
 * child 3 has one child of cost 4 (so child 3's instance is the chain child 3
 * -> its child, complexity 4). Budget 8 is R's whole share. The children's
 * simplest levels need 4 <= 8, so they become instances: each keeps its
 * simplest level and they share the other 4 by value, least complex first.
 * Children 0, 1, 2 get 1 + 4 * 1/6, 1 + 4 * 1/5, 1 + 4 * 1/4 in turn, use 1
 * each (nothing finer), and hand the extra back; child 3 gets 1 + 4 = 5 and
 * takes its child (4). Cut: children 0, 1, 2 and child 3's child, cost 7.
 * With budget 3 the children's 4 do not fit: R alone. */
static void a_branch_shares_its_time_among_its_children(void **state) {
    helper_fixture *f = (helper_fixture *)*state;
    tclod_id r = helper_add(f, TCLOD_NONE, 1.0, 1.0), c[4], g;
    tclod_selector *sel;
    tclod_stats st;
    int i;
    for (i = 0; i < 4; ++i)
        c[i] = helper_add(f, r, i == 3 ? 3.0 : 1.0, 1.0);
    g = helper_add(f, c[3], 3.0, 4.0);
    sel = rh_selector(f, TCLOD_VALUE_BENEFIT, TCLOD_MISFIT_DROP);
    select_rh(sel, NULL, 8.0, &st);
    for (i = 0; i < 3; ++i)
        assert_true(listed(sel, c[i]));
    assert_true(listed(sel, g));
    assert_false(listed(sel, r));
    assert_true(st.cost == 7.0);
    select_rh(sel, NULL, 3.0, &st);
    assert_true(listed(sel, r));
    assert_true(st.cost == 1.0);
    tclod_selector_destroy(sel);
}

/* A host's benefit: the table's, and 0 (not visible) where the node's
 * bounds lie outside the frustum (screen area 0), as an engine culls. */
static double culling_benefit(void *user, const tclod_query *q) {
    return q->screen_area == 0.0f ? 0.0 : table_benefit(user, q);
}

static double unit_importance(void *user, const tclod_query *q) {
    (void)user;
    (void)q;
    return 1.0;
}

/* Under the reference view (90 degrees, far plane 100) root R at depth 50
 * has children A and B one unit and five units off its centre, so the sphere
 * that holds them (radius 6) lies inside the frustum; A's children are G1,
 * at A's centre, and G2, 100 units to the side, outside the frustum. A's
 * children's sphere does not lie within R's, so G2 still needs its frustum
 * test below a root found inside: it is culled, and the cut draws G1 and B
 * (every node costs 1, budget 10). With or without an importance callback
 * (the two ways a child is evaluated). */
static void a_child_outside_the_frustum_is_culled_below_a_branch_inside_it(void **state) {
    helper_fixture *f = (helper_fixture *)*state;
    static const float br[4] = {0.0f, 0.0f, -50.0f, 10.0f}, ba[4] = {0.0f, 0.0f, -50.0f, 1.0f},
                       bb[4] = {5.0f, 0.0f, -50.0f, 1.0f}, bg2[4] = {100.0f, 0.0f, -50.0f, 1.0f};
    tclod_id r, a, b, g1, g2;
    tclod_view view;
    tclod_stats st;
    int with_importance;
    assert_int_equal(table_add_node(&f->model, f->scene, TCLOD_NONE, br, 1.0, 1.0, &r), TCLOD_OK);
    assert_int_equal(table_add_node(&f->model, f->scene, r, ba, 1.0, 1.0, &a), TCLOD_OK);
    assert_int_equal(table_add_node(&f->model, f->scene, r, bb, 1.0, 1.0, &b), TCLOD_OK);
    assert_int_equal(table_add_node(&f->model, f->scene, a, ba, 1.0, 1.0, &g1), TCLOD_OK);
    assert_int_equal(table_add_node(&f->model, f->scene, a, bg2, 1.0, 1.0, &g2), TCLOD_OK);
    helper_view(&view);
    for (with_importance = 0; with_importance < 2; ++with_importance) {
        tclod_selector_desc d;
        tclod_selector *sel;
        rh_desc(f, &d);
        d.callbacks.benefit = culling_benefit;
        d.callbacks.importance = with_importance ? unit_importance : NULL;
        sel = rh_create(f, &d);
        select_rh(sel, &view, 10.0, &st);
        assert_true(listed(sel, g1));
        assert_true(listed(sel, b));
        assert_false(listed(sel, g2));
        assert_false(listed(sel, a));
        assert_true(st.cost == 2.0);
        tclod_selector_destroy(sel);
    }
}

/* ---- value functions (eq. 8-11) ----------------------------------------------- */

static void value_functions_match_the_robin_hood_paper(void **state) {
    (void)state;
    /* a = 4, z = 16, d = 20, I = 0.5 */
    assert_true(tclod_value_of(TCLOD_VALUE_AREA_SQRT_DEPTH, 4.0, 16.0, 20.0, 0.5) ==
                4.0 / 4.0 * 0.5);
    assert_true(tclod_value_of(TCLOD_VALUE_AREA_DEPTH, 4.0, 16.0, 20.0, 0.5) == 4.0 / 16.0 * 0.5);
    assert_true(tclod_value_of(TCLOD_VALUE_AREA_DEPTH2, 4.0, 16.0, 20.0, 0.5) == 4.0 / 256.0 * 0.5);
    assert_true(tclod_value_of(TCLOD_VALUE_SQRT_AREA_DISTANCE2, 4.0, 16.0, 20.0, 0.5) ==
                2.0 / 400.0 * 0.5);
    assert_true(tclod_value_of(TCLOD_VALUE_BENEFIT, 4.0, 16.0, 20.0, 0.5) == 0.5);
    assert_true(tclod_value_of(TCLOD_VALUE_AREA_DEPTH, NAN, 1.0, 1.0, 1.0) == 0.0);
    assert_true(tclod_value_of(TCLOD_VALUE_AREA_DEPTH, 1.0, 0.0, 1.0, 1.0) == 0.0);
    assert_true(tclod_value_of(TCLOD_VALUE_AREA_DEPTH, 1.0, 1.0, 1.0, -1.0) == 0.0);
    assert_true(tclod_value_of((tclod_value)99, 1.0, 1.0, 1.0, 1.0) == 0.0);
}

/* Two equal objects (radius 1) straight ahead of the reference view at depths
 * 10 and 40, importance 1: with a / z², values pi/100 and pi/1600, shares 16 :
 * 1 of 17. Levels cost 1, 2, 16: the near one takes 16, the far one 1. */
static void values_follow_the_view(void **state) {
    helper_fixture *f = (helper_fixture *)*state;
    float near_b[4] = {0.0f, 0.0f, -10.0f, 1.0f}, far_b[4] = {0.0f, 0.0f, -40.0f, 1.0f};
    tclod_id near_id, far_id, prev;
    tclod_selector *sel;
    tclod_view view;
    tclod_stats st;
    assert_int_equal(table_add_node(&f->model, f->scene, TCLOD_NONE, near_b, 1.0, 1.0, &near_id),
                     TCLOD_OK);
    assert_int_equal(table_add_node(&f->model, f->scene, near_id, near_b, 1.0, 2.0, &prev),
                     TCLOD_OK);
    assert_int_equal(table_add_node(&f->model, f->scene, prev, near_b, 1.0, 16.0, &prev), TCLOD_OK);
    assert_int_equal(table_add_node(&f->model, f->scene, TCLOD_NONE, far_b, 1.0, 1.0, &far_id),
                     TCLOD_OK);
    assert_int_equal(table_add_node(&f->model, f->scene, far_id, far_b, 1.0, 2.0, &prev), TCLOD_OK);
    assert_int_equal(table_add_node(&f->model, f->scene, prev, far_b, 1.0, 16.0, &prev), TCLOD_OK);
    helper_view(&view);
    sel = rh_selector(f, TCLOD_VALUE_AREA_DEPTH2, TCLOD_MISFIT_DROP);
    select_rh(sel, &view, 17.0 * (1.0 + 1e-6), &st);
    assert_true(listed(sel, near_id + 2u));
    assert_true(listed(sel, far_id));
    tclod_selector_destroy(sel);
}

/* Two objects of radius 1 (a = pi) and importance 1 under the reference view
 * (eye at the origin, looking down -z): P on the axis at depth 5 (z = d = 5),
 * Q off it at (6, 0, -8) (z = 8, d = 10), so depth and distance differ. A
 * chain with the given level costs for each; P's finest is the cheaper, so P
 * goes first. */
static void add_off_axis_pair(helper_fixture *f, const double *cp, int np, const double *cq, int nq,
                              tclod_id *p, tclod_id *q) {
    static const float bp[4] = {0.0f, 0.0f, -5.0f, 1.0f}, bq[4] = {6.0f, 0.0f, -8.0f, 1.0f};
    tclod_id prev;
    int k;
    assert_int_equal(table_add_node(&f->model, f->scene, TCLOD_NONE, bp, 1.0, cp[0], p), TCLOD_OK);
    for (k = 1, prev = *p; k < np; ++k)
        assert_int_equal(table_add_node(&f->model, f->scene, prev, bp, 1.0, cp[k], &prev),
                         TCLOD_OK);
    assert_int_equal(table_add_node(&f->model, f->scene, TCLOD_NONE, bq, 1.0, cq[0], q), TCLOD_OK);
    for (k = 1, prev = *q; k < nq; ++k)
        assert_int_equal(table_add_node(&f->model, f->scene, prev, bq, 1.0, cq[k], &prev),
                         TCLOD_OK);
}

/* a / sqrt(z) (eq. 8) with the pair above, budget 10: v_P = pi/sqrt 5 =
 * 1.40496, v_Q = pi/sqrt 8 = 1.11072, so P's share is 10 * 1.40496 /
 * 2.51568 = 5.5848: of P's levels 1, 5.5, 5.7 it takes 5.5, and Q the 4.5
 * left (levels 1, 4.5, 6): total 10, no increment. With Q's distance (10) in
 * place of its depth, v_Q = pi/sqrt 10 = 0.99346 and P's share 5.8579 would
 * take 5.7, leaving Q 4.3 and its level 0. */
static void area_sqrt_depth_shares_follow_the_depth_not_the_distance(void **state) {
    helper_fixture *f = (helper_fixture *)*state;
    static const double cp[3] = {1.0, 5.5, 5.7}, cq[3] = {1.0, 4.5, 6.0};
    tclod_id p, q;
    tclod_selector *sel;
    tclod_view view;
    tclod_stats st;
    add_off_axis_pair(f, cp, 3, cq, 3, &p, &q);
    helper_view(&view);
    sel = rh_selector(f, TCLOD_VALUE_AREA_SQRT_DEPTH, TCLOD_MISFIT_DROP);
    select_rh(sel, &view, 10.0 * (1.0 + 1e-6), &st);
    assert_true(listed(sel, p + 1u));
    assert_true(listed(sel, q + 1u));
    assert_true(st.cost == 10.0);
    assert_int_equal(st.increments, 0);
    tclod_selector_destroy(sel);
}

/* sqrt(a) / d² (eq. 11) with the pair above, budget 10: v_P = sqrt(pi)/25,
 * v_Q = sqrt(pi)/100, so P's share is 10 * 4/5 = 8: of P's levels 1, 4, 7.9,
 * 8.5 it takes 7.9, and Q the 2.1 left (levels 1, 2.1, 5, 9): total 10, no
 * increment. With the distance left out (d = 1) the values would be equal
 * and P's share 5; with Q's depth (8) in place of its distance, v_Q =
 * sqrt(pi)/64 and P's share 10 * 64/89 = 7.191. Either way P would take 4 and
 * Q 5, with 1 left that no step fits. */
static void sqrt_area_distance2_shares_follow_the_distance(void **state) {
    helper_fixture *f = (helper_fixture *)*state;
    static const double cp[4] = {1.0, 4.0, 7.9, 8.5}, cq[4] = {1.0, 2.1, 5.0, 9.0};
    tclod_id p, q;
    tclod_selector *sel;
    tclod_view view;
    tclod_stats st;
    add_off_axis_pair(f, cp, 4, cq, 4, &p, &q);
    helper_view(&view);
    sel = rh_selector(f, TCLOD_VALUE_SQRT_AREA_DISTANCE2, TCLOD_MISFIT_DROP);
    select_rh(sel, &view, 10.0 * (1.0 + 1e-6), &st);
    assert_true(listed(sel, p + 2u));
    assert_true(listed(sel, q + 1u));
    assert_true(fabs(st.cost - 10.0) < 1e-12);
    assert_int_equal(st.increments, 0);
    tclod_selector_destroy(sel);
}

/* The pair above as smooth objects (importance w = 1, cost 10 r for P, 10.01 r
 * for Q, so P goes first), budget 10. a / sqrt(z): P's share 5.5848 buys r =
 * 0.55848 (with the distance for the depth, 5.8579 would buy 0.58579).
 * sqrt(a) / d²: P's share 8 buys 0.8 (without the distance 5 would buy 0.5,
 * with the depth 7.191 would buy 0.7191). Q takes what is left. */
static void smooth_values_follow_the_depth_and_the_distance(void **state) {
    helper_fixture *f = (helper_fixture *)*state;
    static const float bp[4] = {0.0f, 0.0f, -5.0f, 1.0f}, bq[4] = {6.0f, 0.0f, -8.0f, 1.0f};
    static const tclod_value values[2] = {TCLOD_VALUE_AREA_SQRT_DEPTH,
                                          TCLOD_VALUE_SQRT_AREA_DISTANCE2};
    static const double share_p[2] = {5.5848, 8.0};
    tclod_id p, q;
    tclod_view view;
    int i;
    assert_int_equal(
        table_add_smooth(&f->model, f->scene, bp, TABLE_POWER, 1.0, 0.5, 10.0, 10.0, 0.0, &p),
        TCLOD_OK);
    assert_int_equal(
        table_add_smooth(&f->model, f->scene, bq, TABLE_POWER, 1.0, 0.5, 10.01, 10.01, 0.0, &q),
        TCLOD_OK);
    helper_view(&view);
    for (i = 0; i < 2; ++i) {
        tclod_selector *sel = rh_selector(f, values[i], TCLOD_MISFIT_DROP);
        tclod_stats st;
        select_rh(sel, &view, 10.0, &st);
        assert_true(fabs(tclod_selector_resolution(sel, p) - share_p[i] / 10.0) < 1e-4);
        assert_true(fabs(tclod_selector_resolution(sel, q) - (10.0 - share_p[i]) / 10.01) < 1e-4);
        tclod_selector_destroy(sel);
    }
}

/* ---- importance ------------------------------------------------------------------- */

/* An importance callback reading importance_by_id (NaN past its end), which
 * counts its calls and the last id it was asked about. */
static double importance_by_id[16];
static unsigned importance_calls;
static tclod_id importance_last_id;

static double test_importance(void *user, const tclod_query *q) {
    (void)user;
    importance_calls++;
    importance_last_id = q->id;
    return q->id < 16u ? importance_by_id[q->id] : NAN;
}

static tclod_selector *importance_selector(helper_fixture *f, tclod_value value, int strict) {
    tclod_selector_desc d;
    tclod_selector *sel;
    rh_desc(f, &d);
    d.callbacks.importance = test_importance;
    d.robin_hood.value = value;
    d.strict = strict;
    sel = rh_create(f, &d);
    importance_calls = 0;
    return sel;
}

/* Two chains with levels 1, 2, 4 and 6 and benefits 3 and 1, budget 8. With
 * the benefits as importance the shares are 6 : 2 (the first takes 6, the
 * second 2); with an importance of 1 for both they are 4 : 4 and each takes
 * 4. The importance is asked once per instance (its first node), the benefit
 * still decides visibility: a chain of benefit 0 is not asked. */
static void the_importance_callback_sets_the_shares_instead_of_the_benefit(void **state) {
    helper_fixture *f = (helper_fixture *)*state;
    static const double costs[4] = {1.0, 2.0, 4.0, 6.0};
    tclod_id big = add_chain(f, 3.0, costs, 4), small = add_chain(f, 1.0, costs, 4);
    tclod_id hidden = add_chain(f, 0.0, costs, 4);
    tclod_selector *sel = rh_selector(f, TCLOD_VALUE_BENEFIT, TCLOD_MISFIT_DROP);
    tclod_stats st;
    select_rh(sel, NULL, 8.0 * (1.0 + 1e-6), &st);
    assert_true(listed(sel, big + 3u));
    assert_true(listed(sel, small + 1u));
    tclod_selector_destroy(sel);

    importance_by_id[big] = importance_by_id[small] = 1.0;
    importance_by_id[hidden] = 1.0;
    sel = importance_selector(f, TCLOD_VALUE_BENEFIT, 0);
    select_rh(sel, NULL, 8.0 * (1.0 + 1e-6), &st);
    assert_true(listed(sel, big + 2u));
    assert_true(listed(sel, small + 2u));
    assert_true(st.cost == 8.0);
    assert_int_equal(st.increments, 0);
    assert_int_equal(importance_calls, 2);
    assert_int_equal(st.invalid_values, 0);
    tclod_selector_destroy(sel);
}

/* The importance multiplies the value function. a / z² (eq. 10) under the
 * reference view with values_follow_the_view's two objects (depths 10 and
 * 40, values pi/100 and pi/1600 with I = 1, levels 1, 2, 16): importance 1
 * and 16 make the values equal, and the budget of 17 gives shares of 8.5 to
 * each: both take 2, and cycle 3 has 13 left but no step of 14 fits. */
static void the_importance_multiplies_the_value_function(void **state) {
    helper_fixture *f = (helper_fixture *)*state;
    float near_b[4] = {0.0f, 0.0f, -10.0f, 1.0f}, far_b[4] = {0.0f, 0.0f, -40.0f, 1.0f};
    tclod_id near_id, far_id, prev;
    tclod_selector *sel;
    tclod_view view;
    tclod_stats st;
    assert_int_equal(table_add_node(&f->model, f->scene, TCLOD_NONE, near_b, 5.0, 1.0, &near_id),
                     TCLOD_OK);
    assert_int_equal(table_add_node(&f->model, f->scene, near_id, near_b, 1.0, 2.0, &prev),
                     TCLOD_OK);
    assert_int_equal(table_add_node(&f->model, f->scene, prev, near_b, 1.0, 16.0, &prev), TCLOD_OK);
    assert_int_equal(table_add_node(&f->model, f->scene, TCLOD_NONE, far_b, 5.0, 1.0, &far_id),
                     TCLOD_OK);
    assert_int_equal(table_add_node(&f->model, f->scene, far_id, far_b, 1.0, 2.0, &prev), TCLOD_OK);
    assert_int_equal(table_add_node(&f->model, f->scene, prev, far_b, 1.0, 16.0, &prev), TCLOD_OK);
    importance_by_id[near_id] = 1.0;
    importance_by_id[far_id] = 16.0;
    helper_view(&view);
    sel = importance_selector(f, TCLOD_VALUE_AREA_DEPTH2, 0);
    select_rh(sel, &view, 17.0 * (1.0 + 1e-6), &st);
    assert_true(listed(sel, near_id + 1u));
    assert_true(listed(sel, far_id + 1u));
    assert_true(st.cost == 4.0);
    assert_int_equal(importance_calls, 2);
    tclod_selector_destroy(sel);
}

/* A NaN importance counts as a bad value and gives no share: of two single
 * levels costing 1, budget 4, the one whose importance is NaN is dropped (its
 * share is 0) and the other takes its level. In strict mode the call fails
 * and the previous result stays. */
static void a_bad_importance_is_counted_and_gives_no_share(void **state) {
    helper_fixture *f = (helper_fixture *)*state;
    static const double c1[1] = {1.0};
    tclod_id a = add_chain(f, 1.0, c1, 1), b = add_chain(f, 1.0, c1, 1);
    tclod_selector *sel;
    tclod_frame fr = helper_frame(NULL, 4.0);
    tclod_stats st;
    importance_by_id[a] = NAN;
    importance_by_id[b] = 1.0;
    sel = importance_selector(f, TCLOD_VALUE_BENEFIT, 0);
    select_rh(sel, NULL, 4.0, &st);
    assert_false(listed(sel, a));
    assert_true(listed(sel, b));
    assert_int_equal(st.invalid_values, 1);
    assert_int_equal(st.dropped_roots, 1);
    tclod_selector_destroy(sel);

    importance_by_id[a] = 1.0;
    sel = importance_selector(f, TCLOD_VALUE_BENEFIT, 1);
    select_rh(sel, NULL, 4.0, &st);
    assert_true(listed(sel, a));
    importance_by_id[a] = -1.0;
    assert_int_equal(tclod_select(sel, &fr, &st), TCLOD_ERR_CALLBACK);
    assert_true(listed(sel, a));
    tclod_selector_destroy(sel);
}

/* A smooth object's importance comes from the callback too, asked with the
 * object's query. Two smooth objects of benefit w = 1 and 3 at r = 1, costs
 * r and 2 r, budget 1.5: with importance 3 and 1 (the reverse of their
 * benefits) the first's share 1.125 buys r = 1 for 1 and the second the 0.5
 * left, r = 0.25. */
static void the_importance_of_a_smooth_object_comes_from_the_callback(void **state) {
    helper_fixture *f = (helper_fixture *)*state;
    float b0[4] = {0.0f, 0.0f, 0.0f, 1.0f}, b1[4] = {5.0f, 0.0f, 0.0f, 1.0f};
    tclod_id s0, s1;
    tclod_selector *sel;
    tclod_stats st;
    assert_int_equal(
        table_add_smooth(&f->model, f->scene, b0, TABLE_POWER, 1.0, 0.5, 1.0, 1.0, 0.0, &s0),
        TCLOD_OK);
    assert_int_equal(
        table_add_smooth(&f->model, f->scene, b1, TABLE_POWER, 3.0, 0.5, 2.0, 2.0, 0.0, &s1),
        TCLOD_OK);
    importance_by_id[s0] = 3.0;
    importance_by_id[s1] = 1.0;
    sel = importance_selector(f, TCLOD_VALUE_BENEFIT, 0);
    select_rh(sel, NULL, 1.5, &st);
    assert_true(tclod_selector_resolution(sel, s0) == 1.0);
    assert_true(fabs(tclod_selector_resolution(sel, s1) - 0.25) < 1e-6);
    assert_int_equal(importance_calls, 2);
    assert_int_equal(importance_last_id, s1);
    tclod_selector_destroy(sel);
}

/* The worlds' benefit is screen area x weight; their importance is the weight
 * alone, whatever the area the query carries, so that the area-based value
 * functions do not count the area twice. A Robin Hood solve over the flyover
 * asks it once per visible instance, after the benefit. */
static unsigned world_benefit_calls, world_importance_calls;

static double counted_world_benefit(void *user, const tclod_query *q) {
    world_benefit_calls++;
    return world_benefit(user, q);
}

static double counted_world_importance(void *user, const tclod_query *q) {
    world_importance_calls++;
    return world_importance(user, q);
}

static void the_worlds_give_their_weight_as_importance(void **state) {
    world_flyover_desc fd;
    world_scene w;
    tclod_callbacks cb;
    tclod_selector_desc d;
    tclod_selector *sel;
    tclod_view view;
    tclod_frame fr;
    tclod_stats st;
    tclod_id id;
    (void)state;
    world_flyover_desc_default(&fd);
    fd.terrain_depth = 3;
    fd.objects = 200;
    assert_int_equal(world_build_flyover(&fd, &w), TCLOD_OK);
    cb = world_callbacks(&w);
    assert_true(cb.importance == world_importance);
    for (id = 0; id < w.node_count; ++id) {
        tclod_query q;
        memset(&q, 0, sizeof q);
        q.id = id;
        q.count = 1;
        q.screen_area = 10.0f;
        assert_true(cb.importance(cb.user, &q) == (double)w.weight[id]);
        assert_true(cb.benefit(cb.user, &q) == 10.0 * (double)w.weight[id]);
        q.screen_area = 1000.0f;
        assert_true(cb.importance(cb.user, &q) == (double)w.weight[id]);
    }
    tclod_selector_desc_default(&d);
    d.solver = TCLOD_SOLVER_ROBIN_HOOD;
    d.callbacks = cb;
    d.callbacks.benefit = counted_world_benefit;
    d.callbacks.importance = counted_world_importance;
    assert_int_equal(tclod_selector_create(w.scene, &d, NULL, &sel), TCLOD_OK);
    world_camera_at(&w.path, 0.1, &view);
    fr = helper_frame(&view, 2.0);
    world_benefit_calls = world_importance_calls = 0;
    assert_int_equal(tclod_select(sel, &fr, &st), TCLOD_OK);
    assert_true(world_importance_calls > 0);
    assert_true(world_importance_calls < world_benefit_calls);
    assert_true(st.cost <= 2.0);
    assert_int_equal(st.invalid_values, 0);
    tclod_selector_destroy(sel);
    world_scene_free(&w);
}

/* ---- the budget ------------------------------------------------------------------- */

static void budget_holds_on_random_scenes(void **state) {
    table_rng rng;
    int instance;
    (void)state;
    table_rng_seed(&rng, 99);
    for (instance = 0; instance < 2000; ++instance) {
        helper_fixture *f;
        tclod_selector_desc d;
        tclod_selector *sel;
        tclod_stats st;
        tclod_view view;
        const tclod_id *ids;
        const tclod_smooth_group *groups;
        size_t n, ng, i;
        double budget, sum = 0.0;
        uint32_t k, smooth = table_rng_below(&rng, 6), nodes = 3 + table_rng_below(&rng, 30);
        assert_int_equal(helper_fixture_setup((void **)&f), 0);
        assert_int_equal(
            table_random_hierarchy(&f->model, f->scene, &rng, nodes, 1 + table_rng_below(&rng, 3),
                                   table_rng_below(&rng, 2) ? TABLE_DIMINISHING : TABLE_ARBITRARY),
            TCLOD_OK);
        for (k = 0; k < smooth; ++k) {
            float b[4];
            double kc = table_rng_uniform(&rng, 0.1, 3.0);
            b[0] = (float)table_rng_uniform(&rng, -20.0, 20.0);
            b[1] = 0.0f;
            b[2] = (float)table_rng_uniform(&rng, -60.0, 10.0);
            b[3] = (float)table_rng_uniform(&rng, 0.1, 3.0);
            assert_int_equal(table_add_smooth(&f->model, f->scene, b, TABLE_POWER,
                                              table_rng_uniform(&rng, 0.5, 5.0), 0.5, kc,
                                              kc * table_rng_uniform(&rng, 1.0, 5.0),
                                              table_rng_uniform(&rng, 0.0, 0.1), NULL),
                             TCLOD_OK);
        }
        rh_desc(f, &d);
        d.robin_hood.value = (tclod_value)table_rng_below(&rng, 5);
        d.robin_hood.misfit = (tclod_misfit)table_rng_below(&rng, 2);
        sel = rh_create(f, &d);
        budget = table_rng_uniform(&rng, 0.0, 40.0);
        helper_view(&view);
        select_rh(sel, table_rng_below(&rng, 2) ? &view : NULL, budget, &st);
        assert_int_equal(tclod_selector_cut(sel, &ids, &n), TCLOD_OK);
        for (i = 0; i < n; ++i)
            sum += f->model.cost[ids[i]];
        assert_int_equal(tclod_selector_smooth_groups(sel, &groups, &ng), TCLOD_OK);
        for (i = 0; i < ng; ++i) {
            const tclod_id *order;
            uint32_t count;
            assert_int_equal(tclod_scene_smooth_order(f->scene, &order, &count), TCLOD_OK);
            assert_int_equal(groups[i].count, 1);
            sum +=
                table_smooth_cost_of(&f->model, order[groups[i].first], groups[i].resolution, NULL);
        }
        if (!(sum <= budget))
            fail_msg("instance %d: cost %.17g > budget %.17g", instance, sum, budget);
        assert_true(st.cost == sum);
        tclod_selector_destroy(sel);
        helper_fixture_teardown((void **)&f);
    }
}

#define FIXTURE_TEST(t) \
    cmocka_unit_test_setup_teardown(t, helper_fixture_setup, helper_fixture_teardown)

int main(void) {
    const struct CMUnitTest tests[] = {
        FIXTURE_TEST(equal_values_get_equal_shares),
        FIXTURE_TEST(leftover_of_a_simple_instance_reaches_a_complex_one),
        FIXTURE_TEST(instances_are_visited_simple_to_complex),
        FIXTURE_TEST(a_scene_change_orders_the_instances_again),
        FIXTURE_TEST(costs_are_asked_once_per_select_across_scene_changes),
        FIXTURE_TEST(a_scene_change_finds_the_branches_children_again),
        FIXTURE_TEST(the_leftover_refines_the_instances_that_can_refine),
        FIXTURE_TEST(shares_follow_the_values),
        FIXTURE_TEST(a_chain_of_more_than_255_levels_takes_its_finest_affordable_level),
        FIXTURE_TEST(an_instance_whose_simplest_level_exceeds_its_share_is_dropped),
        FIXTURE_TEST(the_coarsest_policy_draws_a_misfit_the_time_left_covers),
        FIXTURE_TEST(smooth_objects_take_the_resolution_their_share_buys),
        FIXTURE_TEST(a_leftover_below_a_2000th_of_the_budget_is_not_shared_again),
        FIXTURE_TEST(a_leftover_of_a_2000th_of_the_budget_is_shared_again),
        FIXTURE_TEST(a_branch_shares_its_time_among_its_children),
        FIXTURE_TEST(a_child_outside_the_frustum_is_culled_below_a_branch_inside_it),
        cmocka_unit_test(value_functions_match_the_robin_hood_paper),
        FIXTURE_TEST(values_follow_the_view),
        FIXTURE_TEST(area_sqrt_depth_shares_follow_the_depth_not_the_distance),
        FIXTURE_TEST(sqrt_area_distance2_shares_follow_the_distance),
        FIXTURE_TEST(smooth_values_follow_the_depth_and_the_distance),
        FIXTURE_TEST(the_importance_callback_sets_the_shares_instead_of_the_benefit),
        FIXTURE_TEST(the_importance_multiplies_the_value_function),
        FIXTURE_TEST(a_bad_importance_is_counted_and_gives_no_share),
        FIXTURE_TEST(the_importance_of_a_smooth_object_comes_from_the_callback),
        cmocka_unit_test(the_worlds_give_their_weight_as_importance),
        cmocka_unit_test(budget_holds_on_random_scenes),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
