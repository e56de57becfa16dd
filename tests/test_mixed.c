/*
 * test_mixed — the mixed discrete/continuous solver (src/solve/mixed.c): the line
 * search of eq. 8.14 on a hand-worked two-variable case, the choice between a
 * discrete step and a smooth one by their slopes (eq. 8.8-8.11), saturation
 * and the barrier of eq. 8.13, a kinked setup cost (eq. 8.18) against a
 * hand-computed optimum, random separable concave instances against the
 * closed-form Lagrangian optimum, and a scene without smooth objects, which
 * needs no smooth callbacks.
 *
 * Smooth objects come from the table model: benefit w r^p or w ln(1 + p r),
 * cost k r, or steep r before a kink. "Papers' loop" is smooth_precondition 0
 * (gradient direction); the default, preconditioned loop is 1. Scenes have no
 * bounds and frames no view, so nothing is culled and every smooth object is
 * a variable of its own (split_smooth 0).
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

/* Adds a smooth object without meaningful bounds (no view is used). */
static tclod_id add_smooth(helper_fixture *f, table_shape shape, double w, double p, double k,
                           double steep, double kink) {
    static const float bounds[4] = {0.0f, 0.0f, 0.0f, 1.0f};
    float b[4];
    tclod_id id = TCLOD_NONE;
    memcpy(b, bounds, sizeof b);
    /* distinct ground positions, so the quadtree separates the objects */
    b[0] = (float)tclod_scene_smooth_count(f->scene) * 10.0f;
    assert_int_equal(table_add_smooth(&f->model, f->scene, b, shape, w, p, k, steep, kink, &id),
                     TCLOD_OK);
    return id;
}

static tclod_id add_sqrt(helper_fixture *f, double w, double k) {
    return add_smooth(f, TABLE_POWER, w, 0.5, k, k, 0.0);
}

static tclod_selector *lookahead_selector(helper_fixture *f, int precondition, double epsilon,
                                          uint32_t lookahead) {
    tclod_selector_desc d;
    tclod_selector *sel = NULL;
    tclod_selector_desc_default(&d);
    d.solver = TCLOD_SOLVER_MIXED;
    table_mixed_callbacks(&f->model, &d.callbacks);
    d.mixed.plain_gradient = !(precondition);
    d.mixed.smooth_epsilon = epsilon > 0.0 ? epsilon : TCLOD_OFF; /* 0 alone is the default */
    d.mixed.smooth_tolerance = TCLOD_OFF;
    d.greedy.lookahead = lookahead;
    assert_int_equal(tclod_selector_create(f->scene, &d, NULL, &sel), TCLOD_OK);
    return sel;
}

static tclod_selector *mixed_selector(helper_fixture *f, int precondition, double epsilon) {
    return lookahead_selector(f, precondition, epsilon, 0);
}

static void select_mixed(tclod_selector *sel, double budget, uint32_t max_iterations,
                         tclod_stats *st) {
    tclod_frame fr = helper_frame(NULL, budget);
    fr.max_iterations = max_iterations;
    assert_int_equal(tclod_select(sel, &fr, st), TCLOD_OK);
}

static void assert_near(double actual, double expected, double rel, const char *what) {
    if (!(fabs(actual - expected) <= rel * fabs(expected)))
        fail_msg("%s: %.12g, expected %.12g (relative tolerance %g)", what, actual, expected, rel);
}

static double resolution(const tclod_selector *sel, tclod_id id) {
    return tclod_selector_resolution(sel, id);
}

/* The benefit of the smooth objects at their resolutions, object by object. */
static double smooth_benefit(const helper_fixture *f, const tclod_selector *sel) {
    double sum = 0.0;
    tclod_id i;
    for (i = 0; i < f->model.smooth.count; ++i) {
        double r = resolution(sel, i);
        if (r > 0.0)
            sum += table_smooth_benefit_of(&f->model, i, r, NULL);
    }
    return sum;
}

/* ---- the line search ------------------------------------------------------- */

/* The one node of sel's cut (fails unless the cut has exactly one). */
static tclod_id only_node(const tclod_selector *sel) {
    const tclod_id *ids = NULL;
    size_t n = 0;
    assert_int_equal(tclod_selector_cut(sel, &ids, &n), TCLOD_OK);
    assert_int_equal(n, 1);
    return ids[0];
}

/* Papers' loop. Root R (b 1, c 1) with one child C (b 1.5, c 1.5): slope_d =
 * 0.5 / 0.5 = 1. Smooth objects A = 2 sqrt(r), B = sqrt(r), costs r. At 0
 * their gradient is proportional to the weights (both square roots), so after
 * scaling to a largest component of 1 the direction is a = (1, 1/2) and the
 * line is r = (t, t/2). Along it
 *   d benefit/dt = 1 * 2/(2 sqrt t) + 1/2 * 1/(2 sqrt(t/2)) = 1.353553/sqrt t,
 *   d cost/dt    = 1 + 1/2 = 1.5,
 * so slope_c(t) = 0.902369/sqrt t. The first variable reaches 1 at t_max = 1,
 * where slope_c = 0.902 < slope_d: eq. 8.14 gives t_opt = 0.902369^2 =
 * 0.814270, i.e. A = 0.814270 and B = 0.407135. One iteration (the line
 * search) stops the solve there; a second takes the increment. */
