/*
 * test_stream — residency (docs/streaming.md) in every solver: a node that is
 * not resident is never drawn, a replace refinement waits for all of its
 * children, an additive node's children join one by one, a hierarchy whose
 * root is not resident draws nothing and is counted in stats.absent_roots,
 * a warm start whose cut lost a node falls back to a resident ancestor, a
 * Robin Hood chain ends before its first level that is not resident, smooth
 * objects that are not resident are left out of every group; residency
 * flipped at random between frames; the scene's residency calls refusing
 * bad input and callbacks, changing nothing then, and the bookkeeping of
 * resident bytes.
 *
 * Increment of node n = replace n by its children:
 *   Δb = Σ benefit(children) - benefit(n), Δc = Σ cost(children) - cost(n).
 * A child that is not resident costs +inf below a replacing parent (the
 * increment is refused); below an additive parent, or as a root, it is
 * invisible (benefit 0, cost 0, its subtree culled).
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

/* ---- scenes and selectors ------------------------------------------------------ */

/* A scene, its table and the selector a test runs over them, if any: the
 * fixture closes it. */
typedef struct fixture {
    tclod_scene *s;
    table_model m;
    tclod_selector *sel;
} fixture;

static void open_fixture(fixture *f) {
    assert_int_equal(tclod_scene_create(NULL, &f->s), TCLOD_OK);
    table_init(&f->m);
    f->sel = NULL;
}

static void close_fixture(fixture *f) {
    tclod_selector_destroy(f->sel);
    tclod_scene_destroy(f->s);
    table_free(&f->m);
}

/* Adds a node without bounds; asserts success. */
static tclod_id add(fixture *f, tclod_id parent, double benefit, double cost, int additive,
                    int resident, double bytes) {
    tclod_node_desc d;
    tclod_id id = TCLOD_NONE;
    tclod_node_desc_default(&d);
    d.parent = parent;
    d.refine = additive ? TCLOD_REFINE_ADD : TCLOD_REFINE_REPLACE;
    d.not_resident = !resident;
    d.bytes = bytes;
    assert_int_equal(table_add_node_desc(&f->m, f->s, &d, benefit, cost, &id), TCLOD_OK);
    return id;
}

/* A smooth object with benefit w sqrt(r) and cost k r at (x, 0, 0). */
static tclod_id add_smooth(fixture *f, float x, double w, double k) {
    const float b[4] = {x, 0.0f, 0.0f, 1.0f};
    tclod_id id = TCLOD_NONE;
    assert_int_equal(table_add_smooth(&f->m, f->s, b, TABLE_POWER, w, 0.5, k, k, 0.0, &id),
                     TCLOD_OK);
    return id;
}

/* The configurations every test runs: each solver, the greedy warm and cold
 * and with a lookahead. */
enum { GREEDY_WARM, GREEDY_COLD, GREEDY_LOOKAHEAD, MIXED, ROBIN_HOOD, SOLVERS };
static const char *const solver_name[SOLVERS] = {"greedy", "greedy cold", "greedy lookahead",
                                                 "mixed", "robin hood"};

/* The solver a configuration runs. */
static tclod_solver solver_for(int which) {
    return which == MIXED        ? TCLOD_SOLVER_MIXED
           : which == ROBIN_HOOD ? TCLOD_SOLVER_ROBIN_HOOD
                                 : TCLOD_SOLVER_GREEDY;
}

static tclod_selector *make_selector(fixture *f, int which) {
    tclod_selector_desc d;
    tclod_selector *sel = NULL;
    tclod_selector_desc_default(&d);
    table_mixed_callbacks(&f->m, &d.callbacks);
    d.solver = solver_for(which);
    d.cold_start = which == GREEDY_COLD;
    d.greedy.lookahead = which == GREEDY_LOOKAHEAD ? 2u : 0u;
    /* shares in proportion to the benefits themselves */
    d.robin_hood.value = TCLOD_VALUE_BENEFIT;
    assert_int_equal(tclod_selector_create(f->s, &d, NULL, &sel), TCLOD_OK);
    return sel;
}

/* Makes the fixture's selector for configuration `which`, destroying the
 * one it held. */
static tclod_selector *use_selector(fixture *f, int which) {
    tclod_selector_destroy(f->sel);
    f->sel = make_selector(f, which);
    return f->sel;
}

/* A test body: builds its scene in a fresh fixture and selects with
 * configuration `which`. */
typedef void solver_body(fixture *f, int which);

typedef struct solver_case {
    solver_body *body;
} solver_case;

/* The cmocka test of a solver_case (its state): for each configuration,
 * opens a fixture, runs the body and closes the fixture. */
static void each_solver(void **state) {
    const solver_case *c = (const solver_case *)*state;
    int which;
    for (which = 0; which < SOLVERS; ++which) {
        fixture f;
        open_fixture(&f);
        c->body(&f, which);
        close_fixture(&f);
    }
}

/* The entry of body `b` in main's list of tests, under the body's name. */
/* clang-format off */
#define EACH_SOLVER(b) {#b, each_solver, NULL, NULL, &(solver_case){b}}
/* clang-format on */

static void select_budget(tclod_selector *sel, double budget, uint32_t max_iterations,
                          tclod_stats *st) {
    tclod_frame fr;
    memset(&fr, 0, sizeof fr);
    fr.budget = budget;
    fr.max_iterations = max_iterations;
    assert_int_equal(tclod_select(sel, &fr, st), TCLOD_OK);
}

/* Asserts that the cut is expected[0..n) as a set, that no node in it is
 * listed twice or is not resident, and that st->cost is the cut's cost with
 * the smooth groups' (<= budget). */
static void expect_cut(const fixture *f, const tclod_selector *sel, const tclod_stats *st,
                       double budget, const tclod_id *expected, size_t n, const char *what) {
    const tclod_id *ids = NULL;
    const tclod_smooth_group *g = NULL;
    tclod_id got[64], want[64];
    size_t got_n = 0, ng = 0, i;
    double cost = 0.0;
    assert_int_equal(tclod_selector_cut(sel, &ids, &got_n), TCLOD_OK);
    assert_true(got_n <= 64 && n <= 64);
    for (i = 0; i < got_n; ++i) {
        got[i] = ids[i];
        cost += f->m.cost[ids[i]];
        if (!tclod_scene_node_resident(f->s, ids[i]))
            fail_msg("%s: node %u is drawn and not resident", what, (unsigned)ids[i]);
    }
    assert_int_equal(tclod_selector_smooth_groups(sel, &g, &ng), TCLOD_OK);
    for (i = 0; i < ng; ++i)
        cost += g[i].cost;
    if (n)
        memcpy(want, expected, n * sizeof *want);
    exact_sort_ids(got, got_n);
    exact_sort_ids(want, n);
    for (i = 0; i + 1 < got_n; ++i)
        if (got[i] == got[i + 1])
            fail_msg("%s: node %u is listed twice", what, (unsigned)got[i]);
    helper_assert_ids(what, got, got_n, want, n);
    if (!(cost <= budget) || st->cost != cost)
        fail_msg("%s: cost %.17g (stats %.17g), budget %.17g", what, cost, st->cost, budget);
}

