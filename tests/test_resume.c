/*
 * test_resume — resumable selection (src/select/selector.c: tclod_select_begin,
 * tclod_select_step, tclod_select_finish, tclod_select_cancel, and the
 * solvers' resumable stages in src/solve/greedy/greedy.c, src/solve/mixed.c, src/solve/robin_hood.c):
 * a solve spread over one-iteration steps gives exactly the one-shot result
 * for every solver, cold and warm; the previous result stays readable while a
 * solve is pending; ending the search after any number of steps commits a
 * selection within the budget; the frame's limits apply over the summed
 * steps; calls out of order and a scene changed under a pending solve are
 * refused and change nothing.
 */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include <math.h>
#include <string.h>

#include <tclod/tclod.h>

#include "helpers.h"
#include "table_scene.h"

/* A random hierarchy of 400 nodes in 6 trees with diminishing returns, and
 * 60 smooth objects with a power benefit and a kinked or linear cost, spread
 * over a 40 x 40 square in front of helper_view's camera, with benefits of
 * the same order as the nodes', so that the solvers interleave both. */
typedef struct world {
    tclod_scene *scene;
    table_model model;
    tclod_view view;
} world;

static int world_setup(void **state) {
    static world w;
    table_rng rng;
    uint32_t i;
    memset(&w, 0, sizeof w);
    table_init(&w.model);
    assert_int_equal(tclod_scene_create(NULL, &w.scene), TCLOD_OK);
    table_rng_seed(&rng, 20261124u);
    assert_int_equal(table_random_hierarchy(&w.model, w.scene, &rng, 400, 6, TABLE_DIMINISHING),
                     TCLOD_OK);
    for (i = 0; i < 60; ++i) {
        float b[4];
        double k = table_rng_uniform(&rng, 0.05, 2.0);
        int kinked = (int)table_rng_below(&rng, 2);
        double weight = table_rng_uniform(&rng, 0.05, 0.5);
        b[0] = (float)table_rng_uniform(&rng, -20.0, 20.0);
        b[1] = 0.0f;
        b[2] = (float)table_rng_uniform(&rng, -45.0, -5.0);
        b[3] = (float)table_rng_uniform(&rng, 0.2, 2.0);
        assert_int_equal(table_add_smooth(&w.model, w.scene, b, TABLE_POWER, weight,
                                          table_rng_uniform(&rng, 0.3, 0.8), k,
                                          kinked ? 8.0 * k : k, kinked ? 0.05 : 0.0, NULL),
                         TCLOD_OK);
    }
    helper_view(&w.view);
    *state = &w;
    return 0;
}

static int world_teardown(void **state) {
    world *w = (world *)*state;
    tclod_scene_destroy(w->scene);
    table_free(&w->model);
    return 0;
}

/* The solvers and modes a resumed solve must reproduce. */
typedef enum mode {
    GREEDY,
    GREEDY_ONE_PASS, /* restarts = 1: no search */
    GREEDY_TUNED,    /* cold, lookahead and restarts: its restarts resume too */
    MIXED_MODELLED,
    MIXED_PAPERS,
    ROBIN_HOOD,
    MODE_COUNT
} mode;

static tclod_selector *make_selector(world *w, mode m) {
    tclod_selector_desc d;
    tclod_selector *sel = NULL;
    tclod_selector_desc_default(&d);
    table_mixed_callbacks(&w->model, &d.callbacks);
    if (m == MIXED_MODELLED || m == MIXED_PAPERS) {
        d.solver = TCLOD_SOLVER_MIXED;
        d.mixed.plain_gradient = !(m == MIXED_MODELLED);
    } else if (m == ROBIN_HOOD) {
        d.solver = TCLOD_SOLVER_ROBIN_HOOD;
    } else if (m == GREEDY_ONE_PASS) {
        d.greedy.restarts = 1;
    } else if (m == GREEDY_TUNED) {
        d.cold_start = 1;
        d.greedy.lookahead = 3;
        d.greedy.restarts = TCLOD_MAX_RESTARTS;
    }
    assert_int_equal(tclod_selector_create(w->scene, &d, NULL, &sel), TCLOD_OK);
    return sel;
}

/* The cost of the current selection, from the table: its cut, then every
 * drawn smooth group's members at the group's resolution. */