static void line_search_stops_where_the_slope_along_the_gradient_meets_slope_d(void **state) {
    helper_fixture *f = (helper_fixture *)*state;
    tclod_id root = helper_add(f, TCLOD_NONE, 1.0, 1.0), child, a, b;
    tclod_selector *sel;
    tclod_stats st;
    double slope;
    child = helper_add(f, root, 1.5, 1.5);
    a = add_sqrt(f, 2.0, 1.0);
    b = add_sqrt(f, 1.0, 1.0);
    sel = mixed_selector(f, 0, 0.0);

    select_mixed(sel, 10.0, 1, &st);
    assert_int_equal(st.stop_reason, TCLOD_STOP_ITERATIONS);
    assert_int_equal(st.line_searches, 1);
    assert_near(resolution(sel, a), 0.814270, 5e-3, "A after the line search");
    assert_near(resolution(sel, b), 0.5 * resolution(sel, a), 1e-9, "B on the line");
    /* the slope along the line where it stopped is slope_d */
    slope = 1.353553 / sqrt(resolution(sel, a)) / 1.5;
    assert_near(slope, 1.0, 3e-3, "slope_c at t_opt");
    assert_int_equal(only_node(sel), root);

    /* Figure 8.1: after Q (the smooth step) comes P (the increment) */
    select_mixed(sel, 10.0, 2, &st);
    assert_int_equal(only_node(sel), child);
    assert_near(resolution(sel, a), 0.814270, 5e-3, "A after the increment");
    tclod_selector_destroy(sel);
}

/* ---- discrete or smooth ------------------------------------------------------ */

/* Root R (b 1, c 1), child C (b 1 + 3, c 2): slope_d = 3 / 1 = 3. One smooth
 * object 2 ln(1 + r) costing r: slope_c = 2 / (1 + r) <= 2 < slope_d. The
 * budget 2 covers R and the increment, or R and some smooth resolution, not
 * both: the increment goes first and spends it. Cut {C}, nothing smooth. */
static void discrete_step_first_when_its_slope_beats_the_smooth_slope(void **state) {
    helper_fixture *f = (helper_fixture *)*state;
    tclod_id root = helper_add(f, TCLOD_NONE, 1.0, 1.0), child, s;
    int precondition;
    child = helper_add(f, root, 4.0, 2.0);
    s = add_smooth(f, TABLE_LOG, 2.0, 1.0, 1.0, 1.0, 0.0);
    for (precondition = 0; precondition <= 1; ++precondition) {
        tclod_selector *sel = mixed_selector(f, precondition, 0.0);
        tclod_stats st;
        select_mixed(sel, 2.0, 0, &st);
        assert_int_equal(only_node(sel), child);
        assert_true(resolution(sel, s) == 0.0);
        assert_true(st.benefit == 4.0);
        tclod_selector_destroy(sel);
    }
}

/* As above with C (b 1 + 1.5, c 2): slope_d = 1.5 < slope_c(0) = 2. The smooth
 * object goes first. The papers' loop stops it where its slope falls to 1.5
 * (r = 2/1.5 - 1 = 1/3), but then the increment (cost 1) no longer fits the
 * 2/3 left, which the smooth object takes: r = 1. The preconditioned loop sees
 * at once that after paying for the increment nothing would be left for the
 * steeper smooth object, and gets there directly. Either way the interleaving
 * ends at cut {R}, r = 1 (less the line search's margin of 1e-9 of the
 * budget), benefit 1 + 2 ln 2 = 2.386294. The skipped increment's selection
 * alone, T(C) = {C} with nothing smooth, costs 2 <= 2 and is worth 2.5: the
 * safeguard makes it the result. It is the optimum: with {R} the smooth object
 * gets at most r = 1 (2.386294); with {C} nothing is left for it. */
static void smooth_step_first_when_its_slope_beats_the_discrete_slope(void **state) {
    helper_fixture *f = (helper_fixture *)*state;
    tclod_id root = helper_add(f, TCLOD_NONE, 1.0, 1.0), child, s;
    int precondition;
    child = helper_add(f, root, 2.5, 2.0);
    s = add_smooth(f, TABLE_LOG, 2.0, 1.0, 1.0, 1.0, 0.0);
    for (precondition = 0; precondition <= 1; ++precondition) {
        tclod_selector *sel = mixed_selector(f, precondition, 0.0);
        tclod_stats st;
        select_mixed(sel, 2.0, 0, &st);
        assert_int_equal(only_node(sel), child);
        assert_true(resolution(sel, s) == 0.0);
        assert_true(st.benefit == 2.5);
        assert_true(st.cost <= 2.0);
        tclod_selector_destroy(sel);
    }
}

/* The safeguard's comparison is with the interleaving's final result, smooth
 * part included. Two roots: A (b 1, c 1) with child A1 (b 11, c 9), an
 * increment of +10 for +8 (ratio 1.25), and B (b 1, c 1) with child B1 (b 4,
 * c 2), +3 for +1 (ratio 3); one smooth object 2 ln(1 + r) costing r (slope 2
 * at 0). Budget 10. Best ratio first: B's increment (the cut then costs 3),
 * then the smooth object, whose slope (2 at most) beats A's 1.25, up to r = 1
 * (cost 1); A's increment (+8) does not fit the 7 left at any point: benefit
 * 1 + 4 + 2 ln 2 = 6.386294 for a cost of 4. T(A1) = {A1, B}, cost 9 + 1 = 10,
 * is worth 11 + 1 = 12; the second pass starts there, and nothing is left for
 * B's increment or the smooth object: benefit 12, the optimum (with A1 the 0
 * left buys nothing; without it, at most 1 + 4 + 2 ln 2). */
static void mixed_solve_keeps_the_best_skipped_increment_taken_alone(void **state) {
    helper_fixture *f = (helper_fixture *)*state;
    tclod_id a = helper_add(f, TCLOD_NONE, 1.0, 1.0), b = helper_add(f, TCLOD_NONE, 1.0, 1.0);
    tclod_id a1 = helper_add(f, a, 11.0, 9.0), s, expected[2];
    int precondition;
    helper_add(f, b, 4.0, 2.0);
    s = add_smooth(f, TABLE_LOG, 2.0, 1.0, 1.0, 1.0, 0.0);
    expected[0] = b;
    expected[1] = a1;
    for (precondition = 0; precondition <= 1; ++precondition) {
        tclod_selector *sel = mixed_selector(f, precondition, 0.0);
        tclod_stats st;
        select_mixed(sel, 10.0, 0, &st);
        helper_assert_cut(sel, expected, 2);
        assert_true(resolution(sel, s) == 0.0);
        assert_true(st.benefit == 12.0 && st.cost == 10.0);
        tclod_selector_destroy(sel);
    }
}