/* Selects with `budget` into *st, then expect_cut. */
static void select_expect(const fixture *f, tclod_selector *sel, tclod_stats *st, double budget,
                          const tclod_id *expected, size_t n, const char *what) {
    select_budget(sel, budget, 0, st);
    expect_cut(f, sel, st, budget, expected, n, what);
}

/* Sets node n's residency; asserts success. */
static void set_resident(fixture *f, tclod_id n, int resident) {
    assert_int_equal(tclod_scene_set_resident(f->s, n, resident), TCLOD_OK);
}

/* ---- refinement -------------------------------------------------------------------- */

static void a_half_loaded_refinement_keeps_its_parent(fixture *f, int which) {
    /* R (b 1, c 1) with children A (b 3, c 1) and B (b 3, c 1, not resident),
     * budget 10. R -> {A, B} would gain 5 for 1 more, but B costs +inf while
     * it is not resident: R stays, cost 1. Once B is resident the increment
     * is taken: {A, B}, cost 2. A smooth object far away (b sqrt(r), c 0.5 r:
     * 0.5 at full resolution) lets the mixed solver run its own loop; it fits
     * beside either cut. */
    tclod_selector *sel;
    tclod_stats st;
    tclod_id r, a, b;
    r = add(f, TCLOD_NONE, 1.0, 1.0, 0, 1, 0.0);
    a = add(f, r, 3.0, 1.0, 0, 1, 0.0);
    b = add(f, r, 3.0, 1.0, 0, 0, 0.0);
    add_smooth(f, 100.0f, 1.0, 0.5);
    sel = use_selector(f, which);
    select_expect(f, sel, &st, 10.0, &r, 1, solver_name[which]);
    assert_int_equal(st.absent_roots, 0);
    set_resident(f, b, 1);
    select_expect(f, sel, &st, 10.0, (const tclod_id[]){a, b}, 2, solver_name[which]);
    /* B unloaded again: the warm start takes R back (A alone is no cut) */
    set_resident(f, b, 0);
    select_expect(f, sel, &st, 10.0, &r, 1, solver_name[which]);
}

/* A cost callback answering -0 for every node (the table's values otherwise):
 * -0 is a valid cost (docs/api.md), and goes another way through the
 * evaluation than positive costs. */
static double cost_or_minus_zero(void *user, const tclod_query *q) {
    double c = table_cost(user, q);
    return c == 0.0 ? -0.0 : c;
}

static void a_node_not_resident_costing_minus_zero_is_not_drawn(fixture *f, int which) {
    /* R (b 1, c 1) with children A (b 3, c -0, not resident) and B (b 3, c 1):
     * as above, A costs +inf while it is not resident, whatever its cost:
     * the cut stays {R}, cost 1, budget 10. */
    tclod_selector_desc d;
    tclod_selector *sel = NULL;
    tclod_stats st;
    tclod_id r;
    r = add(f, TCLOD_NONE, 1.0, 1.0, 0, 1, 0.0);
    add(f, r, 3.0, 0.0, 0, 0, 0.0);
    add(f, r, 3.0, 1.0, 0, 1, 0.0);
    tclod_selector_desc_default(&d);
    table_mixed_callbacks(&f->m, &d.callbacks);
    d.callbacks.cost = cost_or_minus_zero;
    d.solver = solver_for(which);
    d.greedy.lookahead = which == GREEDY_LOOKAHEAD ? 2u : 0u;
    assert_int_equal(tclod_selector_create(f->s, &d, NULL, &f->sel), TCLOD_OK);
    sel = f->sel;
    select_expect(f, sel, &st, 10.0, &r, 1, solver_name[which]);
}

static void additive_children_join_one_by_one(fixture *f, int which) {
    /* Additive root A (b 2, c 1) with children C1 and C2 (b 3, c 1 each), both
     * not resident, budget 10. A -> {A, C1, C2} gains 0 (the children are
     * invisible): {A}, cost 1. C1 arrives: the increment gains 3 for 1 more,
     * {A, C1}, cost 2 (C2 is still invisible). C2 arrives: {A, C1, C2}, cost
     * 3. Warm starts find C2 in their cut and count it once it is
     * resident. */
    tclod_selector *sel;
    tclod_stats st;
    tclod_id a, c1, c2;
    a = add(f, TCLOD_NONE, 2.0, 1.0, 1, 1, 0.0);
    c1 = add(f, a, 3.0, 1.0, 0, 0, 0.0);
    c2 = add(f, a, 3.0, 1.0, 0, 0, 0.0);
    add_smooth(f, 100.0f, 1.0, 0.5);
    sel = use_selector(f, which);
    select_expect(f, sel, &st, 10.0, &a, 1, solver_name[which]);
    set_resident(f, c1, 1);
    select_expect(f, sel, &st, 10.0, (const tclod_id[]){a, c1}, 2, solver_name[which]);
    set_resident(f, c2, 1);
    select_expect(f, sel, &st, 10.0, (const tclod_id[]){a, c1, c2}, 3, solver_name[which]);
    /* and leave one by one: C1 unloaded, {A, C2} */
    set_resident(f, c1, 0);
    select_expect(f, sel, &st, 10.0, (const tclod_id[]){a, c2}, 2, solver_name[which]);
}

