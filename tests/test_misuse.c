/*
 * test_misuse — what a host gets wrong, diagnosed instead of punished
 * (docs/api.md, errors):
 *  - a zeroed desc is the defaults (sokol's convention): a selector desc with
 *    only the callbacks set works with every solver, and zeroed scheduler and
 *    calibration descs behave as their _default() fills;
 *  - destroying a scene that a selector or scheduler still reads is refused
 *    and frees nothing.
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

/* ---- zeroed descs ----------------------------------------------------------------- */

/* A root (benefit 1, cost 1) with two children (benefit 3 and 2, cost 2
 * each), all in a sphere 10 m ahead, and a smooth object beside them. */
static void small_world(helper_fixture *f) {
    const float b[4] = {0.0f, 0.0f, -10.0f, 1.0f}, sb[4] = {3.0f, 0.0f, -10.0f, 1.0f};
    tclod_id root;
    assert_int_equal(table_add_node(&f->model, f->scene, TCLOD_NONE, b, 1.0, 1.0, &root), TCLOD_OK);
    assert_int_equal(table_add_node(&f->model, f->scene, root, b, 3.0, 2.0, NULL), TCLOD_OK);
    assert_int_equal(table_add_node(&f->model, f->scene, root, b, 2.0, 2.0, NULL), TCLOD_OK);
    assert_int_equal(
        table_add_smooth(&f->model, f->scene, sb, TABLE_POWER, 1.0, 0.5, 1.0, 1.0, 0.0, NULL),
        TCLOD_OK);
}

static tclod_stats select_with(helper_fixture *f, const tclod_selector_desc *d, double budget,
                               tclod_id *cut, size_t *n) {
    tclod_selector *sel = NULL;
    tclod_view v;
    tclod_frame fr;
    tclod_stats st;
    helper_view(&v);
    fr = helper_frame(&v, budget);
    assert_int_equal(tclod_selector_create(f->scene, d, NULL, &sel), TCLOD_OK);
    assert_int_equal(tclod_select(sel, &fr, &st), TCLOD_OK);
    *n = helper_sorted_cut(sel, cut, 8);
    tclod_selector_destroy(sel);
    return st;
}

static void a_zeroed_selector_desc_with_callbacks_is_the_default(void **state) {
    helper_fixture *f = (helper_fixture *)*state;
    static const tclod_solver solvers[] = {TCLOD_SOLVER_GREEDY, TCLOD_SOLVER_MIXED,
                                           TCLOD_SOLVER_ROBIN_HOOD};
    size_t s;
    small_world(f);
    for (s = 0; s < 3; ++s) {
        tclod_selector_desc zero, def;
        tclod_id cut_zero[8], cut_def[8];
        size_t n_zero, n_def;
        tclod_stats a, b;
        memset(&zero, 0, sizeof zero);
        zero.solver = solvers[s];
        table_mixed_callbacks(&f->model, &zero.callbacks);
        assert_null(tclod_selector_desc_check(f->scene, &zero));
        tclod_selector_desc_default(&def);
        def.solver = solvers[s];
        def.callbacks = zero.callbacks;
        a = select_with(f, &zero, 5.0, cut_zero, &n_zero);
        b = select_with(f, &def, 5.0, cut_def, &n_def);
        assert_int_equal(n_zero, n_def);
        assert_memory_equal(cut_zero, cut_def, n_zero * sizeof cut_zero[0]);
        assert_true(a.benefit == b.benefit && a.cost == b.cost);
        if (solvers[s] == TCLOD_SOLVER_GREEDY) {
            /* budget 5: both children (cost 4, benefit 5) beat the root
             * (cost 1, benefit 1); the smooth object is the mixed solver's */
            assert_int_equal(n_zero, 2);
            assert_int_equal(cut_zero[0], 1);
            assert_int_equal(cut_zero[1], 2);
            assert_true(a.cost == 4.0 && a.benefit == 5.0);
        }
    }
}