/* Both go in when the budget has room: C (b 2.5, c 2) as above, budget 2.2 +
 * 1/3 (R, the increment, and 1/3 + 0.2 for the smooth object). At the end
 * the smooth object's slope 2 / (1 + r) must not be above slope_d = 1.5 while
 * the increment is left out, so the increment is in; the smooth object takes
 * the rest: r = 2.2 + 1/3 - 2 = 0.533333, slope 1.304 < 1.5. */
static void discrete_and_smooth_steps_share_the_budget_by_slope(void **state) {
    helper_fixture *f = (helper_fixture *)*state;
    tclod_id root = helper_add(f, TCLOD_NONE, 1.0, 1.0), child, s;
    int precondition;
    child = helper_add(f, root, 2.5, 2.0);
    s = add_smooth(f, TABLE_LOG, 2.0, 1.0, 1.0, 1.0, 0.0);
    for (precondition = 0; precondition <= 1; ++precondition) {
        tclod_selector *sel = mixed_selector(f, precondition, 0.0);
        tclod_stats st;
        select_mixed(sel, 2.2 + 1.0 / 3.0, 0, &st);
        assert_int_equal(only_node(sel), child);
        assert_near(resolution(sel, s), 0.2 + 1.0 / 3.0, 1e-7, "smooth resolution");
        tclod_selector_destroy(sel);
    }
}

/* ---- saturation and the barrier ---------------------------------------------- */

/* A = 4 sqrt(r), B = sqrt(r), costs r, budget 1.6. From 0 the direction is
 * (1, 1/4); A saturates at t = 1, costing 1 + 1/4 = 1.25 <= 1.6, so the first
 * step ends with A = 1 and B = 1/4. A stays at exactly 1 and the rest of the
 * budget goes to B: B = 1.6 - 1 = 0.6. The optimum is the same (at slope
 * lambda, B = 1/(4 lambda^2) = 0.6 gives lambda = 0.645 < 2, where A would want
 * 4/lambda^2 > 1), so both loops agree. */
static void saturated_variable_stays_at_one_and_the_rest_goes_to_the_others(void **state) {
    helper_fixture *f = (helper_fixture *)*state;
    tclod_id a = add_sqrt(f, 4.0, 1.0), b = add_sqrt(f, 1.0, 1.0);
    int precondition;
    for (precondition = 0; precondition <= 1; ++precondition) {
        tclod_selector *sel = mixed_selector(f, precondition, 0.0);
        tclod_stats st;
        select_mixed(sel, 1.6, 0, &st);
        assert_true(resolution(sel, a) == 1.0);
        assert_near(resolution(sel, b), 0.6, 1e-6, "B");
        assert_true(st.cost <= 1.6);
        tclod_selector_destroy(sel);
    }
}

/* Papers' loop, A = 4 sqrt(r), B = 2 sqrt(r), C = sqrt(r), costs r, budget
 * 2.5. Step 1 (barrier factors equal at 0): direction (1, 1/2, 1/4), A
 * saturates at t = 1 at cost 1.75: A = 1, B = 0.5, C = 0.25.
 * Step 2 without barrier: slopes B 2/(2 sqrt .5) = 1.414214, C 1/(2 sqrt .25)
 * = 1, direction (1, 0.707107); B would reach 1 at t = 0.5 at cost 2.603553 >
 * 2.5, so the budget stops it: 1.75 + 1.707107 t = 2.5, t = 0.439340:
 * B = 0.939340, C = 0.560660.
 * Step 2 with the barrier eps = 0.4 (relative): B's slope times
 * 1 - 0.4/0.5 = 0.2, C's times 1 - 0.4/0.75 = 0.466667: (0.282843, 0.466667),
 * i.e. (0.606092, 1); C reaches 1 first, at t = 0.75, costing 2.954569 > 2.5,
 * so the budget stops it: 1.75 + 1.606092 t = 2.5, t = 0.466971:
 * B = 0.783028, C = 0.716971. The barrier moved resolution away from B, the
 * variable closer to 1. */
static void barrier_moves_resolution_away_from_a_variable_close_to_one(void **state) {
    helper_fixture *f = (helper_fixture *)*state;
    tclod_id a = add_sqrt(f, 4.0, 1.0), b = add_sqrt(f, 2.0, 1.0), c = add_sqrt(f, 1.0, 1.0);
    tclod_selector *sel;
    tclod_stats st;

    sel = mixed_selector(f, 0, 0.0);
    select_mixed(sel, 2.5, 0, &st);
    assert_true(resolution(sel, a) == 1.0);
    assert_near(resolution(sel, b), 0.939340, 1e-5, "B without barrier");
    assert_near(resolution(sel, c), 0.560660, 1e-5, "C without barrier");
    tclod_selector_destroy(sel);

    sel = mixed_selector(f, 0, 0.4);
    select_mixed(sel, 2.5, 0, &st);
    assert_true(resolution(sel, a) == 1.0);
    assert_near(resolution(sel, b), 0.783028, 1e-5, "B with barrier");
    assert_near(resolution(sel, c), 0.716971, 1e-5, "C with barrier");
    tclod_selector_destroy(sel);
}

/* ---- kinked cost ------------------------------------------------------------------ */