static void a_hierarchy_whose_root_is_not_resident_draws_nothing_and_is_counted(fixture *f,
                                                                                int which) {
    /* Roots R1, R2 (b 1, c 1), each with two children (b 2, c 1), and R3
     * (b 0: not visible, not resident, no children), budget 10. All
     * resident: every increment fits, the four children are drawn (cost 4),
     * no absent root. R2 unloaded: its hierarchy draws nothing, also for a
     * warm start whose cut held R2's children: {R1a, R1b}, cost 2, and one
     * absent root (R3 is not visible: not counted), again at the next select
     * (a count per select, not a sum). R3 unloaded changes nothing. R2 back:
     * the four children again, no absent root. */
    tclod_selector *sel;
    tclod_stats st;
    tclod_id r1, r2, r3, kids[4];
    const char *what = solver_name[which];
    r1 = add(f, TCLOD_NONE, 1.0, 1.0, 0, 1, 0.0);
    kids[0] = add(f, r1, 2.0, 1.0, 0, 1, 0.0);
    kids[1] = add(f, r1, 2.0, 1.0, 0, 1, 0.0);
    r2 = add(f, TCLOD_NONE, 1.0, 1.0, 0, 1, 0.0);
    kids[2] = add(f, r2, 2.0, 1.0, 0, 1, 0.0);
    kids[3] = add(f, r2, 2.0, 1.0, 0, 1, 0.0);
    r3 = add(f, TCLOD_NONE, 0.0, 1.0, 0, 1, 0.0);
    add_smooth(f, 100.0f, 1.0, 0.5);
    sel = use_selector(f, which);
    select_expect(f, sel, &st, 10.0, kids, 4, what);
    assert_int_equal(st.absent_roots, 0);
    set_resident(f, r2, 0);
    set_resident(f, r3, 0);
    select_expect(f, sel, &st, 10.0, kids, 2, what);
    assert_int_equal(st.absent_roots, 1);
    select_expect(f, sel, &st, 10.0, kids, 2, what);
    assert_int_equal(st.absent_roots, 1);
    set_resident(f, r2, 1);
    select_expect(f, sel, &st, 10.0, kids, 4, what);
    assert_int_equal(st.absent_roots, 0);
}

static void an_additive_child_not_resident_hides_its_subtree_from_a_warm_start(fixture *f,
                                                                               int which) {
    /* Additive root A (b 1, c 1) with child C (b 2, c 1), whose children C1,
     * C2 (b 3, c 1) are drawn: {A, C1, C2}, cost 3 (budget 10). C unloaded:
     * as the child of an additive node it is invisible, its subtree draws
     * nothing: {A}, cost 1, also from the warm start that held C1 and C2. */
    tclod_selector *sel;
    tclod_stats st;
    tclod_id ids[3], c;
    ids[0] = add(f, TCLOD_NONE, 1.0, 1.0, 1, 1, 0.0);
    c = add(f, ids[0], 2.0, 1.0, 0, 1, 0.0);
    ids[1] = add(f, c, 3.0, 1.0, 0, 1, 0.0);
    ids[2] = add(f, c, 3.0, 1.0, 0, 1, 0.0);
    sel = use_selector(f, which);
    select_expect(f, sel, &st, 10.0, ids, 3, solver_name[which]);
    set_resident(f, c, 0);
    select_expect(f, sel, &st, 10.0, ids, 1, solver_name[which]);
    assert_int_equal(st.absent_roots, 0);
}

/* ---- warm starts ---------------------------------------------------------------------- */

/* R -> {A -> {A1, A2}, B} and Q -> {Q1, Q2}: every node b 1 at the roots, 2
 * one level down, 3 at A1, A2; costs as given. */
typedef struct two_trees {
    tclod_id r, a, b, a1, a2, q, q1, q2;
} two_trees;

static void build_two_trees(fixture *f, two_trees *t, double r_cost) {
    t->r = add(f, TCLOD_NONE, 1.0, r_cost, 0, 1, 0.0);
    t->a = add(f, t->r, 2.0, 1.0, 0, 1, 0.0);
    t->a1 = add(f, t->a, 3.0, 1.0, 0, 1, 0.0);
    t->a2 = add(f, t->a, 3.0, 1.0, 0, 1, 0.0);
    t->b = add(f, t->r, 2.0, 1.0, 0, 1, 0.0);
    t->q = add(f, TCLOD_NONE, 1.0, 1.0, 0, 1, 0.0);
    t->q1 = add(f, t->q, 2.0, 1.0, 0, 1, 0.0);
    t->q2 = add(f, t->q, 2.0, 1.0, 0, 1, 0.0);
}

static void a_warm_start_whose_cut_lost_a_node_falls_back_to_a_resident_ancestor(fixture *f,
                                                                                 int which) {
    /* Costs 1 everywhere, budget 10: every increment fits (R -> {A, B}: Δb 3,
     * Δc 1; A -> {A1, A2}: Δb 4, Δc 1; Q -> {Q1, Q2}: Δb 3, Δc 1), the cut is
     * {A1, A2, B, Q1, Q2}, cost 5. The host unloads A1 and A, a drawn node
     * and the parent it would fall back to. The warm start replaces A1 by
     * its nearest resident ancestor R, which takes the place of R's cut
     * nodes; R cannot refine while A is missing: {R, Q1, Q2}, cost 3,
     * reached without a decrement or an increment (Q's subtree untouched),
     * so that even a limit of one iteration gets it. */
    two_trees t;
    tclod_selector *sel;
    tclod_stats st;
    const char *what = solver_name[which];
    if (which == GREEDY_COLD || which == ROBIN_HOOD)
        return; /* no warm start */
    build_two_trees(f, &t, 1.0);
    sel = use_selector(f, which);
    select_expect(f, sel, &st, 10.0, (const tclod_id[]){t.a1, t.a2, t.b, t.q1, t.q2}, 5, what);
    set_resident(f, t.a1, 0);
    set_resident(f, t.a, 0);
    select_budget(sel, 10.0, 1, &st);
    expect_cut(f, sel, &st, 10.0, (const tclod_id[]){t.r, t.q1, t.q2}, 3, what);
    assert_int_equal(st.decrements, 0);
    assert_int_equal(st.increments, 0);
}

static void a_fallback_over_the_budget_is_brought_within_it(fixture *f, int which) {
    /* As above with R costing 4 and a budget of 5: the roots cost 5 and fit;
     * R -> {A, B} saves 2 (Δc -2) and is taken, then A -> {A1, A2} and
     * Q -> {Q1, Q2}, 1 more each: {A1, A2, B, Q1, Q2}, cost 5. With A1 and A
     * unloaded R falls back in, {R, Q1, Q2} costs 6 > 5, and the warm start
     * collapses Q's children (the only decrement): {R, Q}, cost 5. */
    two_trees t;
    tclod_selector *sel;
    tclod_stats st;
    const char *what = solver_name[which];
    if (which == GREEDY_COLD || which == ROBIN_HOOD)
        return;
    build_two_trees(f, &t, 4.0);
    sel = use_selector(f, which);
    select_expect(f, sel, &st, 5.0, (const tclod_id[]){t.a1, t.a2, t.b, t.q1, t.q2}, 5, what);
    set_resident(f, t.a1, 0);
    set_resident(f, t.a, 0);
    select_expect(f, sel, &st, 5.0, (const tclod_id[]){t.r, t.q}, 2, what);
    assert_int_equal(st.decrements, 1);
}