static double selection_cost(const tclod_selector *sel, tclod_scene *scene, const table_model *m) {
    const tclod_id *ids = NULL, *order = NULL;
    const tclod_smooth_group *g = NULL;
    size_t n = 0, ng = 0, i;
    uint32_t count = 0, k;
    double sum;
    assert_int_equal(tclod_selector_cut(sel, &ids, &n), TCLOD_OK);
    sum = table_sum_cost(m, ids, n);
    assert_int_equal(tclod_selector_smooth_groups(sel, &g, &ng), TCLOD_OK);
    if (ng == 0)
        return sum;
    assert_int_equal(tclod_scene_smooth_order(scene, &order, &count), TCLOD_OK);
    for (i = 0; i < ng; ++i)
        for (k = 0; k < g[i].count; ++k)
            sum += table_smooth_cost_of(m, order[g[i].first + k], g[i].resolution, NULL);
    return sum;
}

/* Asserts that two selectors hold the same result: the same cut in the same
 * order and the same smooth groups, bit for bit. */
static void assert_same_result(const tclod_selector *a, const tclod_selector *b) {
    const tclod_id *ia = NULL, *ib = NULL;
    const tclod_smooth_group *ga = NULL, *gb = NULL;
    size_t na = 0, nb = 0;
    assert_int_equal(tclod_selector_cut(a, &ia, &na), TCLOD_OK);
    assert_int_equal(tclod_selector_cut(b, &ib, &nb), TCLOD_OK);
    assert_int_equal(na, nb);
    if (na)
        assert_memory_equal(ia, ib, na * sizeof *ia);
    assert_int_equal(tclod_selector_smooth_groups(a, &ga, &na), TCLOD_OK);
    assert_int_equal(tclod_selector_smooth_groups(b, &gb, &nb), TCLOD_OK);
    assert_int_equal(na, nb);
    if (na)
        assert_memory_equal(ga, gb, na * sizeof *ga);
}

/* Steps sel through frame f one iteration at a time; returns the steps. */
static uint32_t step_through(tclod_selector *sel, const tclod_frame *f, tclod_stats *st) {
    uint32_t steps = 0;
    int done = 0;
    assert_int_equal(tclod_select_begin(sel, f), TCLOD_OK);
    while (!done) {
        assert_int_equal(tclod_select_step(sel, 0.0, 1, &done, st), TCLOD_OK);
        ++steps;
        assert_true(steps < 1000000u);
    }
    assert_int_equal(tclod_select_pending(sel), 0);
    return steps;
}

static void stepped_solve_equals_one_shot_for_every_solver(void **state) {
    world *w = (world *)*state;
    /* three frames per solver: cold, then warm with a higher and a lower
     * budget and a moved camera */
    static const double budgets[3] = {40.0, 90.0, 25.0};
    int m;
    for (m = 0; m < MODE_COUNT; ++m) {
        tclod_selector *one = make_selector(w, (mode)m), *stepped = make_selector(w, (mode)m);
        int k;
        for (k = 0; k < 3; ++k) {
            tclod_view v = w->view;
            tclod_frame f;
            tclod_stats a, b;
            uint32_t steps;
            v.eye[0] = (float)(3 * k);
            f = helper_frame(&v, budgets[k]);
            assert_int_equal(tclod_select(one, &f, &a), TCLOD_OK);
            steps = step_through(stepped, &f, &b);
            assert_same_result(one, stepped);
            assert_true(a.benefit == b.benefit);
            assert_true(a.cost == b.cost);
            assert_int_equal(a.iterations, b.iterations);
            assert_int_equal(a.evaluations, b.evaluations);
            assert_int_equal(a.stop_reason, b.stop_reason);
            /* the solve did pause: one step per iteration, about */
            if (m != ROBIN_HOOD && steps <= 10u)
                fail_msg("mode %d frame %d: %u steps, %u iterations", m, k, (unsigned)steps,
                         (unsigned)b.iterations);
        }
        tclod_selector_destroy(one);
        tclod_selector_destroy(stepped);
    }
}