/* A = sqrt(r) costing r; B = 2 sqrt(r) costing 10 r up to r = 0.1 (a setup
 * cost: every unit dear until the kink), then 1 + (r - 0.1). Budget 2.
 * With B past the kink both sit at one slope lambda: A = 1/(4 lambda^2),
 * B = 4/(4 lambda^2) = 4 A, and A + 1 + (B - 0.1) = 2 gives 5 A = 1.1:
 * A = 0.22, B = 0.88, benefit sqrt(.22) + 2 sqrt(.88) = 2.345208.
 * With B before the kink: A = 1/(4 lambda^2), B = 1/(100 lambda^2), costs
 * A + 10 B = 0.35 / lambda^2 = 2 would put A above 1, so A = 1 and B = 0.1
 * (the kink): benefit 1 + 2 sqrt(.1) = 1.632456. Without B: A = 1, benefit 1.
 * The optimum is the first. */
static void kinked_cost_reaches_the_hand_computed_optimum(void **state) {
    helper_fixture *f = (helper_fixture *)*state;
    tclod_id a = add_sqrt(f, 1.0, 1.0);
    tclod_id b = add_smooth(f, TABLE_POWER, 2.0, 0.5, 1.0, 10.0, 0.1);
    tclod_selector *sel = mixed_selector(f, 1, 0.0);
    tclod_stats st;
    select_mixed(sel, 2.0, 0, &st);
    assert_near(resolution(sel, a), 0.22, 2e-3, "A");
    assert_near(resolution(sel, b), 0.88, 2e-3, "B");
    assert_near(st.benefit, 2.345208, 1e-4, "benefit");
    assert_true(st.cost <= 2.0);
    tclod_selector_destroy(sel);
}

/* Papers' loop, one line search. R (b 1, c 1) with child C (b 1.5, c 1.5):
 * slope_d = 1. One smooth object sqrt(r) costing 2 r up to the kink r = 0.3,
 * then 0.6 + 0.45 (r - 0.3); the budget (10) does not bind, so t_max = 1 (the
 * direction is a = 1). The line search maximises phi(r) = sqrt(r) - c(r):
 *   before the kink phi' = 1/(2 sqrt r) - 2 falls to 0 at r = 1/16 = 0.0625,
 *     phi(0.0625) = 0.25 - 0.125 = 0.125 (a local maximum);
 *   at the kink phi' jumps from 0.912871 - 2 < 0 to 0.912871 - 0.45 > 0, and
 *     stays positive up to r = 1 (0.5 - 0.45 = 0.05): phi(1) = 1 - 0.6 - 0.315
 *     = 0.085, the other local maximum;
 * so the optimum of the line is r = 0.0625. The slope at t_max is above
 * slope_d, which eq. 8.14 alone would take for the answer. */
static void line_search_brackets_a_kink_and_keeps_the_better_local_maximum(void **state) {
    helper_fixture *f = (helper_fixture *)*state;
    tclod_id root = helper_add(f, TCLOD_NONE, 1.0, 1.0), s;
    tclod_selector *sel;
    tclod_stats st;
    helper_add(f, root, 1.5, 1.5);
    s = add_smooth(f, TABLE_POWER, 1.0, 0.5, 0.45, 2.0, 0.3);
    sel = mixed_selector(f, 0, 0.0);
    select_mixed(sel, 10.0, 1, &st);
    assert_int_equal(st.line_searches, 1);
    assert_near(resolution(sel, s), 0.0625, 5e-3, "r after the line search");
    assert_int_equal(only_node(sel), root);
    tclod_selector_destroy(sel);
}

/* ---- random kinked instances against brute force --------------------------------- */

/* The cost of smooth object i at r. */
static double kinked_cost(const table_smooth *t, tclod_id i, double r) {
    return r < t->kink[i] ? t->steep[i] * r : t->steep[i] * t->kink[i] + t->k[i] * (r - t->kink[i]);
}

/* The papers' direction from resolution 0 as the library computes it (no
 * barrier): every object's benefit slope where slopes are asked (10^-9),
 * scaled to a largest component of 1. */
static void direction_from_zero(const table_model *m, double *a) {
    double largest = 0.0;
    tclod_id i;
    for (i = 0; i < m->smooth.count; ++i) {
        table_smooth_benefit_of(m, i, 1e-9, &a[i]);
        if (a[i] > largest)
            largest = a[i];
    }
    for (i = 0; i < m->smooth.count; ++i)
        a[i] /= largest;
}

/* Benefit less lambda times cost of the smooth objects at r = t a, and their
 * cost alone. */
static double line_phi(const table_model *m, const double *a, double t, double lambda,
                       double *cost) {
    double sum = 0.0;
    tclod_id i;
    *cost = 0.0;
    for (i = 0; i < m->smooth.count; ++i) {
        double r = t * a[i] < 1.0 ? t * a[i] : 1.0;
        *cost += kinked_cost(&m->smooth, i, r);
        sum += table_smooth_benefit_of(m, i, r, NULL);
    }
    return sum - lambda * *cost;
}

/* Papers' loop, one line search, 300 random instances. One to three smooth
 * objects, benefits
 * w r^p or w ln(1 + p r), costs with a setup (steep, 2 to 20 times the slope
 * after it, up to a kink in [0.02, 0.3]); R (b 1, c 1) with one child of
 * slope_d = lambda, 0.05 to 0.9 times the slope along the gradient at 0 (so
 * that the smooth step comes first); budgets that fit R and the increment,
 * from where the line reaches the budget early to where it does not bind.
 * The line search goes along the
 * gradient a from 0 and should stop at the best point of phi(t) = benefit -
 * lambda cost on [0, t_max] (t_max: the first object at 1, or the budget left
 * after R, less the line search's margin of 1e-9 of the budget). Brute force:
 * phi on 20000 equal steps of [0, t_max], plus each kink's two sides and t_max
 * itself. The line search's point (every object on the line) must be within
 * 1e-4 of the benefits' scale of that maximum (the refinement of a crossing
 * stops within 10^-3 of the slope's terms; at 0 nothing moves, and the
 * increment follows in the same iteration). */