static void a_lookahead_jump_may_pass_a_node_that_is_not_resident(void **state) {
    /* P (b 1, c 1) -> X (b 1.25, c 2) -> {X1, X2} (b 5, c 1.5 each), budget
     * 10, lookahead 2. The plain increment P -> X gains 0.25 per unit of
     * cost, the jump P -> {X1, X2} 9 for 2 (4.5): the jump is taken, cost 3.
     * X unloaded: the drawn nodes are resident, and the warm start keeps
     * them; a cold solve cannot refine P into X, nor jump past it (a jump
     * passes only nodes it could draw): {P}. X1 unloaded as well: the warm
     * start falls back past X to P. */
    fixture f;
    tclod_selector *warm, *cold;
    tclod_stats st;
    tclod_id p, x, x12[2];
    (void)state;
    open_fixture(&f);
    p = add(&f, TCLOD_NONE, 1.0, 1.0, 0, 1, 0.0);
    x = add(&f, p, 1.25, 2.0, 0, 1, 0.0);
    x12[0] = add(&f, x, 5.0, 1.5, 0, 1, 0.0);
    x12[1] = add(&f, x, 5.0, 1.5, 0, 1, 0.0);
    warm = make_selector(&f, GREEDY_LOOKAHEAD);
    select_expect(&f, warm, &st, 10.0, x12, 2, "lookahead");
    assert_int_equal(st.increments, 1);
    set_resident(&f, x, 0);
    select_expect(&f, warm, &st, 10.0, x12, 2, "lookahead, warm");
    cold = make_selector(&f, GREEDY_LOOKAHEAD);
    select_expect(&f, cold, &st, 10.0, &p, 1, "lookahead, cold");
    set_resident(&f, x12[0], 0);
    select_expect(&f, warm, &st, 10.0, &p, 1, "lookahead, warm");
    tclod_selector_destroy(cold);
    tclod_selector_destroy(warm);
    close_fixture(&f);
}

/* ---- chains ---------------------------------------------------------------------- */

static void a_chain_ends_before_its_first_level_that_is_not_resident(fixture *f, int which) {
    /* One object of three levels L0 -> L1 -> L2 (b 1, 2, 3; c 1, 2, 3). With
     * a budget of 10 every solver draws L2 (cost 3). L1 unloaded: L2 is
     * resident, but no solver refines past L1 (the Robin Hood solver's
     * search, which starts at the level taken last, included): L0, cost 1.
     * L1 back and L2 unloaded: L1, cost 2. With an infinite budget and L1
     * unloaded: L0 again. */
    tclod_selector *sel;
    tclod_stats st;
    tclod_id l[3];
    const char *what = solver_name[which];
    l[0] = add(f, TCLOD_NONE, 1.0, 1.0, 0, 1, 0.0);
    l[1] = add(f, l[0], 2.0, 2.0, 0, 1, 0.0);
    l[2] = add(f, l[1], 3.0, 3.0, 0, 1, 0.0);
    sel = use_selector(f, which);
    select_expect(f, sel, &st, 10.0, &l[2], 1, what);
    set_resident(f, l[1], 0);
    if (which == GREEDY_WARM || which == GREEDY_LOOKAHEAD || which == MIXED) {
        /* a warm start keeps L2: it is resident */
        select_expect(f, sel, &st, 10.0, &l[2], 1, what);
        sel = use_selector(f, which);
    }
    select_expect(f, sel, &st, 10.0, &l[0], 1, what);
    set_resident(f, l[1], 1);
    set_resident(f, l[2], 0);
    select_expect(f, sel, &st, 10.0, &l[1], 1, what);
    set_resident(f, l[1], 0);
    set_resident(f, l[2], 1);
    sel = use_selector(f, which);
    select_expect(f, sel, &st, HUGE_VAL, &l[0], 1, what);
}

/* ---- smooth objects ---------------------------------------------------------------- */

static void smooth_objects_not_resident_are_in_no_group(void **state) {
    /* Three smooth objects (b sqrt(r), c r each), budget 100: each is drawn at
     * full resolution (cost 3 in all). The middle one unloaded: resolution 0
     * and in no group, the others still at 1 (cost 2); with variables split
     * or shared alike. Back: 1 again. */
    static const int solvers[3] = {MIXED, MIXED, ROBIN_HOOD};
    int k;
    (void)state;
    for (k = 0; k < 3; ++k) {
        fixture f;
        tclod_selector_desc d;
        tclod_selector *sel = NULL;
        tclod_stats st;
        const tclod_smooth_group *g = NULL;
        const tclod_id *order = NULL;
        uint32_t order_n = 0;
        size_t ng = 0, i;
        tclod_id o[3];
        open_fixture(&f);
        o[0] = add_smooth(&f, -5.0f, 1.0, 1.0);
        o[1] = add_smooth(&f, 0.0f, 1.0, 1.0);
        o[2] = add_smooth(&f, 5.0f, 1.0, 1.0);
        tclod_selector_desc_default(&d);
        table_mixed_callbacks(&f.m, &d.callbacks);
        d.solver = solvers[k] == MIXED ? TCLOD_SOLVER_MIXED : TCLOD_SOLVER_ROBIN_HOOD;
        d.mixed.split_smooth = k == 1;
        d.robin_hood.value = TCLOD_VALUE_BENEFIT;
        assert_int_equal(tclod_selector_create(f.s, &d, NULL, &sel), TCLOD_OK);
        select_budget(sel, 100.0, 0, &st);
        for (i = 0; i < 3; ++i)
            assert_true(tclod_selector_resolution(sel, o[i]) == 1.0);
        assert_true(st.cost == 3.0);
        assert_int_equal(tclod_scene_set_smooth_resident(f.s, o[1], 0), TCLOD_OK);
        select_budget(sel, 100.0, 0, &st);
        assert_true(tclod_selector_resolution(sel, o[0]) == 1.0);
        assert_true(tclod_selector_resolution(sel, o[1]) == 0.0);
        assert_true(tclod_selector_resolution(sel, o[2]) == 1.0);
        assert_true(st.cost == 2.0);
        assert_int_equal(tclod_scene_smooth_order(f.s, &order, &order_n), TCLOD_OK);
        assert_int_equal(tclod_selector_smooth_groups(sel, &g, &ng), TCLOD_OK);
        for (i = 0; i < ng; ++i) {
            uint32_t j;
            for (j = g[i].first; j < g[i].first + g[i].count; ++j)
                assert_true(order[j] != o[1]);
        }
        assert_int_equal(tclod_scene_set_smooth_resident(f.s, o[1], 1), TCLOD_OK);
        select_budget(sel, 100.0, 0, &st);
        assert_true(tclod_selector_resolution(sel, o[1]) == 1.0);
        tclod_selector_destroy(sel);
        close_fixture(&f);
    }
}