static void previous_result_stays_readable_while_a_solve_is_pending(void **state) {
    world *w = (world *)*state;
    int m;
    for (m = 0; m < MODE_COUNT; ++m) {
        tclod_selector *sel = make_selector(w, (mode)m), *twin = make_selector(w, (mode)m);
        tclod_frame f = helper_frame(&w->view, 30.0), g = helper_frame(&w->view, 80.0);
        int done = 0;
        assert_int_equal(tclod_select(sel, &f, NULL), TCLOD_OK);
        assert_int_equal(tclod_select(twin, &f, NULL), TCLOD_OK);
        assert_int_equal(tclod_select_begin(sel, &g), TCLOD_OK);
        assert_int_equal(tclod_select_pending(sel), 1);
        assert_same_result(sel, twin);
        assert_int_equal(tclod_select_step(sel, 0.0, 1, &done, NULL), TCLOD_OK);
        assert_int_equal(done, 0);
        assert_same_result(sel, twin);
        /* cancelling keeps the old result, and the next solve starts warm
         * from it exactly as the twin's does */
        assert_int_equal(tclod_select_cancel(sel), TCLOD_OK);
        assert_int_equal(tclod_select_pending(sel), 0);
        assert_same_result(sel, twin);
        assert_int_equal(tclod_select(sel, &g, NULL), TCLOD_OK);
        assert_int_equal(tclod_select(twin, &g, NULL), TCLOD_OK);
        assert_same_result(sel, twin);
        tclod_selector_destroy(sel);
        tclod_selector_destroy(twin);
    }
}

static void finishing_after_any_step_commits_a_feasible_selection(void **state) {
    world *w = (world *)*state;
    int m;
    for (m = 0; m < MODE_COUNT; ++m) {
        tclod_selector *sel = make_selector(w, (mode)m);
        tclod_frame f = helper_frame(&w->view, 35.0);
        tclod_stats full, st;
        uint32_t total, k;
        total = step_through(sel, &f, &full);
        for (k = 0; k <= total; k += 1u + total / 40u) {
            uint32_t j;
            int done = 0;
            /* start over cold each time */
            tclod_selector_destroy(sel);
            sel = make_selector(w, (mode)m);
            assert_int_equal(tclod_select_begin(sel, &f), TCLOD_OK);
            for (j = 0; j < k && !done; ++j)
                assert_int_equal(tclod_select_step(sel, 0.0, 1, &done, &st), TCLOD_OK);
            if (!done) {
                assert_int_equal(tclod_select_finish(sel, &st), TCLOD_OK);
                assert_int_equal(st.stop_reason, TCLOD_STOP_FINISHED);
                /* stopping early never gains */
                assert_true(st.benefit <= full.benefit * (1.0 + 1e-12));
            }
            assert_int_equal(tclod_select_pending(sel), 0);
            assert_true(st.cost <= 35.0);
            assert_true(selection_cost(sel, w->scene, &w->model) <= 35.0 * (1.0 + 1e-12));
        }
        tclod_selector_destroy(sel);
    }
}

static void frame_limits_count_over_all_steps(void **state) {
    world *w = (world *)*state;
    tclod_selector *sel = make_selector(w, GREEDY);
    tclod_frame f = helper_frame(&w->view, 1e9);
    tclod_stats st;
    int done = 0, steps = 0;
    f.max_iterations = 25;
    assert_int_equal(tclod_select_begin(sel, &f), TCLOD_OK);
    while (!done) {
        assert_int_equal(tclod_select_step(sel, 0.0, 4, &done, &st), TCLOD_OK);
        ++steps;
    }
    assert_int_equal(st.stop_reason, TCLOD_STOP_ITERATIONS);
    assert_int_equal(st.iterations, 25);
    /* 4 per step up to 24, then the 25th and the stop */
    assert_int_equal(steps, 7);
    tclod_selector_destroy(sel);
}

static void time_slices_pause_and_resume(void **state) {
    world *w = (world *)*state;
    tclod_selector *sel = make_selector(w, MIXED_MODELLED), *one = make_selector(w, MIXED_MODELLED);
    tclod_frame f = helper_frame(&w->view, 60.0);
    int done = 0;
    uint32_t steps = 0;
    /* a slice of 1 ns ends at the first clock reading: the solve advances
     * by a few iterations per step and still ends with the one-shot result */
    assert_int_equal(tclod_select_begin(sel, &f), TCLOD_OK);
    while (!done) {
        assert_int_equal(tclod_select_step(sel, 1e-9, 0, &done, NULL), TCLOD_OK);
        ++steps;
    }
    assert_int_equal(tclod_select(one, &f, NULL), TCLOD_OK);
    assert_same_result(sel, one);
    assert_true(steps > 1u);
    tclod_selector_destroy(sel);
    tclod_selector_destroy(one);
}