static void line_search_on_kinked_instances_finds_the_best_point_of_the_line(void **state) {
    table_rng rng;
    int instance;
    (void)state;
    table_rng_seed(&rng, 8018);
    for (instance = 0; instance < 300; ++instance) {
        helper_fixture *f;
        tclod_selector *sel;
        tclod_stats st;
        tclod_id root, i;
        double lambda, dc = table_rng_uniform(&rng, 0.1, 1.0), slope_b = 0.0, slope_c = 0.0;
        double a[3], full = 0.0, scale = 0.0, budget, limit, t_max = HUGE_VAL, lo, hi, cost;
        double best, got, t, got_cost;
        uint32_t n = 1u + table_rng_below(&rng, 3), k;
        assert_int_equal(helper_fixture_setup((void **)&f), 0);
        for (i = 0; i < n; ++i) {
            table_shape shape = table_rng_below(&rng, 2) ? TABLE_LOG : TABLE_POWER;
            double p = shape == TABLE_POWER ? table_rng_uniform(&rng, 0.3, 0.8)
                                            : table_rng_uniform(&rng, 1.0, 20.0);
            double k_after = table_rng_uniform(&rng, 0.5, 2.0);
            double steep = k_after * table_rng_uniform(&rng, 2.0, 20.0);
            double kink = table_rng_uniform(&rng, 0.02, 0.3);
            add_smooth(f, shape, table_rng_uniform(&rng, 0.5, 5.0), p, k_after, steep, kink);
            full += kinked_cost(&f->model.smooth, i, 1.0);
            scale += table_smooth_benefit_of(&f->model, i, 1.0, NULL);
        }
        direction_from_zero(&f->model, a);
        for (i = 0; i < n; ++i) { /* the slope along a at 0, which slope_d must not beat */
            double db;
            table_smooth_benefit_of(&f->model, i, 1e-9, &db);
            slope_b += a[i] * db;
            slope_c += a[i] * f->model.smooth.steep[i];
        }
        lambda = slope_b / slope_c * table_rng_uniform(&rng, 0.05, 0.9);
        root = helper_add(f, TCLOD_NONE, 1.0, 1.0);
        helper_add(f, root, 1.0 + lambda * dc, 1.0 + dc);
        /* the increment fits, so that it is the line search's slope_d */
        budget = 1.0 + dc + full * table_rng_uniform(&rng, 0.05, 1.2);
        limit = budget - 1e-9 * budget - 1.0;
        for (i = 0; i < n; ++i)
            if (1.0 / a[i] < t_max)
                t_max = 1.0 / a[i];
        line_phi(&f->model, a, t_max, lambda, &cost);
        if (cost > limit) { /* the budget's edge: bisection on the cost */
            for (lo = 0.0, hi = t_max, k = 0; k < 200; ++k) {
                line_phi(&f->model, a, 0.5 * (lo + hi), lambda, &cost);
                if (cost <= limit)
                    lo = 0.5 * (lo + hi);
                else
                    hi = 0.5 * (lo + hi);
            }
            t_max = lo;
        }
        best = line_phi(&f->model, a, t_max, lambda, &cost);
        for (k = 0; k < 20000; ++k) {
            double v = line_phi(&f->model, a, t_max * (double)k / 20000.0, lambda, &cost);
            if (v > best)
                best = v;
        }
        for (i = 0; i < n; ++i) {
            double tk = f->model.smooth.kink[i] / a[i];
            int side;
            for (side = -1; side <= 1; side += 2) {
                double v, at = tk * (1.0 + 1e-12 * side);
                if (!(at < t_max))
                    continue;
                v = line_phi(&f->model, a, at, lambda, &cost);
                if (v > best)
                    best = v;
            }
        }
        sel = mixed_selector(f, 0, 0.0);
        select_mixed(sel, budget, 1, &st);
        assert_int_equal(st.line_searches, 1);
        for (t = 0.0, i = 0; i < n; ++i)
            if (a[i] == 1.0)
                t = resolution(sel, i);
        /* on the line, but never asked below 10^-9 */
        for (i = 0; i < n; ++i)
            assert_true(fabs(resolution(sel, i) - t * a[i]) <= 1.1e-9);
        for (got = got_cost = 0.0, i = 0; i < n; ++i) {
            double r = resolution(sel, i);
            got_cost += kinked_cost(&f->model.smooth, i, r);
            got += table_smooth_benefit_of(&f->model, i, r, NULL);
        }
        got -= lambda * got_cost;
        if (!(got >= best - 1e-4 * scale))
            fail_msg("instance %d: phi %.12g at t = %.9g, the line's best is %.12g", instance, got,
                     t, best);
        assert_true(got_cost <= limit + 1e-12 * budget);
        tclod_selector_destroy(sel);
        helper_fixture_teardown((void **)&f);
    }
}

/* Preconditioned loop: four objects of weight 1 and twelve of 0.01 (w sqrt(r),
 * costs r), budget 4. At slope lambda each takes r = w^2 / (4 lambda^2), and
 * the budget is spent where 1 / (4 lambda^2) = 4 / (4 + 12 * 10^-4) =
 * 0.999700 (below 1): r = 0.999700 and 0.0000999700, benefit sqrt(4 * 4.0012)
 * = 4.000600. The models are exact for square roots, so the smooth step aimed
 * at the slope at which they spend the budget lands there. */