/* ---- a randomised run -------------------------------------------------------------- */

/* Whether node n is the top of a hierarchy of its own for residency: a root
 * or an additive node's child. */
static int top(const fixture *f, tclod_id n) {
    tclod_id p = f->m.parent[n];
    return p == TCLOD_NONE || f->m.kind[p] == TABLE_ADD;
}

static void residency_flipped_at_random_never_draws_a_node_not_resident(void **state) {
    /* A random hierarchy, chains of four levels, additive nodes with
     * children and smooth objects; 40 frames (seeded), each flipping the
     * residency of about a tenth of the nodes and smooth objects, then
     * selecting with every configuration, a warm selector of each kept from
     * frame to frame and a fresh one. Every result: nodes listed once, each
     * resident, none below a node that is not resident and the top of its
     * hierarchy; for a fresh selector none below a node that is not resident
     * at all (refinement never passes one; a warm start may keep resident
     * nodes below one); smooth groups of resident objects only; the cost
     * within the budget; absent_roots the roots that are not resident (all
     * visible). */
    fixture f;
    table_rng rng;
    tclod_selector *warm[SOLVERS];
    uint32_t i, frame, smooth_n;
    int which;
    (void)state;
    open_fixture(&f);
    table_rng_seed(&rng, 2201);
    assert_int_equal(table_random_hierarchy(&f.m, f.s, &rng, 120, 6, TABLE_DIMINISHING), TCLOD_OK);
    assert_int_equal(table_chains(&f.m, f.s, &rng, 10, 4, 0.0f), TCLOD_OK);
    for (i = 0; i < 6; ++i) {
        tclod_id a = add(&f, TCLOD_NONE, 2.0, 1.0, 1, 1, 0.0), c;
        c = add(&f, a, 3.0, 1.0, 0, 1, 0.0);
        add(&f, a, 3.0, 1.0, 1, 1, 0.0);
        add(&f, c, 2.0, 0.75, 0, 1, 0.0);
        add(&f, c, 2.0, 0.75, 0, 1, 0.0);
    }
    for (i = 0; i < 12; ++i)
        add_smooth(&f, (float)i * 4.0f, 1.0 + (double)i, 0.5 + 0.1 * (double)i);
    smooth_n = tclod_scene_smooth_count(f.s);
    for (which = 0; which < SOLVERS; ++which)
        warm[which] = make_selector(&f, which);
    for (frame = 0; frame < 40; ++frame) {
        double budget = table_rng_uniform(&rng, 0.0, 1.2) * table_leaves_cost(&f.m);
        uint32_t absent_roots = 0;
        for (i = 0; i < f.m.count; ++i)
            if (f.m.kind[i] != TABLE_NONE && table_rng_below(&rng, 10) == 0)
                set_resident(&f, i, !tclod_scene_node_resident(f.s, i));
        for (i = 0; i < smooth_n; ++i)
            if (table_rng_below(&rng, 10) == 0)
                assert_int_equal(
                    tclod_scene_set_smooth_resident(f.s, i, !tclod_scene_smooth_resident(f.s, i)),
                    TCLOD_OK);
        for (i = 0; i < f.m.count; ++i)
            absent_roots += f.m.kind[i] != TABLE_NONE && f.m.parent[i] == TCLOD_NONE &&
                            !tclod_scene_node_resident(f.s, i);
        for (which = 0; which < 2 * SOLVERS; ++which) {
            tclod_selector *sel =
                which < SOLVERS ? warm[which] : make_selector(&f, which - SOLVERS);
            const tclod_id *ids = NULL;
            const tclod_smooth_group *g = NULL;
            const tclod_id *order = NULL;
            uint32_t order_n = 0;
            size_t n = 0, ng = 0, k;
            double cost = 0.0;
            tclod_stats st;
            uint8_t seen[512];
            memset(seen, 0, sizeof seen);
            select_budget(sel, budget, 0, &st);
            assert_int_equal(tclod_selector_cut(sel, &ids, &n), TCLOD_OK);
            for (k = 0; k < n; ++k) {
                tclod_id v = ids[k], p;
                assert_true(v < 512 && !seen[v]);
                seen[v] = 1;
                if (!tclod_scene_node_resident(f.s, v))
                    fail_msg("frame %u, %s%s: node %u drawn, not resident", (unsigned)frame,
                             solver_name[which % SOLVERS], which < SOLVERS ? "" : " (fresh)",
                             (unsigned)v);
                for (p = f.m.parent[v]; p != TCLOD_NONE; p = f.m.parent[p])
                    if (!tclod_scene_node_resident(f.s, p) && (top(&f, p) || which >= SOLVERS))
                        fail_msg("frame %u, %s%s: node %u drawn below %u, not resident",
                                 (unsigned)frame, solver_name[which % SOLVERS],
                                 which < SOLVERS ? "" : " (fresh)", (unsigned)v, (unsigned)p);
                cost += f.m.cost[v];
            }
            assert_int_equal(tclod_scene_smooth_order(f.s, &order, &order_n), TCLOD_OK);
            assert_int_equal(tclod_selector_smooth_groups(sel, &g, &ng), TCLOD_OK);
            for (k = 0; k < ng; ++k) {
                uint32_t j;
                for (j = g[k].first; j < g[k].first + g[k].count; ++j)
                    assert_true(tclod_scene_smooth_resident(f.s, order[j]));
                cost += g[k].cost;
            }
            if (!(cost <= budget) || st.cost != cost)
                fail_msg("frame %u, %s: cost %.17g (stats %.17g), budget %.17g", (unsigned)frame,
                         solver_name[which % SOLVERS], cost, st.cost, budget);
            assert_int_equal(st.absent_roots, absent_roots);
            if (which >= SOLVERS)
                tclod_selector_destroy(sel);
        }
    }
    for (which = 0; which < SOLVERS; ++which)
        tclod_selector_destroy(warm[which]);
    close_fixture(&f);
}