static void calls_out_of_order_are_refused(void **state) {
    world *w = (world *)*state;
    tclod_selector *sel = make_selector(w, GREEDY);
    tclod_frame f = helper_frame(&w->view, 30.0), bad = f;
    int done = 7;
    assert_int_equal(tclod_select_step(sel, 0.0, 0, &done, NULL), TCLOD_ERR_STATE);
    assert_int_equal(done, 7);
    assert_int_equal(tclod_select_finish(sel, NULL), TCLOD_ERR_STATE);
    assert_int_equal(tclod_select_cancel(sel), TCLOD_OK); /* nothing to cancel */
    assert_int_equal(tclod_select_begin(NULL, &f), TCLOD_ERR_ARG);
    assert_int_equal(tclod_select_begin(sel, NULL), TCLOD_ERR_ARG);
    bad.budget = NAN;
    assert_int_equal(tclod_select_begin(sel, &bad), TCLOD_ERR_ARG);
    assert_int_equal(tclod_select_pending(sel), 0);
    assert_int_equal(tclod_select_begin(sel, &f), TCLOD_OK);
    assert_int_equal(tclod_select_begin(sel, &f), TCLOD_ERR_STATE);
    assert_int_equal(tclod_select(sel, &f, NULL), TCLOD_ERR_STATE);
    assert_int_equal(tclod_select_step(sel, -1.0, 0, &done, NULL), TCLOD_ERR_ARG);
    assert_int_equal(tclod_select_step(sel, NAN, 0, &done, NULL), TCLOD_ERR_ARG);
    assert_int_equal(tclod_select_step(sel, 0.0, 0, NULL, NULL), TCLOD_ERR_ARG);
    assert_int_equal(tclod_select_step(NULL, 0.0, 0, &done, NULL), TCLOD_ERR_ARG);
    assert_int_equal(tclod_select_finish(NULL, NULL), TCLOD_ERR_ARG);
    assert_int_equal(tclod_select_cancel(NULL), TCLOD_ERR_ARG);
    assert_int_equal(tclod_select_pending(NULL), 0);
    assert_int_equal(tclod_select_pending(sel), 1);
    assert_int_equal(tclod_select_step(sel, 0.0, 0, &done, NULL), TCLOD_OK);
    assert_int_equal(done, 1);
    tclod_selector_destroy(sel);
}

/* Between begin and the end of a solve the scene holds still: every edit is
 * refused with TCLOD_ERR_STATE and changes nothing, and the solve ends as an
 * unhindered twin's. Once it ended the edits go through, and the next warm
 * solve sees them. */