static void preconditioned_loop_spends_the_budget_at_the_slope_its_models_predict(void **state) {
    helper_fixture *f = (helper_fixture *)*state;
    tclod_selector *sel;
    tclod_stats st;
    tclod_id i;
    for (i = 0; i < 16; ++i)
        add_sqrt(f, i % 4 == 0 ? 1.0 : 0.01, 1.0);
    sel = mixed_selector(f, 1, 0.0);
    select_mixed(sel, 4.0, 0, &st);
    for (i = 0; i < 16; ++i)
        assert_near(resolution(sel, i), i % 4 == 0 ? 0.999700 : 0.0000999700, 1e-6, "resolution");
    assert_near(st.benefit, 4.000600, 1e-7, "benefit");
    assert_true(st.cost <= 4.0);
    tclod_selector_destroy(sel);
}

/* ---- random separable concave instances ------------------------------------------ */

/* The closed-form resolution of object i at slope lambda: where its benefit
 * slope equals lambda times its (linear) cost slope, within [0, 1]. Power:
 * w p r^(p-1) = lambda k. Log: w p / (1 + p r) = lambda k. */
static double lagrange_resolution(const table_model *m, tclod_id i, double lambda) {
    const table_smooth *t = &m->smooth;
    double w = t->w[i], p = t->p[i], k = t->k[i], r;
    if (t->shape[i] == TABLE_POWER)
        r = pow(w * p / (lambda * k), 1.0 / (1.0 - p));
    else
        r = w / (lambda * k) - 1.0 / p;
    return r < 0.0 ? 0.0 : (r > 1.0 ? 1.0 : r);
}

/* The optimum of max sum b_i(r_i) s.t. sum k_i r_i <= budget: the spend at
 * slope lambda is continuous and decreasing, so bisection on ln(lambda). */
static double lagrange_optimum(const table_model *m, double budget) {
    double lo = -40.0, hi = 40.0, sum = 0.0;
    tclod_id i;
    int it;
    for (it = 0; it < 200; ++it) {
        double mid = 0.5 * (lo + hi), cost = 0.0;
        for (i = 0; i < m->smooth.count; ++i)
            cost += m->smooth.k[i] * lagrange_resolution(m, i, exp(mid));
        if (cost > budget)
            lo = mid;
        else
            hi = mid;
    }
    for (i = 0; i < m->smooth.count; ++i)
        sum += table_smooth_benefit_of(m, i, lagrange_resolution(m, i, exp(hi)), NULL);
    return sum;
}

static void separable_concave_instances_reach_99_percent_of_the_lagrangian_optimum(void **state) {
    table_rng rng;
    int instance;
    double worst = 1.0;
    (void)state;
    table_rng_seed(&rng, 2024);
    for (instance = 0; instance < 100; ++instance) {
        helper_fixture *f;
        tclod_selector *sel;
        tclod_stats st;
        double budget, optimum;
        uint32_t i;
        assert_int_equal(helper_fixture_setup((void **)&f), 0);
        for (i = 0; i < 30; ++i) {
            table_shape shape = table_rng_below(&rng, 2) ? TABLE_LOG : TABLE_POWER;
            double p = shape == TABLE_POWER ? table_rng_uniform(&rng, 0.2, 0.9)
                                            : table_rng_uniform(&rng, 1.0, 50.0);
            double k = table_rng_uniform(&rng, 0.5, 5.5);
            add_smooth(f, shape, table_rng_uniform(&rng, 0.5, 10.5), p, k, k, 0.0);
        }
        budget = table_rng_uniform(&rng, 2.0, 60.0);
        optimum = lagrange_optimum(&f->model, budget);
        sel = mixed_selector(f, 1, 0.0);
        select_mixed(sel, budget, 0, &st);
        assert_true(st.cost <= budget);
        if (st.benefit > optimum * (1.0 + 1e-9))
            fail_msg("instance %d: benefit %.12g above the optimum %.12g", instance, st.benefit,
                     optimum);
        assert_near(smooth_benefit(f, sel), st.benefit, 1e-9, "benefit of the resolutions");
        if (st.benefit / optimum < worst)
            worst = st.benefit / optimum;
        tclod_selector_destroy(sel);
        helper_fixture_teardown((void **)&f);
    }
    if (!(worst >= 0.99))
        fail_msg("worst instance reached %.5f of the optimum", worst);
}

/* ---- limits ---------------------------------------------------------------------- */

/* With an unlimited budget every smooth object is at full resolution and every
 * node at its finest level. */
static void unlimited_budget_draws_everything_at_full_resolution(void **state) {
    helper_fixture *f = (helper_fixture *)*state;
    tclod_id root = helper_add(f, TCLOD_NONE, 1.0, 1.0), child, s1, s2;
    int precondition;
    child = helper_add(f, root, 2.0, 2.0);
    s1 = add_sqrt(f, 1.0, 1.0);
    s2 = add_smooth(f, TABLE_LOG, 3.0, 5.0, 2.0, 4.0, 0.05);
    for (precondition = 0; precondition <= 1; ++precondition) {
        tclod_selector *sel = mixed_selector(f, precondition, 1e-3);
        tclod_stats st;
        select_mixed(sel, INFINITY, 0, &st);
        assert_true(resolution(sel, s1) == 1.0);
        assert_true(resolution(sel, s2) == 1.0);
        assert_int_equal(only_node(sel), child);
        assert_int_equal(st.stop_reason, TCLOD_STOP_FINEST);
        tclod_selector_destroy(sel);
    }
}

/* A zero budget draws nothing that costs: every resolution is 0. */
static void zero_budget_draws_no_smooth_object(void **state) {
    helper_fixture *f = (helper_fixture *)*state;
    tclod_id s = add_sqrt(f, 1.0, 1.0);
    tclod_selector *sel = mixed_selector(f, 1, 1e-3);
    tclod_stats st;
    const tclod_smooth_group *groups;
    size_t n;
    select_mixed(sel, 0.0, 0, &st);
    assert_true(resolution(sel, s) == 0.0);
    assert_int_equal(tclod_selector_smooth_groups(sel, &groups, &n), TCLOD_OK);
    assert_int_equal(n, 0);
    assert_true(st.cost == 0.0);
    tclod_selector_destroy(sel);
}