/* ---- bad input ---------------------------------------------------------------------- */

/* What a scene and a selector over it hold, to compare before and after a
 * call that must change nothing. */
typedef struct snapshot {
    double resident_bytes;
    int resident[8];
    double bytes[8];
    int smooth_resident;
    double smooth_bytes;
    tclod_id cut[8];
    size_t n;
} snapshot;

static void take(const fixture *f, const tclod_selector *sel, tclod_id smooth, snapshot *o) {
    const tclod_id *ids = NULL;
    tclod_id i;
    memset(o, 0, sizeof *o);
    o->resident_bytes = tclod_scene_resident_bytes(f->s);
    for (i = 0; i < 8; ++i) {
        o->resident[i] = tclod_scene_node_resident(f->s, i);
        o->bytes[i] = tclod_scene_node_bytes(f->s, i);
    }
    o->smooth_resident = tclod_scene_smooth_resident(f->s, smooth);
    o->smooth_bytes = tclod_scene_smooth_bytes(f->s, smooth);
    assert_int_equal(tclod_selector_cut(sel, &ids, &o->n), TCLOD_OK);
    assert_true(o->n <= 8);
    if (o->n)
        memcpy(o->cut, ids, o->n * sizeof *ids);
}

static void same(const snapshot *a, const snapshot *b) {
    assert_memory_equal(a, b, sizeof *a);
}

/* A call that must fail with `status` and message `msg` and change nothing. */
#define REFUSED(f, sel, smooth, call, status, msg)                  \
    do {                                                            \
        snapshot before_, after_;                                   \
        take(f, sel, smooth, &before_);                             \
        assert_int_equal(call, status);                             \
        assert_string_equal(tclod_scene_last_error((f)->s), (msg)); \
        take(f, sel, smooth, &after_);                              \
        same(&before_, &after_);                                    \
    } while (0)

#define BYTES_RULE "bytes must be finite, >= 0 and at most FLT_MAX"

static void residency_calls_refuse_bad_input_and_change_nothing(void **state) {
    /* R (bytes 100) -> {A (bytes 40), B (bytes 60, not resident)}, an additive
     * root E (no size) with its hidden id, a removed node D, a smooth object
     * of 8 bytes; a selection drawn over them ({R, E}: R cannot refine while
     * B is missing). Each bad call is TCLOD_ERR_ARG with its message, and
     * leaves every node's residency and size, the resident bytes (100 + 40 +
     * 8 = 148) and the selection as they were. */
    fixture f;
    tclod_selector *sel;
    tclod_stats st;
    tclod_id r, a, b, d, e, hidden, o;
    tclod_node_desc nd;
    const double bad[5] = {NAN, HUGE_VAL, -HUGE_VAL, -1.0, 1e39};
    int i;
    (void)state;
    open_fixture(&f);
    r = add(&f, TCLOD_NONE, 1.0, 1.0, 0, 1, 100.0);
    a = add(&f, r, 3.0, 1.0, 0, 1, 40.0);
    b = add(&f, r, 3.0, 1.0, 0, 0, 60.0);
    d = add(&f, TCLOD_NONE, 1.0, 1.0, 0, 1, 0.0);
    e = add(&f, TCLOD_NONE, 1.0, 1.0, 1, 1, 0.0);
    hidden = e + 1; /* the additive node's second id, the last one taken */
    assert_int_equal(tclod_scene_node_count(f.s), hidden + 1);
    assert_int_equal(table_remove_node(&f.m, f.s, d), TCLOD_OK);
    o = add_smooth(&f, 0.0f, 1.0, 1.0);
    assert_int_equal(tclod_scene_set_smooth_bytes(f.s, o, 8.0), TCLOD_OK);
    assert_true(tclod_scene_resident_bytes(f.s) == 148.0);
    sel = make_selector(&f, GREEDY_WARM);
    select_budget(sel, 10.0, 0, &st);
    REFUSED(&f, sel, o, tclod_scene_set_resident(f.s, 99, 1), TCLOD_ERR_ARG,
            "tclod_scene_set_resident: node is not a live node");
    REFUSED(&f, sel, o, tclod_scene_set_resident(f.s, d, 1), TCLOD_ERR_ARG,
            "tclod_scene_set_resident: node is not a live node");
    REFUSED(&f, sel, o, tclod_scene_set_resident(f.s, hidden, 0), TCLOD_ERR_ARG,
            "tclod_scene_set_resident: node is not a live node");
    REFUSED(&f, sel, o, tclod_scene_set_node_bytes(f.s, hidden, 4.0), TCLOD_ERR_ARG,
            "tclod_scene_set_node_bytes: node is not a live node");
    REFUSED(&f, sel, o, tclod_scene_set_resident(f.s, TCLOD_NONE, 0), TCLOD_ERR_ARG,
            "tclod_scene_set_resident: node is not a live node");
    REFUSED(&f, sel, o, tclod_scene_set_resident(f.s, b, 2), TCLOD_ERR_ARG,
            "tclod_scene_set_resident: resident must be 0 or 1");
    REFUSED(&f, sel, o, tclod_scene_set_resident(f.s, a, -1), TCLOD_ERR_ARG,
            "tclod_scene_set_resident: resident must be 0 or 1");
    REFUSED(&f, sel, o, tclod_scene_set_smooth_resident(f.s, o + 1, 0), TCLOD_ERR_ARG,
            "tclod_scene_set_smooth_resident: smooth is not a live smooth object");
    REFUSED(&f, sel, o, tclod_scene_set_smooth_resident(f.s, o, 3), TCLOD_ERR_ARG,
            "tclod_scene_set_smooth_resident: resident must be 0 or 1");
    REFUSED(&f, sel, o, tclod_scene_set_node_bytes(f.s, d, 1.0), TCLOD_ERR_ARG,
            "tclod_scene_set_node_bytes: node is not a live node");
    REFUSED(&f, sel, o, tclod_scene_set_smooth_bytes(f.s, 77, 1.0), TCLOD_ERR_ARG,
            "tclod_scene_set_smooth_bytes: smooth is not a live smooth object");
    for (i = 0; i < 5; ++i) {
        REFUSED(&f, sel, o, tclod_scene_set_node_bytes(f.s, a, bad[i]), TCLOD_ERR_ARG,
                "tclod_scene_set_node_bytes: " BYTES_RULE);
        REFUSED(&f, sel, o, tclod_scene_set_node_bytes(f.s, b, bad[i]), TCLOD_ERR_ARG,
                "tclod_scene_set_node_bytes: " BYTES_RULE);
        REFUSED(&f, sel, o, tclod_scene_set_smooth_bytes(f.s, o, bad[i]), TCLOD_ERR_ARG,
                "tclod_scene_set_smooth_bytes: " BYTES_RULE);
    }
    /* a node desc: both fields checked before anything is added */
    tclod_node_desc_default(&nd);
    nd.not_resident = 2;
    REFUSED(&f, sel, o, tclod_scene_add_node_desc(f.s, &nd, &d), TCLOD_ERR_ARG,
            "tclod_scene_add_node_desc: not_resident must be 0 or 1");
    tclod_node_desc_default(&nd);
    for (i = 0; i < 5; ++i) {
        nd.bytes = bad[i];
        REFUSED(&f, sel, o, tclod_scene_add_node_desc(f.s, &nd, &d), TCLOD_ERR_ARG,
                "tclod_scene_add_node_desc: " BYTES_RULE);
    }
    assert_int_equal(tclod_scene_node_count(f.s), 6);
    /* the largest size a float holds is one */
    assert_int_equal(tclod_scene_set_node_bytes(f.s, b, (double)FLT_MAX), TCLOD_OK);
    assert_true(tclod_scene_node_bytes(f.s, b) == (double)FLT_MAX);
    assert_true(tclod_scene_resident_bytes(f.s) == 148.0);
    /* the selection the refusals left is the one the scene gives */
    select_expect(&f, sel, &st, 10.0, (const tclod_id[]){r, e}, 2, "after the refusals");
    tclod_selector_destroy(sel);
    close_fixture(&f);
}