static void edits_under_a_pending_solve_are_refused(void **state) {
    world *w = (world *)*state;
    tclod_selector *sel = make_selector(w, GREEDY), *twin = make_selector(w, GREEDY);
    tclod_frame f = helper_frame(&w->view, 30.0), g = helper_frame(&w->view, 70.0);
    const float sphere[4] = {0.0f, 0.0f, -5.0f, 1.0f};
    tclod_bounds b = tclod_bounds_sphere(0.0, 0.0, -5.0, 1.0);
    uint32_t count = tclod_scene_node_count(w->scene), smooth = tclod_scene_smooth_count(w->scene);
    tclod_id id;
    int done = 0;
    assert_int_equal(tclod_select(sel, &f, NULL), TCLOD_OK);
    assert_int_equal(tclod_select(twin, &f, NULL), TCLOD_OK);
    assert_int_equal(tclod_select_begin(sel, &g), TCLOD_OK);
    assert_int_equal(tclod_select_step(sel, 0.0, 2, &done, NULL), TCLOD_OK);
    assert_int_equal(done, 0);
    assert_int_equal(tclod_scene_add_node(w->scene, TCLOD_NONE, NULL, &id), TCLOD_ERR_STATE);
    assert_int_equal(tclod_scene_remove_node(w->scene, 0), TCLOD_ERR_STATE);
    assert_int_equal(tclod_scene_set_node_bounds(w->scene, 0, &b), TCLOD_ERR_STATE);
    assert_int_equal(tclod_scene_add_smooth(w->scene, sphere, &id), TCLOD_ERR_STATE);
    assert_int_equal(tclod_scene_node_count(w->scene), count);
    assert_int_equal(tclod_scene_smooth_count(w->scene), smooth);
    assert_int_equal(tclod_select_step(sel, 0.0, 0, &done, NULL), TCLOD_OK);
    assert_int_equal(done, 1);
    assert_int_equal(tclod_select(twin, &g, NULL), TCLOD_OK);
    assert_same_result(sel, twin);
    /* a cancelled solve lets go of the scene too */
    assert_int_equal(tclod_select_begin(sel, &f), TCLOD_OK);
    assert_int_equal(tclod_scene_add_node(w->scene, TCLOD_NONE, NULL, &id), TCLOD_ERR_STATE);
    assert_int_equal(tclod_select_cancel(sel), TCLOD_OK);
    assert_int_equal(table_add_node(&w->model, w->scene, TCLOD_NONE, NULL, 1.0, 1.0, &id),
                     TCLOD_OK);
    assert_int_equal(tclod_scene_node_count(w->scene), count + 1u);
    /* the next solves see the grown scene */
    assert_int_equal(tclod_select(sel, &g, NULL), TCLOD_OK);
    assert_int_equal(tclod_select(twin, &g, NULL), TCLOD_OK);
    assert_same_result(sel, twin);
    tclod_selector_destroy(sel);
    tclod_selector_destroy(twin);
}

static void a_solve_after_a_budget_that_fits_nothing_recovers(void **state) {
    world *w = (world *)*state;
    int m;
    for (m = 0; m < MODE_COUNT; ++m) {
        /* a warm solve does not search: the greedy's reference is one pass */
        tclod_selector *sel = make_selector(w, (mode)m),
                       *fresh = make_selector(w, m == GREEDY ? GREEDY_ONE_PASS : (mode)m);
        tclod_frame big = helper_frame(&w->view, 50.0), none = helper_frame(&w->view, 0.0);
        tclod_stats a, b;
        size_t n = 1;
        const tclod_id *ids;
        assert_int_equal(tclod_select(sel, &big, NULL), TCLOD_OK);
        /* nothing fits: every visible root is left out */
        assert_int_equal(tclod_select(sel, &none, &a), TCLOD_OK);
        assert_int_equal(tclod_selector_cut(sel, &ids, &n), TCLOD_OK);
        assert_int_equal(n, 0);
        assert_true(a.cost == 0.0);
        assert_true(a.dropped_roots > 0u);
        /* then the full budget again: as much as a fresh selector gets, with
         * no root left out that it keeps */
        assert_int_equal(tclod_select(sel, &big, &a), TCLOD_OK);
        assert_int_equal(tclod_select(fresh, &big, &b), TCLOD_OK);
        /* (the Robin Hood solver drops an instance whose share is too small
         * for its simplest level, fresh or not) */
        if (a.dropped_roots != b.dropped_roots || !(a.benefit >= b.benefit * (1.0 - 1e-9)))
            fail_msg("mode %d: dropped %u, benefit %.17g, fresh %.17g (dropped %u)", m,
                     a.dropped_roots, a.benefit, b.benefit, b.dropped_roots);
        tclod_selector_destroy(sel);
        tclod_selector_destroy(fresh);
    }
}

int main(void) {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(stepped_solve_equals_one_shot_for_every_solver),
        cmocka_unit_test(previous_result_stays_readable_while_a_solve_is_pending),
        cmocka_unit_test(finishing_after_any_step_commits_a_feasible_selection),
        cmocka_unit_test(frame_limits_count_over_all_steps),
        cmocka_unit_test(time_slices_pause_and_resume),
        cmocka_unit_test(calls_out_of_order_are_refused),
        cmocka_unit_test(a_solve_after_a_budget_that_fits_nothing_recovers),
        /* last: it grows the scene */
        cmocka_unit_test(edits_under_a_pending_solve_are_refused),
    };
    return cmocka_run_group_tests(tests, world_setup, world_teardown);
}