/* Every iteration limit gives a feasible selection whose benefit does not
 * fall as the limit grows past the first few steps' order of magnitude. */
static void iteration_limits_stop_with_a_feasible_selection(void **state) {
    helper_fixture *f = (helper_fixture *)*state;
    table_rng rng;
    uint32_t i, limit;
    tclod_id root = helper_add(f, TCLOD_NONE, 1.0, 1.0);
    table_rng_seed(&rng, 7);
    for (i = 0; i < 3; ++i)
        helper_add(f, root, 0.8, 0.4);
    for (i = 0; i < 12; ++i)
        add_sqrt(f, table_rng_uniform(&rng, 1.0, 5.0), 1.0);
    for (limit = 1; limit <= 40; ++limit) {
        int precondition;
        for (precondition = 0; precondition <= 1; ++precondition) {
            tclod_selector *sel = mixed_selector(f, precondition, 1e-3);
            tclod_stats st;
            select_mixed(sel, 4.0, limit, &st);
            assert_true(st.cost <= 4.0);
            assert_true(st.iterations <= limit + 1u);
            tclod_selector_destroy(sel);
        }
    }
}

static void without_smooth_objects_the_mixed_solver_keeps_the_greedys_safeguard(void **state) {
    helper_fixture *f = (helper_fixture *)*state;
    /* Two roots: A (benefit 19, cost 29) with children (59.018, 61) and
     * (48.982, 53), an increment of +89 benefit for +85 cost (ratio 1.047);
     * B (50, 60) with children (32.4828, 21) and (33.5172, 51), +16 for +12
     * (ratio 1.333). Budget 176, roots 89. Best ratio first takes B's
     * increment (101), after which A's (+85) no longer fits: benefit 85. The
     * optimum refines A alone: 61 + 53 + 60 = 174 <= 176, benefit
     * 59.018 + 48.982 + 50 = 158; both increments cost 186. The greedy's
     * safeguard (the best skipped increment taken alone) finds it. */
    tclod_id a = helper_add(f, TCLOD_NONE, 19.0, 29.0), b = helper_add(f, TCLOD_NONE, 50.0, 60.0);
    tclod_id a1 = helper_add(f, a, 59.018, 61.0), a2 = helper_add(f, a, 48.982, 53.0);
    tclod_id expected[3];
    int precondition;
    helper_add(f, b, 32.4828, 21.0);
    helper_add(f, b, 33.5172, 51.0);
    expected[0] = b;
    expected[1] = a1;
    expected[2] = a2;
    for (precondition = 0; precondition <= 1; ++precondition) {
        tclod_selector *sel = mixed_selector(f, precondition, 1e-3);
        tclod_stats st;
        select_mixed(sel, 176.0, 0, &st);
        helper_assert_cut(sel, expected, 3);
        assert_near(st.benefit, 158.0, 1e-12, "benefit");
        assert_int_equal(st.variables, 0);
        tclod_selector_destroy(sel);
    }
}

static void without_smooth_objects_the_mixed_solver_needs_no_smooth_callbacks(void **state) {
    helper_fixture *f = (helper_fixture *)*state;
    /* The scene of the safeguard test above, and the host's callbacks
     * without smooth ones: the mixed solver is created and selects what the
     * greedy does, {B, A1, A2}, benefit 158, alone and under a scheduler.
     * Once the scene has a smooth object, which it cannot draw, a select, a
     * begin and a scheduler update fail with TCLOD_ERR_ARG and keep what
     * they showed; a new mixed selector is refused. */
    tclod_id a = helper_add(f, TCLOD_NONE, 19.0, 29.0), b = helper_add(f, TCLOD_NONE, 50.0, 60.0);
    tclod_id a1 = helper_add(f, a, 59.018, 61.0), a2 = helper_add(f, a, 48.982, 53.0);
    tclod_id expected[3];
    tclod_selector_desc d;
    tclod_scheduler_desc sd;
    tclod_selector *sel = NULL, *other = NULL;
    tclod_scheduler *sch[2] = {NULL, NULL};
    tclod_frame frame = helper_frame(NULL, 176.0);
    tclod_stats st;
    tclod_view v;
    const tclod_draw *items[2];
    size_t n[2];
    int k;
    helper_add(f, b, 32.4828, 21.0);
    helper_add(f, b, 33.5172, 51.0);
    expected[0] = b;
    expected[1] = a1;
    expected[2] = a2;
    tclod_selector_desc_default(&d);
    table_callbacks(&f->model, &d.callbacks);
    assert_null(d.callbacks.smooth_benefit);
    d.solver = TCLOD_SOLVER_MIXED;
    assert_int_equal(tclod_selector_create(f->scene, &d, NULL, &sel), TCLOD_OK);
    assert_int_equal(tclod_select(sel, &frame, &st), TCLOD_OK);
    helper_assert_cut(sel, expected, 3);
    assert_near(st.benefit, 158.0, 1e-12, "benefit");
    tclod_scheduler_desc_default(&sd);
    helper_view(&v);
    for (k = 0; k < 2; ++k) {
        d.solver = k ? TCLOD_SOLVER_GREEDY : TCLOD_SOLVER_MIXED;
        assert_int_equal(tclod_scheduler_create(f->scene, &d, &sd, NULL, &sch[k]), TCLOD_OK);
        assert_int_equal(tclod_scheduler_update(sch[k], 0.0, &v, 176.0, 0.0), TCLOD_OK);
        assert_int_equal(tclod_scheduler_update(sch[k], 1.2, &v, 176.0, 0.0), TCLOD_OK);
        assert_int_equal(tclod_scheduler_draws(sch[k], &items[k], &n[k]), TCLOD_OK);
    }
    assert_int_equal(n[0], 3);
    assert_int_equal(n[0], n[1]);
    assert_memory_equal(items[0], items[1], n[0] * sizeof(tclod_draw));
    add_sqrt(f, 1.0, 1.0);
    assert_int_equal(tclod_select(sel, &frame, &st), TCLOD_ERR_ARG);
    helper_assert_cut(sel, expected, 3);
    assert_int_equal(tclod_select_begin(sel, &frame), TCLOD_ERR_ARG);
    assert_int_equal(tclod_select_pending(sel), 0);
    assert_int_equal(tclod_scheduler_update(sch[0], 1.3, &v, 176.0, 0.0), TCLOD_ERR_ARG);
    assert_int_equal(tclod_scheduler_draws(sch[0], &items[0], &n[0]), TCLOD_OK);
    assert_int_equal(n[0], 3);
    d.solver = TCLOD_SOLVER_MIXED;
    assert_int_equal(tclod_selector_create(f->scene, &d, NULL, &other), TCLOD_ERR_ARG);
    assert_null(other);
    tclod_scheduler_destroy(sch[1]);
    tclod_scheduler_destroy(sch[0]);
    tclod_selector_destroy(sel);
}