static void zeroed_scheduler_and_calibration_descs_are_the_defaults(void **state) {
    helper_fixture *f = (helper_fixture *)*state;
    tclod_selector_desc sd;
    tclod_scheduler_desc zero, def;
    tclod_calib_desc czero, cdef;
    tclod_calib *c0 = NULL, *c1 = NULL;
    tclod_scheduler *s0 = NULL, *s1 = NULL;
    tclod_view v;
    double b0, b1;
    int k;
    small_world(f);
    memset(&sd, 0, sizeof sd);
    table_callbacks(&f->model, &sd.callbacks);
    memset(&zero, 0, sizeof zero);
    tclod_scheduler_desc_default(&def);
    assert_null(tclod_scheduler_desc_check(&zero));
    assert_int_equal(tclod_scheduler_create(f->scene, &sd, &zero, NULL, &s0), TCLOD_OK);
    assert_int_equal(tclod_scheduler_create(f->scene, &sd, &def, NULL, &s1), TCLOD_OK);
    helper_view(&v);
    for (k = 0; k < 40; ++k) {
        const tclod_draw *d0, *d1;
        size_t n0, n1;
        double t = k / 20.0;
        assert_int_equal(tclod_scheduler_update(s0, t, &v, 5.0, 0.0), TCLOD_OK);
        assert_int_equal(tclod_scheduler_update(s1, t, &v, 5.0, 0.0), TCLOD_OK);
        assert_int_equal(tclod_scheduler_draws(s0, &d0, &n0), TCLOD_OK);
        assert_int_equal(tclod_scheduler_draws(s1, &d1, &n1), TCLOD_OK);
        assert_int_equal(n0, n1);
        assert_memory_equal(d0, d1, n0 * sizeof *d0);
        /* frames take 1.5 ms per unit: both calibrations follow alike */
        assert_int_equal(tclod_scheduler_report_frame(s0, 6.0, 2.0), TCLOD_OK);
        assert_int_equal(tclod_scheduler_report_frame(s1, 6.0, 2.0), TCLOD_OK);
    }
    assert_true(tclod_calib_scale(tclod_scheduler_calib(s0)) ==
                tclod_calib_scale(tclod_scheduler_calib(s1)));
    tclod_scheduler_destroy(s0);
    tclod_scheduler_destroy(s1);
    /* a calibration alone: rise 0.5 from the first measured ratio 2 towards
     * 4 gives 3, as the default rates say */
    memset(&czero, 0, sizeof czero);
    tclod_calib_desc_default(&cdef);
    assert_int_equal(tclod_calib_create(&czero, NULL, &c0), TCLOD_OK);
    assert_int_equal(tclod_calib_create(&cdef, NULL, &c1), TCLOD_OK);
    assert_int_equal(tclod_calib_report(c0, 1.0, 2.0, 1.0), TCLOD_OK);
    assert_int_equal(tclod_calib_report(c0, 1.0, 4.0, 1.0), TCLOD_OK);
    assert_int_equal(tclod_calib_report(c1, 1.0, 2.0, 1.0), TCLOD_OK);
    assert_int_equal(tclod_calib_report(c1, 1.0, 4.0, 1.0), TCLOD_OK);
    assert_true(tclod_calib_scale(c0) == 3.0 && tclod_calib_scale(c1) == 3.0);
    assert_int_equal(tclod_calib_budget(c0, 20.0, &b0), TCLOD_OK);
    assert_int_equal(tclod_calib_budget(c1, 20.0, &b1), TCLOD_OK);
    assert_true(b0 == b1);
    tclod_calib_destroy(c0);
    tclod_calib_destroy(c1);
}

/* ---- destroying a scene in use ---------------------------------------------------- */

static void a_scene_in_use_is_not_destroyed(void **state) {
    helper_fixture *f = (helper_fixture *)*state;
    tclod_selector *sel;
    tclod_scheduler *sch = NULL;
    tclod_selector_desc sd;
    tclod_scheduler_desc d;
    tclod_scene *s = NULL;
    tclod_id id;
    small_world(f);
    sel = helper_selector(f->scene, &f->model, 1);
    /* refused while the selector reads it; the scene still works */
    assert_int_equal(tclod_scene_destroy(f->scene), TCLOD_ERR_STATE);
    assert_int_equal(tclod_scene_node_count(f->scene), 3);
    tclod_selector_destroy(sel);
    /* and while a scheduler does */
    assert_int_equal(tclod_scene_create(NULL, &s), TCLOD_OK);
    assert_int_equal(tclod_scene_add_node(s, TCLOD_NONE, NULL, &id), TCLOD_OK);
    memset(&sd, 0, sizeof sd);
    table_callbacks(&f->model, &sd.callbacks);
    memset(&d, 0, sizeof d);
    assert_int_equal(tclod_scheduler_create(s, &sd, &d, NULL, &sch), TCLOD_OK);
    assert_int_equal(tclod_scene_destroy(s), TCLOD_ERR_STATE);
    assert_int_equal(tclod_scene_add_node(s, id, NULL, &id), TCLOD_OK);
    tclod_scheduler_destroy(sch);
    assert_int_equal(tclod_scene_destroy(s), TCLOD_OK);
    assert_int_equal(tclod_scene_destroy(NULL), TCLOD_OK);
}

int main(void) {
    const struct CMUnitTest tests[] = {
#define FIXTURE_TEST(t) \
    cmocka_unit_test_setup_teardown(t, helper_fixture_setup, helper_fixture_teardown)
        FIXTURE_TEST(a_zeroed_selector_desc_with_callbacks_is_the_default),
        FIXTURE_TEST(zeroed_scheduler_and_calibration_descs_are_the_defaults),
        FIXTURE_TEST(a_scene_in_use_is_not_destroyed),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