/* Callbacks that try to change residency from inside a solve. */
typedef struct meddler {
    table_model *m;
    tclod_scene *s;
    tclod_id node, smooth;
    tclod_status got[4];
    char error[4][160];
    int tried;
} meddler;

static double meddling_benefit(void *user, const tclod_query *q) {
    meddler *p = (meddler *)user;
    int k;
    if (p->tried)
        return table_benefit(p->m, q);
    p->tried = 1;
    for (k = 0; k < 4; ++k) {
        switch (k) {
        case 0:
            p->got[k] = tclod_scene_set_resident(p->s, p->node, 0);
            break;
        case 1:
            p->got[k] = tclod_scene_set_node_bytes(p->s, p->node, 1.0);
            break;
        case 2:
            p->got[k] = tclod_scene_set_smooth_resident(p->s, p->smooth, 0);
            break;
        default:
            p->got[k] = tclod_scene_set_smooth_bytes(p->s, p->smooth, 1.0);
            break;
        }
        strncpy(p->error[k], tclod_scene_last_error(p->s), sizeof p->error[k] - 1u);
    }
    return table_benefit(p->m, q);
}

static double meddling_cost(void *user, const tclod_query *q) {
    return table_cost(((meddler *)user)->m, q);
}

static double meddling_smooth_benefit(void *user, const tclod_query *q, double r, double *d_dr) {
    return table_smooth_benefit(((meddler *)user)->m, q, r, d_dr);
}

static double meddling_smooth_cost(void *user, const tclod_query *q, double r, double *d_dr) {
    return table_smooth_cost(((meddler *)user)->m, q, r, d_dr);
}

static void residency_changed_from_a_callback_is_refused(fixture *f, int which) {
    /* A benefit callback tries to unload R, resize it, unload and resize the
     * smooth object during each solver's select: each call is
     * TCLOD_ERR_STATE ("a solve holds the scene"), the select succeeds and
     * draws R's children (b 3, c 1 each, budget 10), and the scene keeps R
     * resident at 100 bytes, the smooth object resident at 8: 108 resident
     * bytes. A pending resumable solve refuses the same. */
    meddler p;
    tclod_selector_desc d;
    tclod_selector *sel = NULL;
    tclod_stats st;
    tclod_frame fr;
    tclod_id r, kids[2], o;
    int k, done = 0;
    r = add(f, TCLOD_NONE, 1.0, 1.0, 0, 1, 100.0);
    kids[0] = add(f, r, 3.0, 1.0, 0, 1, 0.0);
    kids[1] = add(f, r, 3.0, 1.0, 0, 1, 0.0);
    o = add_smooth(f, 50.0f, 1.0, 0.5);
    assert_int_equal(tclod_scene_set_smooth_bytes(f->s, o, 8.0), TCLOD_OK);
    memset(&p, 0, sizeof p);
    p.m = &f->m;
    p.s = f->s;
    p.node = r;
    p.smooth = o;
    tclod_selector_desc_default(&d);
    d.callbacks.benefit = meddling_benefit;
    d.callbacks.cost = meddling_cost;
    d.callbacks.smooth_benefit = meddling_smooth_benefit;
    d.callbacks.smooth_cost = meddling_smooth_cost;
    d.callbacks.user = &p;
    d.solver = solver_for(which);
    d.robin_hood.value = TCLOD_VALUE_BENEFIT;
    assert_int_equal(tclod_selector_create(f->s, &d, NULL, &f->sel), TCLOD_OK);
    sel = f->sel;
    select_budget(sel, 10.0, 0, &st);
    assert_true(p.tried);
    for (k = 0; k < 4; ++k) {
        assert_int_equal(p.got[k], TCLOD_ERR_STATE);
        assert_non_null(strstr(p.error[k], "a solve holds the scene"));
    }
    expect_cut(f, sel, &st, 10.0, kids, 2, solver_name[which]);
    assert_true(tclod_scene_node_resident(f->s, r) && tclod_scene_node_bytes(f->s, r) == 100.0);
    assert_true(tclod_scene_smooth_resident(f->s, o) && tclod_scene_smooth_bytes(f->s, o) == 8.0);
    assert_true(tclod_scene_resident_bytes(f->s) == 108.0);
    /* between begin and the end of the solve */
    memset(&fr, 0, sizeof fr);
    fr.budget = 10.0;
    assert_int_equal(tclod_select_begin(sel, &fr), TCLOD_OK);
    assert_int_equal(tclod_scene_set_resident(f->s, kids[0], 0), TCLOD_ERR_STATE);
    assert_int_equal(tclod_scene_set_node_bytes(f->s, kids[0], 5.0), TCLOD_ERR_STATE);
    assert_int_equal(tclod_scene_set_smooth_resident(f->s, o, 0), TCLOD_ERR_STATE);
    assert_int_equal(tclod_select_step(sel, 0.0, 0, &done, &st), TCLOD_OK);
    assert_true(done);
    expect_cut(f, sel, &st, 10.0, kids, 2, solver_name[which]);
    assert_true(tclod_scene_resident_bytes(f->s) == 108.0);
}