/* Chains P0 (b 1, c 1) -> P1 (1.5, 3) -> P2 (9, 5) and Q0 (1, 1) -> Q1 (3, 3),
 * and a smooth object of benefit r / 2 and cost r (slope 1/2 throughout, cost
 * 1 at most); budget 6, the roots cost 2. One level down P gains 0.5 for 2
 * (slope 1/4), Q gains 2 for 2 (slope 1): Q goes first, then the smooth
 * object to r = 1, and P's step no longer fits the 1 left, nor would it be
 * worth the smooth object's place: cut {P0, Q1}, benefit 1 + 3 + 1/2. With
 * lookahead 1, P's increment reaches P2, gaining 8 for 4 (slope 2): it goes
 * first and spends the whole budget: cut {P2, Q0}, r = 0, benefit 10, the
 * optimum. */
static void lookahead_increments_compete_with_smooth_steps_by_their_slope(void **state) {
    helper_fixture *f = (helper_fixture *)*state;
    tclod_id p0 = helper_add(f, TCLOD_NONE, 1.0, 1.0), q0 = helper_add(f, TCLOD_NONE, 1.0, 1.0);
    tclod_id p1 = helper_add(f, p0, 1.5, 3.0), p2 = helper_add(f, p1, 9.0, 5.0);
    tclod_id q1 = helper_add(f, q0, 3.0, 3.0), s;
    tclod_id one_level[2], reached[2];
    int precondition;
    s = add_smooth(f, TABLE_POWER, 0.5, 1.0, 1.0, 1.0, 0.0);
    one_level[0] = p0;
    one_level[1] = q1;
    reached[0] = q0;
    reached[1] = p2;
    for (precondition = 0; precondition <= 1; ++precondition) {
        tclod_selector *sel = mixed_selector(f, precondition, 0.0);
        tclod_stats st;
        select_mixed(sel, 6.0, 0, &st);
        helper_assert_cut(sel, one_level, 2);
        assert_near(st.benefit, 4.5, 1e-6, "benefit without lookahead");
        tclod_selector_destroy(sel);
        sel = lookahead_selector(f, precondition, 0.0, 1);
        select_mixed(sel, 6.0, 0, &st);
        helper_assert_cut(sel, reached, 2);
        assert_true(resolution(sel, s) == 0.0);
        assert_true(st.benefit == 10.0 && st.cost == 6.0);
        tclod_selector_destroy(sel);
    }
}

#define FIXTURE_TEST(t) \
    cmocka_unit_test_setup_teardown(t, helper_fixture_setup, helper_fixture_teardown)

int main(void) {
    const struct CMUnitTest tests[] = {
        FIXTURE_TEST(line_search_stops_where_the_slope_along_the_gradient_meets_slope_d),
        FIXTURE_TEST(discrete_step_first_when_its_slope_beats_the_smooth_slope),
        FIXTURE_TEST(smooth_step_first_when_its_slope_beats_the_discrete_slope),
        FIXTURE_TEST(discrete_and_smooth_steps_share_the_budget_by_slope),
        FIXTURE_TEST(saturated_variable_stays_at_one_and_the_rest_goes_to_the_others),
        FIXTURE_TEST(barrier_moves_resolution_away_from_a_variable_close_to_one),
        FIXTURE_TEST(kinked_cost_reaches_the_hand_computed_optimum),
        FIXTURE_TEST(line_search_brackets_a_kink_and_keeps_the_better_local_maximum),
        cmocka_unit_test(line_search_on_kinked_instances_finds_the_best_point_of_the_line),
        FIXTURE_TEST(preconditioned_loop_spends_the_budget_at_the_slope_its_models_predict),
        cmocka_unit_test(separable_concave_instances_reach_99_percent_of_the_lagrangian_optimum),
        FIXTURE_TEST(unlimited_budget_draws_everything_at_full_resolution),
        FIXTURE_TEST(zero_budget_draws_no_smooth_object),
        FIXTURE_TEST(iteration_limits_stop_with_a_feasible_selection),
        FIXTURE_TEST(without_smooth_objects_the_mixed_solver_keeps_the_greedys_safeguard),
        FIXTURE_TEST(without_smooth_objects_the_mixed_solver_needs_no_smooth_callbacks),
        FIXTURE_TEST(mixed_solve_keeps_the_best_skipped_increment_taken_alone),
        FIXTURE_TEST(lookahead_increments_compete_with_smooth_steps_by_their_slope),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