/* ---- resident bytes ------------------------------------------------------------------ */

static void resident_bytes_follow_adds_removals_sizes_and_flips(void **state) {
    /* Sizes in whole bytes (exact in float and double), worked step by step:
     *   R 100 -> {A 250 not resident -> A1 50, B 1000}; additive D 8 -> D1 16
     *   not resident (D's hidden id has no size): 100 + 50 + 1000 + 8 = 1158
     *   smooth S1 sized 64 (resident): 1222; S2 sized 32: 1254; S2 unloaded:
     *   1222
     *   A resized to 300 (not resident): 1222, A's size 300
     *   B resized to 500: 1222 - 1000 + 500 = 722
     *   A loaded: 722 + 300 = 1022; loaded again: no change
     *   A1 unloaded: 1022 - 50 = 972
     *   R removed with its subtree (resident R 100, A 300, B 500; A1 not):
     *   972 - 900 = 72 (D 8 + S1 64)
     *   D removed (D1 not resident): 64; S2 removed (not resident): 64;
     *   S1 removed: 0. */
    fixture f;
    tclod_id r, a, a1, b, dd, d1, s1, s2;
    tclod_scene *s;
    (void)state;
    open_fixture(&f);
    s = f.s;
    r = add(&f, TCLOD_NONE, 1.0, 1.0, 0, 1, 100.0);
    a = add(&f, r, 1.0, 1.0, 0, 0, 250.0);
    a1 = add(&f, a, 1.0, 1.0, 0, 1, 50.0);
    b = add(&f, r, 1.0, 1.0, 0, 1, 1000.0);
    dd = add(&f, TCLOD_NONE, 1.0, 1.0, 1, 1, 8.0);
    d1 = add(&f, dd, 1.0, 1.0, 0, 0, 16.0);
    assert_true(tclod_scene_resident_bytes(s) == 1158.0);
    assert_false(tclod_scene_node_resident(s, a));
    assert_true(tclod_scene_node_bytes(s, a) == 250.0);
    assert_false(tclod_scene_node_resident(s, d1));
    s1 = add_smooth(&f, 0.0f, 1.0, 1.0);
    s2 = add_smooth(&f, 3.0f, 1.0, 1.0);
    assert_true(tclod_scene_smooth_bytes(s, s1) == 0.0);
    assert_int_equal(tclod_scene_set_smooth_bytes(s, s1, 64.0), TCLOD_OK);
    assert_true(tclod_scene_resident_bytes(s) == 1222.0);
    assert_int_equal(tclod_scene_set_smooth_bytes(s, s2, 32.0), TCLOD_OK);
    assert_true(tclod_scene_resident_bytes(s) == 1254.0);
    assert_int_equal(tclod_scene_set_smooth_resident(s, s2, 0), TCLOD_OK);
    assert_true(tclod_scene_resident_bytes(s) == 1222.0);
    assert_false(tclod_scene_smooth_resident(s, s2));
    assert_int_equal(tclod_scene_set_node_bytes(s, a, 300.0), TCLOD_OK);
    assert_true(tclod_scene_resident_bytes(s) == 1222.0);
    assert_true(tclod_scene_node_bytes(s, a) == 300.0);
    assert_int_equal(tclod_scene_set_node_bytes(s, b, 500.0), TCLOD_OK);
    assert_true(tclod_scene_resident_bytes(s) == 722.0);
    assert_int_equal(tclod_scene_set_resident(s, a, 1), TCLOD_OK);
    assert_true(tclod_scene_resident_bytes(s) == 1022.0);
    assert_int_equal(tclod_scene_set_resident(s, a, 1), TCLOD_OK);
    assert_true(tclod_scene_resident_bytes(s) == 1022.0);
    assert_int_equal(tclod_scene_set_resident(s, a1, 0), TCLOD_OK);
    assert_true(tclod_scene_resident_bytes(s) == 972.0);
    assert_int_equal(table_remove_node(&f.m, s, r), TCLOD_OK);
    assert_true(tclod_scene_resident_bytes(s) == 72.0);
    assert_false(tclod_scene_node_resident(s, a));
    assert_true(tclod_scene_node_bytes(s, a) == 0.0);
    assert_int_equal(table_remove_node(&f.m, s, dd), TCLOD_OK);
    assert_true(tclod_scene_resident_bytes(s) == 64.0);
    assert_int_equal(tclod_scene_remove_smooth(s, s2), TCLOD_OK);
    assert_true(tclod_scene_resident_bytes(s) == 64.0);
    assert_int_equal(tclod_scene_remove_smooth(s, s1), TCLOD_OK);
    assert_true(tclod_scene_resident_bytes(s) == 0.0);
    assert_true(tclod_scene_resident_bytes(NULL) == 0.0);
    close_fixture(&f);
}

int main(void) {
    const struct CMUnitTest tests[] = {
        EACH_SOLVER(a_half_loaded_refinement_keeps_its_parent),
        EACH_SOLVER(a_node_not_resident_costing_minus_zero_is_not_drawn),
        EACH_SOLVER(additive_children_join_one_by_one),
        EACH_SOLVER(a_hierarchy_whose_root_is_not_resident_draws_nothing_and_is_counted),
        EACH_SOLVER(an_additive_child_not_resident_hides_its_subtree_from_a_warm_start),
        EACH_SOLVER(a_warm_start_whose_cut_lost_a_node_falls_back_to_a_resident_ancestor),
        EACH_SOLVER(a_fallback_over_the_budget_is_brought_within_it),
        cmocka_unit_test(a_lookahead_jump_may_pass_a_node_that_is_not_resident),
        EACH_SOLVER(a_chain_ends_before_its_first_level_that_is_not_resident),
        cmocka_unit_test(smooth_objects_not_resident_are_in_no_group),
        cmocka_unit_test(residency_flipped_at_random_never_draws_a_node_not_resident),
        cmocka_unit_test(residency_calls_refuse_bad_input_and_change_nothing),
        EACH_SOLVER(residency_changed_from_a_callback_is_refused),
        cmocka_unit_test(resident_bytes_follow_adds_removals_sizes_and_flips),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
